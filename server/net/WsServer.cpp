// gi-server's network side (net/WsServer.h): the libwebsockets 4.1 loop on one service thread, its
// setup and teardown, metrics, connection admission and access control, and the loop's callbacks,
// which route to the HTTP API (HttpApi.cpp), the gi-stream endpoint (StreamEndpoint.cpp) and the
// drain and housekeeping (Drain.cpp). Only the service thread writes; workers wake it with
// lws_cancel_service().
#include "net/ServerInternals.h"

namespace gis {

WsServer::Impl* WsServer::Impl::from(lws* wsi) {
    return static_cast<Impl*>(lws_context_user(lws_get_context(wsi)));
}

void WsServer::Impl::countError(const std::string& code) {
    metrics.counter("gis_errors_total", "error messages sent to clients, by code", {{"code", code}}).inc();
}

void WsServer::Impl::countHttp(const std::string& endpoint, unsigned status) {
    metrics
        .counter("gis_http_requests_total", "HTTP requests by endpoint and status",
                 {{"endpoint", endpoint}, {"status", std::to_string(status)}})
        .inc();
}

void WsServer::Impl::onFrame(const FrameReport& r) {
    metrics.counter("gis_frames_total", "frames rendered, by quality step", {{"quality", r.quality}}).inc();
    metrics.histogram("gis_frame_ms", "frame render time", defaultLatencyBucketsMs()).observe(r.frameMs);
    metrics
        .histogram("gis_admission_wait_ms", "time a render waited for a render slot",
                   defaultLatencyBucketsMs())
        .observe(r.queueMs);
    metrics.histogram("gis_encode_ms", "frame encoding time", defaultLatencyBucketsMs()).observe(r.encodeMs);
    for (const auto& [pass, ms] : r.passMs)
        metrics.histogram("gis_pass_ms", "per-pass render time", defaultLatencyBucketsMs(), {{"pass", pass}})
            .observe(ms);
    if (r.dropped)
        metrics.counter("gis_frames_dropped_total", "frames a client skipped (window full or replaced)")
            .inc(static_cast<double>(r.dropped));
}

void WsServer::Impl::updateGauges() {
    std::size_t controllers = 0, viewers = 0, detached = 0;
    for (const auto& e : sessions->all()) {
        if (e->controller)
            ++controllers;
        else
            ++detached;
        viewers += e->session->viewerCount();
    }
    metrics.gauge("gis_sessions", "open sessions (including those waiting for a resume)")
        .set(static_cast<double>(sessions->size()));
    metrics.gauge("gis_sessions_detached", "sessions waiting for their controller to resume")
        .set(static_cast<double>(detached));
    metrics.gauge("gis_clients", "attached clients by role", {{"role", "controller"}})
        .set(static_cast<double>(controllers));
    metrics.gauge("gis_clients", "attached clients by role", {{"role", "viewer"}})
        .set(static_cast<double>(viewers));
    metrics.gauge("gis_renders_active", "renders holding a render slot").set(gate->active());
    metrics.gauge("gis_render_queue_depth", "renders waiting for a render slot").set(gate->waiting());
    metrics.gauge("gis_http_render_queue", "POST /api/render jobs waiting for a worker")
        .set(static_cast<double>(workers->queued()));
    metrics.gauge("gis_teardowns_pending", "ended sessions whose render thread is still being joined")
        .set(static_cast<double>(reaper->pending()));
    if (const auto resident = residentBytes())
        metrics.gauge("process_resident_memory_bytes", "the server's resident set size")
            .set(static_cast<double>(*resident));
    metrics.gauge("gis_uptime_seconds", "seconds since the server started")
        .set(std::chrono::duration<double>(Clock::now() - started).count());
    metrics.gauge("gis_draining", "1 while the server drains after SIGTERM (no new sessions)")
        .set(phase == Phase::Running ? 0.0 : 1.0);
}

void WsServer::Impl::logRefusal(const std::string& reason, const std::string& detail) {
    metrics.counter("gis_refusals_total", "requests and connections refused, by reason", {{"reason", reason}})
        .inc();
    if (refusalLines[reason]++ < kRefusalLinesPerTick)
        logWarn("net: refused (" + reason + "): " + validUtf8(detail));
    else
        ++refusalsSuppressed[reason];
}

void WsServer::Impl::flushRefusalLog() {
    for (const auto& [reason, count] : refusalsSuppressed)
        if (count > 0)
            logWarn("net: refused (" + reason + "): " + std::to_string(count) + " more in the last 0.5 s");
    refusalsSuppressed.clear();
    refusalLines.clear();
}

std::string WsServer::Impl::peerAddress(lws* wsi) const {
    auto it = peers.find(wsi);
    return it == peers.end() ? std::string("unknown") : it->second.address;
}

bool WsServer::Impl::admitConnection(const lws_filter_network_conn_args& args) {
    const std::string address = addressText(args.cli_addr);
    if (static_cast<int>(peers.size()) >= connectionCap) {
        logRefusal("connection_limit", address + ": " + std::to_string(peers.size()) +
                                           " connections open (cap " + std::to_string(connectionCap) +
                                           ", --max-connections)");
        return false;
    }
    if (pendingByAddress[address] >= config.maxPendingPerIp) {
        logRefusal("pending_per_address", address + " has " + std::to_string(config.maxPendingPerIp) +
                                              " connections without a finished request or hello "
                                              "(--max-pending-per-ip)");
        return false;
    }
    return true;
}

void WsServer::Impl::peerCreated(lws* wsi) {
    char name[INET6_ADDRSTRLEN + 8] = {};
    const char* address = lws_get_peer_simple(wsi, name, sizeof name);
    Peer& peer = peers[wsi];
    if (!peer.address.empty()) return; // counted already
    peer.address = address && *address ? address : "unknown";
    peer.pending = true;
    ++pendingByAddress[peer.address];
}

void WsServer::Impl::settle(lws* wsi) {
    auto it = peers.find(wsi);
    if (it == peers.end() || !it->second.pending || it->second.address.empty()) return;
    it->second.pending = false;
    if (--pendingByAddress[it->second.address] <= 0) pendingByAddress.erase(it->second.address);
}

void WsServer::Impl::peerDestroyed(lws* wsi) {
    settle(wsi);
    peers.erase(wsi);
    bodiesPending.erase(wsi);
}

bool WsServer::Impl::originAllowed(lws* wsi) {
    const std::string origin = header(wsi, WSI_TOKEN_ORIGIN);
    if (origin.empty()) return true; // not a browser: the token (if any) decides
    const std::string host = header(wsi, WSI_TOKEN_HOST);
    if (origin == "http://" + host || origin == "https://" + host) return true;
    for (const auto& o : config.allowOrigins)
        if (origin == o) return true;
    return false;
}

bool WsServer::Impl::bearerOk(lws* wsi) {
    if (config.token.empty()) return true;
    const std::string token = bearerToken(header(wsi, WSI_TOKEN_HTTP_AUTHORIZATION));
    return !token.empty() && sameSecret(token, config.token);
}

int WsServer::Impl::onConnectionEvent(lws* wsi, lws_callback_reasons reason, void* user, bool& handled) {
    handled = true;
    switch (reason) {
    case LWS_CALLBACK_FILTER_NETWORK_CONNECTION:
        return user && admitConnection(*static_cast<lws_filter_network_conn_args*>(user)) ? 0 : 1;
    case LWS_CALLBACK_WSI_CREATE:
        // Before the socket is attached: the connection counts from here, its address comes next.
        peers[wsi];
        return 0;
    case LWS_CALLBACK_SERVER_NEW_CLIENT_INSTANTIATED:
        peerCreated(wsi);
        return 0;
    case LWS_CALLBACK_WSI_DESTROY:
        peerDestroyed(wsi);
        exchanges.erase(wsi); // in case the connection went without CLOSED_HTTP
        return 0;
    case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION:
        // An upgrade without Sec-WebSocket-Protocol lands on the HTTP protocol: refuse it.
        logRefusal("ws_protocol",
                   peerAddress(wsi) + " asked for a WebSocket without the gi-stream sub-protocol");
        return 1;
    case LWS_CALLBACK_HTTP_CONFIRM_UPGRADE: {
        const std::string uri = header(wsi, WSI_TOKEN_GET_URI);
        const std::string subprotocols = header(wsi, WSI_TOKEN_PROTOCOL);
        if (uri != "/ws" || subprotocols.find("gi-stream") == std::string::npos) {
            logRefusal("ws_upgrade", peerAddress(wsi) + " asked to upgrade " + uri.substr(0, 200) +
                                         " with sub-protocol '" + subprotocols.substr(0, 100) + "'");
            const char* why = uri != "/ws" ? "WebSocket upgrades are served on /ws only"
                                           : "send Sec-WebSocket-Protocol: gi-stream (protocol/PROTOCOL.md)";
            lws_return_http_status(wsi, uri != "/ws" ? HTTP_STATUS_NOT_FOUND : HTTP_STATUS_BAD_REQUEST, why);
            return 1;
        }
        return 0;
    }
    default:
        handled = false;
        return 0;
    }
}

int WsServer::Impl::httpCallback(lws* wsi, lws_callback_reasons reason, void* user, void* in, size_t len) {
    Impl* self = from(wsi);
    if (self && reason == LWS_CALLBACK_EVENT_WAIT_CANCELLED) {
        self->onWake();
        return 0;
    }
    if (self) {
        bool handled = false;
        const int r = self->onConnectionEvent(wsi, reason, user, handled);
        if (handled) return r;
    }
    return self ? self->onHttp(wsi, reason, static_cast<PerSession*>(user), in, len)
                : lws_callback_http_dummy(wsi, reason, user, in, len);
}

int WsServer::Impl::streamCallback(lws* wsi, lws_callback_reasons reason, void* user, void* in, size_t len) {
    Impl* self = from(wsi);
    return self ? self->onStream(wsi, reason, static_cast<PerSession*>(user), in, len) : 0;
}

WsServer::WsServer(ServerConfig config) : mImpl(std::make_unique<Impl>()) {
    Impl& m = *mImpl;
    m.config = std::move(config);
    // protocol/messages.json says who answers each message: the stream endpoint or the session.
    const std::vector<std::string> sessionTypes = Session::messageTypes();
    for (const ClientMessageSpec& spec : clientMessages()) {
        const bool endpoint = Impl::connectionHandlers().count(spec.type) == 1;
        const bool session =
            std::find(sessionTypes.begin(), sessionTypes.end(), spec.type) != sessionTypes.end();
        if (spec.connection != endpoint || spec.connection == session)
            throw Error("net: protocol/messages.json says '" + spec.type + "' is answered by the " +
                        (spec.connection ? "connection" : "session") + ", and the server disagrees");
    }
    m.sessions = std::make_unique<Directory>(
        Directory::Limits{.maxSessions = m.config.maxSessions,
                          .maxViewersPerSession = kMaxViewersPerSession,
                          .resumeGrace = std::chrono::seconds(m.config.resumeGraceS),
                          .idleTimeoutS = static_cast<double>(m.config.idleTimeoutS)});
    char resolved[PATH_MAX];
    if (!realpath(m.config.clientDir.c_str(), resolved))
        throw InputError("--client-dir", "directory '" + m.config.clientDir + "' does not exist");
    m.clientRoot = resolved;
    m.config.clientDir = resolved;
    m.catalog = std::make_shared<SceneCatalog>(m.config.sceneDirs, m.config.session.scene,
                                               static_cast<std::uint64_t>(m.config.maxDecodedMb) << 20);
    m.connectionCap = m.config.maxConnections > 0 ? m.config.maxConnections
                                                  : connectionCapFromFileLimit(m.config.maxSessions);
    m.defaultScene = m.scenes->get(m.catalog->resolve(m.config.session.scene));
    if (m.config.uploadDir.empty()) {
        m.uploadRoot =
            (fs::temp_directory_path() / ("gi-server-uploads-" + std::to_string(::getpid()))).string();
        m.ownsUploadRoot = true;
    } else {
        m.uploadRoot = m.config.uploadDir;
    }
    std::error_code ec;
    fs::create_directories(m.uploadRoot, ec);
    if (ec) throw InputError("--upload-dir", "cannot create '" + m.uploadRoot + "': " + ec.message());
    m.gate = std::make_unique<RenderGate>(m.config.renderSlots);
    // API workers share the gate with sessions but never hold its last slot: with two or more slots,
    // API renders run on at most slots - 1 of them (and at most 4: each holds a GL context), so a
    // burst of render requests cannot hold every session's controller behind it.
    m.workers =
        std::make_unique<GlWorkerPool>(m.config.session.backend, std::clamp(m.config.renderSlots - 1, 1, 4),
                                       static_cast<std::size_t>(m.config.httpRenderQueue), m.gate.get());
}

WsServer::~WsServer() {
    mImpl->stop = true;
    mImpl->unpacker.reset(); // finishes an extraction in progress: it wakes the loop's context
    if (mImpl->context) lws_context_destroy(mImpl->context); // closes connections: sessions end
    for (const auto& e : mImpl->sessions->all()) mImpl->endSession(e, "", "");
    mImpl->workers.reset();
    mImpl->reaper.reset(); // joins every render thread
    if (mImpl->ownsUploadRoot) {
        std::error_code ec;
        fs::remove_all(mImpl->uploadRoot, ec);
    }
}

void WsServer::listen() {
    lws_set_log_level(LLL_ERR | LLL_WARN, nullptr);
    std::memset(mImpl->protocols, 0, sizeof mImpl->protocols);
    mImpl->protocols[0].name = "http";
    mImpl->protocols[0].callback = &Impl::httpCallback;
    mImpl->protocols[0].per_session_data_size = sizeof(PerSession);
    mImpl->protocols[1].name = "gi-stream";
    mImpl->protocols[1].callback = &Impl::streamCallback;
    mImpl->protocols[1].per_session_data_size = sizeof(PerSession);
    mImpl->protocols[1].rx_buffer_size = 16384;

    lws_context_creation_info info;
    std::memset(&info, 0, sizeof info);
    if (mImpl->config.port < 1 || mImpl->config.port > 65535)
        throw InputError("--port", "port must be in [1, 65535], got " + std::to_string(mImpl->config.port));
    info.port = mImpl->config.port;
    info.iface = mImpl->config.host.c_str();
    info.protocols = mImpl->protocols;
    info.user = mImpl.get();
    info.options = LWS_SERVER_OPTION_VALIDATE_UTF8;
    // Room for the X-GI-Stats response header and large Authorization headers.
    info.max_http_header_data = 8192;
    mImpl->context = lws_create_context(&info);
    if (!mImpl->context)
        throw Error("net: cannot listen on " + mImpl->config.host + ":" + std::to_string(mImpl->config.port) +
                    " (address in use or not available?)");
    mPort = mImpl->config.port;
    logInfo("net: at most " + std::to_string(mImpl->connectionCap) + " connections (" +
            (mImpl->config.maxConnections > 0 ? std::string("--max-connections")
                                              : std::string("from the open-file limit")) +
            "), " + std::to_string(mImpl->config.maxPendingPerIp) +
            " per address before their request or hello is done");
    mImpl->scheduleHousekeeping();
}

void WsServer::run() {
    while (!mImpl->stop.load()) {
        if (lws_service(mImpl->context, 0) < 0) break;
        mImpl->pollShutdown();
    }
}

bool WsServer::stoppedAtOnce() const {
    return mImpl->handledStopRequests >= 2;
}

void WsServer::requestStop() {
    // Signal handlers call this: an atomic increment and lws_cancel_service (a write to the loop's
    // wake-up pipe) only; the loop does the work in pollShutdown().
    mImpl->stopRequests.fetch_add(1);
    if (mImpl->context) lws_cancel_service(mImpl->context);
}

} // namespace gis
