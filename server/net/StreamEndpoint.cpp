// The gi-stream WebSocket endpoint: connections, hello (what the session directory decided), the message
// table's connection handlers and the rest handed to the session, welcome, errors and closes, and the session
// ends.
#include "net/ServerInternals.h"

namespace gis {

void WsServer::Impl::sendDirect(Connection& c, const nlohmann::json& msg) {
    if (msg.value("type", "") == "error") countError(msg.value("code", "unknown"));
    if (c.direct.size() >= kMaxDirectMessages) return; // a client that never reads loses replies
    c.direct.push_back(msg.dump());
    lws_callback_on_writable(c.wsi);
}

void WsServer::Impl::sendError(Connection& c, const ProtocolError& e) {
    sendDirect(c, errorMessage(e));
}

void WsServer::Impl::closeWith(Connection& c, const ProtocolError& e, int code) {
    if (!c.helloDone) logRefusal(e.code, peerAddress(c.wsi) + ": " + e.message);
    sendError(c, e);
    c.closing = true;
    c.closeCode = code;
    c.closeReason = e.code;
    lws_callback_on_writable(c.wsi);
}

void WsServer::Impl::endSession(const std::shared_ptr<SessionEntry>& entry, const std::string& code,
                                const std::string& message) {
    if (!sessions->end(*entry)) return;
    for (auto& [wsi, c] : connections) {
        if (c->entry != entry) continue;
        if (!code.empty())
            closeWith(*c, {code, message, "", ""},
                      code == "idle_timeout"    ? 1000
                      : code == "render_failed" ? 1011
                                                : 1001);
        c->link.reset();
        c->entry.reset();
    }
    logInfo("net: session " + entry->session->id() + " ended (" + (code.empty() ? "closed" : code) +
            ") after " + std::to_string(entry->session->framesRendered()) + " frames");
    auto session = entry->session;
    reaper->retire([session] {
        session->stop();
        std::error_code ec;
        if (!session->uploadDir().empty()) fs::remove_all(session->uploadDir(), ec);
    });
}

nlohmann::json WsServer::Impl::welcomeFor(const SessionEntry& entry, ClientRole role, bool resumed,
                                          int maxInFlight) {
    const StreamOptions stream = entry.session->streamOptions();
    const SessionLimits& l = config.session.limits;
    nlohmann::json w = {
        {"type", "welcome"},
        {"protocol", kProtocolVersion},
        {"server", kServerName},
        {"session", entry.session->id()},
        {"role", roleName(role)},
        {"resumed", resumed},
        {"codec", codecName(stream.codec)},
        {"quality", stream.quality},
        {"max_in_flight", maxInFlight},
        {"adaptive", stream.adaptive},
        {"frame_target_ms", stream.frameTargetMs >= 0 ? stream.frameTargetMs : l.frameTargetMs},
        {"limits",
         {{"max_size", {l.maxWidth, l.maxHeight}},
          {"max_vpls", l.maxVpls},
          {"max_message_bytes", config.maxMessageBytes},
          {"messages_per_second", config.messagesPerSecond},
          {"resume_grace_s", config.resumeGraceS},
          {"idle_timeout_s", config.idleTimeoutS},
          {"interactive_scale", l.interactiveScale},
          {"interactive_lod_px", l.interactiveLodPixels},
          {"frame_target_ms", l.frameTargetMs},
          {"slice_ms", l.sliceMs},
          {"settle_ms", l.settleMs},
          {"refine_budget_ms", l.refineBudgetMs}}},
        {"scenes", entry.session->sceneNames()},
        {"techniques", techniquesJson()},
        {"frame_params_schema", frameParamTable().jsonSchema()},
        {"state", entry.session->stateJson()}};
    if (role == ClientRole::Controller) {
        w["resume_token"] = entry.resumeToken;
        w["view_token"] = entry.viewToken;
    }
    return w;
}

std::shared_ptr<ClientLink> WsServer::Impl::makeLink(ClientRole role, int maxInFlight, bool acceptsPatches) {
    lws_context* ctx = context;
    return std::make_shared<ClientLink>(
        role, maxInFlight, [ctx] { lws_cancel_service(ctx); }, 64, acceptsPatches);
}

void WsServer::Impl::onHello(Connection& c, const nlohmann::json& hello) {
    if (phase != Phase::Running) {
        // Resumes and viewers too: a session on a draining server cannot outlive the drain.
        closeWith(c,
                  shuttingDown("hello", "the server is shutting down; connect again (without resume) to "
                                        "reach another instance"),
                  1001);
        return;
    }
    if (const int asked = hello["protocol"].get<int>();
        asked < kOldestProtocolVersion || asked > kProtocolVersion) {
        closeWith(c,
                  {"protocol_mismatch",
                   "this server speaks protocols " + std::to_string(kOldestProtocolVersion) + " to " +
                       std::to_string(kProtocolVersion) + ", the client " + std::to_string(asked),
                   "/protocol", "hello"},
                  1002);
        return;
    }
    if (!config.token.empty() && !c.headerAuth &&
        !(hello.contains("token") && sameSecret(hello["token"].get<std::string>(), config.token))) {
        closeWith(c,
                  {"unauthorized", "this server needs its token in hello.token or an Authorization header",
                   "/token", "hello"},
                  1008);
        return;
    }
    const int maxInFlight = hello.value("max_in_flight", 1);
    const bool acceptsPatches = hello.value("patches", false);
    StreamOptions stream;
    stream.quality = hello.value("quality", config.jpegQuality);
    stream.adaptive = hello.value("adaptive", true);
    stream.frameTargetMs = hello.value("frame_target_ms", -1);
    if (hello.contains("codecs")) stream.codec = parseImageCodec(hello["codecs"][0].get<std::string>());

    auto token = [&](const char* key) {
        return hello.contains(key) ? std::optional<std::string>(hello[key].get<std::string>()) : std::nullopt;
    };
    const Directory::HelloDecision decision = sessions->decide(token("view"), token("resume"));
    using Kind = Directory::HelloDecision::Kind;
    if (decision.kind == Kind::Refuse) {
        if (decision.refusal.code == "busy" && !hello.contains("view"))
            metrics.counter("gis_sessions_refused_total", "sessions refused at the session cap").inc();
        closeWith(c, decision.refusal, decision.closeCode);
        return;
    }
    std::shared_ptr<SessionEntry> entry = decision.entry;
    if (decision.kind == Kind::Viewer) {
        c.link = makeLink(ClientRole::Viewer, maxInFlight, acceptsPatches);
        c.entry = entry;
        c.helloDone = true;
        settle(c.wsi);
        sendDirect(c, welcomeFor(*entry, ClientRole::Viewer, false, maxInFlight));
        entry->session->attach(c.link);
        logInfo("net: a viewer joined session " + entry->session->id() + " from " + peerAddress(c.wsi));
        return;
    }
    const bool resumed = decision.kind == Kind::Resume;
    if (resumed && entry->controller) {
        // The old connection may be half-open and not noticed yet: the resume takes over.
        Connection* old = entry->controller;
        old->link.reset();
        old->entry.reset();
        closeWith(*old, {"session_ended", "another connection resumed this session", "", ""}, 1001);
    }
    if (!resumed) {
        const std::string id = sessions->nextId();
        std::shared_ptr<Session> session;
        try {
            session = std::make_shared<Session>(id, config.session, scenes, catalog, gate.get(),
                                                (fs::path(uploadRoot) / id).string());
        } catch (const std::exception& e) {
            closeWith(c, {"render_failed", std::string("cannot start a session: ") + e.what(), "", "hello"},
                      1011);
            return;
        }
        session->setObservers([this](const FrameReport& r) { onFrame(r); },
                              [this](const std::string& code) { countError(code); });
        lws_context* ctx = context;
        session->setFailureObserver([ctx] { lws_cancel_service(ctx); });
        entry = sessions->add(session);
        metrics.counter("gis_sessions_started_total", "sessions created").inc();
    }
    if (hello.contains("size")) {
        try {
            entry->session->resize(hello["size"][0], hello["size"][1], hello.value("dpr", 1.0));
        } catch (const ProtocolError& e) {
            sendError(c, e);
        }
    }
    c.link = makeLink(ClientRole::Controller, maxInFlight, acceptsPatches);
    c.entry = entry;
    c.helloDone = true;
    settle(c.wsi);
    sessions->attach(*entry, &c);
    // Attach first so that welcome reports the negotiated stream; it still goes out before any
    // frame (direct replies are written before the link's queue).
    entry->session->attach(c.link, &stream);
    sendDirect(c, welcomeFor(*entry, ClientRole::Controller, resumed, maxInFlight));
    if (!resumed) entry->session->start();
    logInfo("net: session " + entry->session->id() + (resumed ? " resumed" : " opened") + " by " +
            peerAddress(c.wsi) + " (" + std::to_string(sessions->size()) + " open)");
}

void WsServer::Impl::onMessage(Connection& c, const std::string& text) {
    nlohmann::json msg;
    try {
        msg = parseClientMessage(text);
    } catch (const ProtocolError& e) {
        if (!c.helloDone)
            closeWith(c,
                      {"hello_required", "the first message must be a valid hello: " + e.message, e.where,
                       e.request},
                      1008);
        else
            sendError(c, e);
        return;
    }
    const std::string type = msg["type"];
    if (!c.helloDone) {
        if (type != "hello") {
            closeWith(c, {"hello_required", "send hello first (protocol/PROTOCOL.md)", "/type", type}, 1008);
            return;
        }
        onHello(c, msg);
        return;
    }
    // parseClientMessage accepts only the table's types (protocol/messages.json).
    const ClientMessageSpec& spec = *findClientMessage(type);
    if (spec.connection) {
        (this->*connectionHandlers().at(type))(c, msg);
        return;
    }
    if (!c.entry || !c.link) return; // the session ended; the close is on its way
    if (c.link->role() == ClientRole::Viewer && !spec.viewers) {
        sendError(c, {"read_only", "viewers cannot steer a shared session", "/type", type});
        return;
    }
    try {
        c.entry->session->apply(msg, c.link);
    } catch (const ProtocolError& e) {
        sendError(c, e);
    }
}

const std::map<std::string, WsServer::Impl::ConnectionHandler>& WsServer::Impl::connectionHandlers() {
    static const std::map<std::string, ConnectionHandler> handlers = {
        {"hello", &Impl::onHelloAgain}, {"ping", &Impl::onPing}, {"ack", &Impl::onAck}};
    return handlers;
}

void WsServer::Impl::onHelloAgain(Connection& c, const nlohmann::json&) {
    sendError(c, {"invalid_message", "hello was already accepted on this connection", "/type", "hello"});
}

void WsServer::Impl::onPing(Connection& c, const nlohmann::json& msg) {
    nlohmann::json pong = {{"type", "pong"}};
    if (msg.contains("t")) pong["t"] = msg["t"];
    sendDirect(c, pong);
}

void WsServer::Impl::onAck(Connection& c, const nlohmann::json& msg) {
    if (!c.entry || !c.link) return; // the session ended; the close is on its way
    try {
        c.entry->session->ack(c.link, msg["frame"].get<std::uint32_t>());
    } catch (const ProtocolError& e) {
        sendError(c, e);
    }
}

int WsServer::Impl::onStream(lws* wsi, lws_callback_reasons reason, PerSession* pss, void* in, size_t len) {
    switch (reason) {
    case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION:
        if (phase == Phase::Closing) return 1; // the loop ends in a moment
        if (header(wsi, WSI_TOKEN_GET_URI) != "/ws") {
            logRefusal("ws_path", peerAddress(wsi) + " asked for a WebSocket on another path than /ws");
            return 1;
        }
        if (!originAllowed(wsi)) {
            logWarn("net: refused a WebSocket from origin '" + header(wsi, WSI_TOKEN_ORIGIN) + "'");
            countHttp("/ws", 403);
            return 1;
        }
        if (pss) pss->headerAuth = !config.token.empty() && bearerOk(wsi);
        break;
    case LWS_CALLBACK_ESTABLISHED: {
        auto conn = std::make_unique<Connection>();
        conn->wsi = wsi;
        conn->headerAuth = pss && pss->headerAuth;
        if (config.messagesPerSecond > 0)
            conn->limiter =
                std::make_unique<RateLimiter>(config.messagesPerSecond, 2 * config.messagesPerSecond);
        if (pss) pss->connection = conn.get();
        connections[wsi] = std::move(conn);
        metrics.counter("gis_connections_total", "WebSocket connections accepted").inc();
        break;
    }
    case LWS_CALLBACK_RECEIVE: {
        Connection* c = pss ? pss->connection : nullptr;
        if (!c || c->closing) break;
        if (!c->rxTooLarge) {
            if (c->rx.size() + len > config.maxMessageBytes) {
                c->rxTooLarge = true;
                c->rx.clear();
            } else {
                c->rx.append(static_cast<const char*>(in), len);
            }
        }
        if (!lws_is_final_fragment(wsi) || lws_remaining_packet_payload(wsi) > 0) break;
        const std::string text = std::move(c->rx);
        const bool tooLarge = c->rxTooLarge;
        c->rx.clear();
        c->rxTooLarge = false;
        if (c->limiter && !c->limiter->allow()) {
            // One notice a second at most: answering every dropped message would be its own flood.
            if (Clock::now() - c->lastRateError > std::chrono::seconds(1)) {
                c->lastRateError = Clock::now();
                sendError(*c, {"rate_limited",
                               "more than " + std::to_string(static_cast<int>(config.messagesPerSecond)) +
                                   " messages per second; messages are being dropped",
                               "", ""});
            }
            break;
        }
        if (!c->helloDone && (tooLarge || lws_frame_is_binary(wsi))) {
            // PROTOCOL.md: anything but a hello first is answered hello_required and closed.
            logRefusal("hello_required", peerAddress(wsi) + " sent a " + (tooLarge ? "too large" : "binary") +
                                             " first message");
            closeWith(*c,
                      {"hello_required",
                       tooLarge ? "the first message must be a hello of at most " +
                                      std::to_string(config.maxMessageBytes) + " bytes"
                                : "the first message must be a JSON text hello",
                       "", ""},
                      tooLarge ? 1009 : 1003);
        } else if (tooLarge)
            sendError(*c, {"message_too_large",
                           "messages are limited to " + std::to_string(config.maxMessageBytes) + " bytes", "",
                           ""});
        else if (lws_frame_is_binary(wsi))
            sendError(*c, {"binary_not_accepted", "clients send JSON text messages only", "", ""});
        else
            onMessage(*c, text);
        break;
    }
    case LWS_CALLBACK_WS_PEER_INITIATED_CLOSE: {
        Connection* c = pss ? pss->connection : nullptr;
        if (c && len >= 2) {
            const auto* b = static_cast<const unsigned char*>(in);
            c->peerCloseCode = (b[0] << 8) | b[1];
        }
        break;
    }
    case LWS_CALLBACK_SERVER_WRITEABLE: {
        Connection* c = pss ? pss->connection : nullptr;
        if (!c) break;
        std::string text;
        bool binary = false;
        std::shared_ptr<const std::string> shared;
        if (!c->direct.empty()) {
            text = std::move(c->direct.front());
            c->direct.pop_front();
        } else if (c->closing) {
            lws_close_reason(wsi, static_cast<lws_close_status>(c->closeCode),
                             reinterpret_cast<unsigned char*>(c->closeReason.data()), c->closeReason.size());
            return -1;
        } else if (c->link) {
            OutgoingMessage m;
            if (!c->link->pop(m)) break;
            binary = m.binary;
            shared = std::move(m.data);
        } else {
            break;
        }
        const std::string& data = shared ? *shared : text;
        c->tx.resize(LWS_PRE + data.size());
        std::memcpy(c->tx.data() + LWS_PRE, data.data(), data.size());
        const int n =
            lws_write(wsi, c->tx.data() + LWS_PRE, data.size(), binary ? LWS_WRITE_BINARY : LWS_WRITE_TEXT);
        if (n < static_cast<int>(data.size())) {
            logWarn("net: write failed on a connection");
            return -1;
        }
        metrics.counter("gis_bytes_sent_total", "bytes written to WebSocket clients")
            .inc(static_cast<double>(n));
        if (!c->direct.empty() || c->closing || (c->link && c->link->hasOutgoing()))
            lws_callback_on_writable(wsi);
        break;
    }
    case LWS_CALLBACK_CLOSED: {
        auto it = connections.find(wsi);
        if (it == connections.end()) break;
        Connection& c = *it->second;
        if (c.entry && c.link) {
            auto entry = std::exchange(c.entry, nullptr);
            auto link = std::exchange(c.link, nullptr);
            if (link->role() == ClientRole::Viewer) {
                entry->session->detach(link);
            } else if (entry->controller == &c) {
                entry->session->detach(link);
                sessions->detach(*entry, Clock::now()); // the grace period starts
                if (stop || phase == Phase::Closing) {
                    endSession(entry, "", ""); // the server is going down: no messages
                } else if (phase == Phase::Draining) {
                    // No resume during a drain (hello is refused), so waiting would only delay the exit.
                    endSession(entry, "session_ended",
                               c.peerCloseCode == 1000
                                   ? "the controller closed the session"
                                   : "the controller left while the server shuts down; no resume");
                } else if (c.peerCloseCode == 1000 || config.resumeGraceS == 0) {
                    endSession(entry, "session_ended", "the controller closed the session");
                } else {
                    logInfo("net: session " + entry->session->id() + " lost its controller; kept " +
                            std::to_string(config.resumeGraceS) + " s for a resume");
                }
            }
        }
        connections.erase(it);
        if (pss) pss->connection = nullptr;
        break;
    }
    case LWS_CALLBACK_EVENT_WAIT_CANCELLED:
        onWake();
        break;
    default:
        break;
    }
    return 0;
}

} // namespace gis
