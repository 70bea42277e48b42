#include "net/WsServer.h"

#include <libwebsockets.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <climits>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "core/Error.h"
#include "core/JsonSchema.h"
#include "core/Log.h"
#include "frame/FrameParams.h"
#include "gi/Technique.h"
#include "net/Metrics.h"
#include "net/RateLimiter.h"
#include "net/SessionDirectory.h"
#include "render/FrameRenderer.h"
#include "job/ApiRender.h"
#include "job/RenderRequest.h"
#include "scene/SceneArchive.h"
#include "scene/SceneLoader.h"
#include "session/GlWorkerPool.h"
#include "session/RenderGate.h"

namespace gis {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
constexpr const char* kServerName = "gi-server/0.2.0";
constexpr std::size_t kMaxViewersPerSession = 32;
constexpr std::size_t kMaxRenderRequestBytes = 1 << 20;
constexpr std::size_t kMaxDirectMessages = 64;

/// Runs slow work away from the loop, in order, on one thread of its own: teardowns (joining render
/// threads, deleting upload sandboxes) on one queue, unpacking zipped uploads on another.
class BackgroundQueue {
public:
    BackgroundQueue() : mThread([this] { loop(); }) {}
    ~BackgroundQueue() {
        {
            std::lock_guard lock(mMutex);
            mStop = true;
        }
        mCv.notify_all();
        mThread.join();
    }
    void retire(std::function<void()> work) {
        {
            std::lock_guard lock(mMutex);
            mQueue.push_back(std::move(work));
            ++mPending;
        }
        mCv.notify_all();
    }
    /// Work queued or running (teardowns: it should fall back to 0 soon after sessions end).
    std::size_t pending() {
        std::lock_guard lock(mMutex);
        return mPending;
    }

private:
    void loop() {
        std::unique_lock lock(mMutex);
        while (true) {
            mCv.wait(lock, [&] { return mStop || !mQueue.empty(); });
            while (!mQueue.empty()) {
                auto work = std::move(mQueue.front());
                mQueue.pop_front();
                lock.unlock();
                work();
                work = nullptr;
                lock.lock();
                --mPending;
            }
            if (mStop) return;
        }
    }
    std::mutex mMutex;
    std::condition_variable mCv;
    std::deque<std::function<void()>> mQueue;
    std::size_t mPending = 0;
    bool mStop = false;
    std::thread mThread;
};

std::string header(lws* wsi, lws_token_indexes token) {
    const int len = lws_hdr_total_length(wsi, token);
    if (len <= 0) return {};
    std::string out(static_cast<std::size_t>(len) + 1, '\0');
    if (lws_hdr_copy(wsi, out.data(), len + 1, token) < 0) return {};
    out.resize(static_cast<std::size_t>(len));
    return out;
}

std::string customHeader(lws* wsi, const char* name) {
    const int nameLen = static_cast<int>(std::strlen(name));
    const int len = lws_hdr_custom_length(wsi, name, nameLen);
    if (len <= 0) return {};
    std::string out(static_cast<std::size_t>(len) + 1, '\0');
    if (lws_hdr_custom_copy(wsi, out.data(), len + 1, name, nameLen) < 0) return {};
    out.resize(static_cast<std::size_t>(len));
    return out;
}

std::string addressText(const sockaddr_storage& address) {
    char text[INET6_ADDRSTRLEN] = {};
    if (address.ss_family == AF_INET)
        inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in&>(address).sin_addr, text, sizeof text);
    else if (address.ss_family == AF_INET6)
        inet_ntop(AF_INET6, &reinterpret_cast<const sockaddr_in6&>(address).sin6_addr, text, sizeof text);
    return text[0] ? text : "unknown";
}

std::string lowerCase(std::string text) {
    for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return text;
}

/// The token of an `Authorization: Bearer <token>` header; the scheme is case-insensitive (RFC 9110
/// 11.1) and surrounding blanks are ignored. Empty for any other header.
std::string bearerToken(const std::string& header) {
    const std::size_t space = header.find(' ');
    if (space == std::string::npos || lowerCase(header.substr(0, space)) != "bearer") return {};
    const std::size_t start = header.find_first_not_of(' ', space);
    if (start == std::string::npos) return {};
    const std::size_t end = header.find_last_not_of(" \t");
    return header.substr(start, end + 1 - start);
}

/// Default connection cap: the open-file limit less what sessions (GL contexts, upload files), the
/// listening socket, logs and libraries need, so that accept() never fails with EMFILE.
int connectionCapFromFileLimit(int maxSessions) {
    rlimit limit{};
    long files = 1024; // the common default, when the limit cannot be read
    if (getrlimit(RLIMIT_NOFILE, &limit) == 0)
        files = limit.rlim_cur == RLIM_INFINITY ? 1L << 20 : static_cast<long>(limit.rlim_cur);
    const long reserve = 64 + 16L * maxSessions;
    return static_cast<int>(std::clamp(files - reserve, 16L, 1L << 20));
}

std::string urlArg(lws* wsi, const char* name) {
    char buf[512];
    const char* v = lws_get_urlarg_by_name(wsi, name, buf, sizeof buf);
    return v ? std::string(v) : std::string();
}

std::string mimeType(const std::string& path) {
    auto ext = path.substr(path.find_last_of('.') + 1);
    if (ext == "html") return "text/html; charset=utf-8";
    if (ext == "js" || ext == "mjs") return "text/javascript; charset=utf-8";
    if (ext == "css") return "text/css; charset=utf-8";
    if (ext == "json") return "application/json";
    if (ext == "png") return "image/png";
    if (ext == "svg") return "image/svg+xml";
    if (ext == "ico") return "image/x-icon";
    return "application/octet-stream";
}

nlohmann::json techniquesJson() {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& e : techniqueRegistry())
        list.push_back({{"name", e.info.name},
                        {"description", e.info.description},
                        {"paper", e.info.paper},
                        {"params_schema", e.info.params.jsonSchema()}});
    return list;
}

/// One HTTP response, written in two writable callbacks: headers, then the body.
using HttpResponse = HttpReply;

struct HttpExchange {
    std::string uri;
    bool post = false;
    bool bodyDone = false;        ///< LWS_CALLBACK_HTTP_BODY_COMPLETION came (or no body is expected)
    bool closeAfter = false;      ///< answered before its body arrived: close instead of reading it
    Clock::time_point deadline{}; ///< the whole request (headers and body) must be in by then
    std::string body;
    bool bodyTooLarge = false;
    std::size_t bodyLimit = 0;
    std::uint64_t jobId = 0; ///< awaiting a render or an archive extraction when non-zero
    bool ready = false;
    bool headersSent = false;
    HttpResponse response;
    std::string endpoint; ///< for metrics
};

struct Connection;
/// Sessions by id and token, steered by connections (net/SessionDirectory.h).
using Directory = SessionDirectory<Session, Connection>;
using SessionEntry = Directory::Entry;

struct Connection {
    lws* wsi = nullptr;
    Clock::time_point opened = Clock::now();
    bool helloDone = false;
    bool headerAuth = false;
    std::string rx;
    bool rxTooLarge = false;
    std::vector<unsigned char> tx;  // LWS_PRE headroom + message
    std::deque<std::string> direct; // replies from the network layer (welcome, errors, pong)
    std::unique_ptr<RateLimiter> limiter;
    Clock::time_point lastRateError{};
    std::shared_ptr<ClientLink> link;
    std::shared_ptr<SessionEntry> entry;
    int peerCloseCode = 0;
    bool closing = false;
    int closeCode = 1000;
    std::string closeReason;
};

// Per-connection storage lws allocates (zeroed, plain memory): pointers and flags only.
struct PerSession {
    Connection* connection;
    HttpExchange* http; ///< owned by Impl::exchanges
    bool headerAuth;
};

struct Housekeeping {
    lws_sorted_usec_list_t sul; // first member: the callback gets this address back
    WsServer::Impl* self;
};

} // namespace

struct WsServer::Impl {
    /// Running, then (after the first stop request) Draining: no new sessions, running ones go on;
    /// then Closing: everything is closed with 1001 and the loop ends once the close frames are out.
    enum class Phase { Running, Draining, Closing };

    ServerConfig config;
    std::string clientRoot;
    std::string uploadRoot;
    bool ownsUploadRoot = false;
    lws_context* context = nullptr;
    std::atomic<bool> stop{false};
    std::atomic<int> stopRequests{0}; // bumped by signal handlers: lock-free, nothing else
    static_assert(std::atomic<int>::is_always_lock_free);
    int handledStopRequests = 0;
    Phase phase = Phase::Running;
    Clock::time_point drainDeadline{}, closeDeadline{};
    Clock::time_point started = Clock::now();
    std::shared_ptr<SceneCache> scenes = std::make_shared<SceneCache>();
    std::shared_ptr<const Scene> defaultScene; // keeps the default scene cached between sessions
    std::shared_ptr<const SceneCatalog> catalog;
    std::unique_ptr<RenderGate> gate;
    std::unique_ptr<GlWorkerPool> workers;
    MetricsRegistry metrics;
    std::map<lws*, std::unique_ptr<Connection>> connections;
    std::map<lws*, std::unique_ptr<HttpExchange>> exchanges; ///< PerSession::http points into it
    std::unique_ptr<Directory> sessions;                     // made with the config's limits
    std::unique_ptr<BackgroundQueue> reaper = std::make_unique<BackgroundQueue>();
    std::uint64_t nextSessionId = 1;
    lws_protocols protocols[3];
    Housekeeping housekeeping{};

    /// Every accepted connection, HTTP or WebSocket, from accept to close; `pending` until its HTTP
    /// request is in or its hello accepted (what the per-address cap counts).
    struct Peer {
        std::string address;
        Clock::time_point opened = Clock::now();
        bool pending = true;
    };
    std::map<lws*, Peer> peers;
    std::map<std::string, int> pendingByAddress;
    int connectionCap = 0;
    std::set<lws*> bodiesPending; ///< POST requests whose body has not completed
    /// Refusals are logged, but at most kRefusalLinesPerTick lines per housekeeping tick and reason:
    /// a flood must not become a flood of log lines. The rest are counted and summed up.
    static constexpr int kRefusalLinesPerTick = 5;
    std::map<std::string, int> refusalLines, refusalsSuppressed;

    // Finished HTTP render jobs, handed from workers to the loop.
    std::mutex doneMutex;
    std::map<std::uint64_t, HttpResponse> done;
    std::map<std::uint64_t, lws*> awaiting;
    /// Unpacks zipped uploads (declared after `done`: joined before it goes).
    std::unique_ptr<BackgroundQueue> unpacker = std::make_unique<BackgroundQueue>();
    std::uint64_t nextJobId = 1;

    static Impl* from(lws* wsi) { return static_cast<Impl*>(lws_context_user(lws_get_context(wsi))); }

    // --- metrics ----------------------------------------------------------------------------
    void countError(const std::string& code) {
        metrics.counter("gis_errors_total", "error messages sent to clients, by code", {{"code", code}})
            .inc();
    }
    void countHttp(const std::string& endpoint, unsigned status) {
        metrics
            .counter("gis_http_requests_total", "HTTP requests by endpoint and status",
                     {{"endpoint", endpoint}, {"status", std::to_string(status)}})
            .inc();
    }
    void onFrame(const FrameReport& r) {
        metrics.counter("gis_frames_total", "frames rendered, by quality step", {{"quality", r.quality}})
            .inc();
        metrics.histogram("gis_frame_ms", "frame render time", defaultLatencyBucketsMs()).observe(r.frameMs);
        metrics
            .histogram("gis_admission_wait_ms", "time a render waited for a render slot",
                       defaultLatencyBucketsMs())
            .observe(r.queueMs);
        metrics.histogram("gis_encode_ms", "frame encoding time", defaultLatencyBucketsMs())
            .observe(r.encodeMs);
        for (const auto& [pass, ms] : r.passMs)
            metrics
                .histogram("gis_pass_ms", "per-pass render time", defaultLatencyBucketsMs(), {{"pass", pass}})
                .observe(ms);
        if (r.dropped)
            metrics.counter("gis_frames_dropped_total", "frames a client skipped (window full or replaced)")
                .inc(static_cast<double>(r.dropped));
    }
    void updateGauges() {
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
        metrics.gauge("gis_uptime_seconds", "seconds since the server started")
            .set(std::chrono::duration<double>(Clock::now() - started).count());
        metrics.gauge("gis_draining", "1 while the server drains after SIGTERM (no new sessions)")
            .set(phase == Phase::Running ? 0.0 : 1.0);
    }

    // --- connections and refusals ---------------------------------------------------------------
    void logRefusal(const std::string& reason, const std::string& detail) {
        metrics
            .counter("gis_refusals_total", "requests and connections refused, by reason",
                     {{"reason", reason}})
            .inc();
        if (refusalLines[reason]++ < kRefusalLinesPerTick)
            logWarn("net: refused (" + reason + "): " + validUtf8(detail));
        else
            ++refusalsSuppressed[reason];
    }
    void flushRefusalLog() {
        for (const auto& [reason, count] : refusalsSuppressed)
            if (count > 0)
                logWarn("net: refused (" + reason + "): " + std::to_string(count) +
                        " more in the last 0.5 s");
        refusalsSuppressed.clear();
        refusalLines.clear();
    }
    std::string peerAddress(lws* wsi) const {
        auto it = peers.find(wsi);
        return it == peers.end() ? std::string("unknown") : it->second.address;
    }
    /// Before lws reads a byte: the overall cap (below the open-file limit) and the per-address cap on
    /// connections that have not finished their request or hello.
    bool admitConnection(const lws_filter_network_conn_args& args) {
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
    void peerCreated(lws* wsi) {
        char name[INET6_ADDRSTRLEN + 8] = {};
        const char* address = lws_get_peer_simple(wsi, name, sizeof name);
        Peer& peer = peers[wsi];
        if (!peer.address.empty()) return; // counted already
        peer.address = address && *address ? address : "unknown";
        peer.pending = true;
        ++pendingByAddress[peer.address];
    }
    void settle(lws* wsi) {
        auto it = peers.find(wsi);
        if (it == peers.end() || !it->second.pending || it->second.address.empty()) return;
        it->second.pending = false;
        if (--pendingByAddress[it->second.address] <= 0) pendingByAddress.erase(it->second.address);
    }
    void peerDestroyed(lws* wsi) {
        settle(wsi);
        peers.erase(wsi);
        bodiesPending.erase(wsi);
    }

    // --- access control -----------------------------------------------------------------------
    bool originAllowed(lws* wsi) {
        const std::string origin = header(wsi, WSI_TOKEN_ORIGIN);
        if (origin.empty()) return true; // not a browser: the token (if any) decides
        const std::string host = header(wsi, WSI_TOKEN_HOST);
        if (origin == "http://" + host || origin == "https://" + host) return true;
        for (const auto& o : config.allowOrigins)
            if (origin == o) return true;
        return false;
    }
    bool bearerOk(lws* wsi) {
        if (config.token.empty()) return true;
        const std::string token = bearerToken(header(wsi, WSI_TOKEN_HTTP_AUTHORIZATION));
        return !token.empty() && sameSecret(token, config.token);
    }

    // --- HTTP -------------------------------------------------------------------------------
    /// A fresh exchange for the request on `wsi`, owned by `exchanges` (lws's per-connection memory
    /// is plain and zeroed: it can only point); the previous one on the connection goes.
    HttpExchange& beginExchange(lws* wsi, PerSession* pss) {
        auto& owned = exchanges[wsi];
        owned = std::make_unique<HttpExchange>();
        pss->http = owned.get();
        return *owned;
    }
    void endExchange(lws* wsi, PerSession* pss) {
        if (pss) pss->http = nullptr;
        exchanges.erase(wsi);
    }

    void respond(lws* wsi, PerSession* pss, HttpResponse response) {
        if (!pss->http) beginExchange(wsi, pss);
        countHttp(pss->http->endpoint.empty() ? "static" : pss->http->endpoint, response.status);
        if (response.status >= 400 && response.status != 404)
            logRefusal("http_" + std::to_string(response.status), peerAddress(wsi) + " " +
                                                                      (pss->http->post ? "POST " : "GET ") +
                                                                      pss->http->uri.substr(0, 200));
        if (pss->http->post && !pss->http->bodyDone) {
            // Answered before its body came (auth, origin, limits): the body is not read, the
            // connection closes once the answer is out.
            pss->http->closeAfter = true;
            bodiesPending.erase(wsi);
            response.headers.emplace_back("connection:", "close");
        }
        pss->http->response = std::move(response);
        pss->http->ready = true;
        lws_callback_on_writable(wsi);
    }

    int writeHttp(lws* wsi, PerSession* pss) {
        HttpExchange* x = pss ? pss->http : nullptr;
        if (!x || !x->ready) return 0;
        HttpResponse& r = x->response;
        if (!x->headersSent) {
            std::size_t extra = 512 + r.contentType.size();
            for (const auto& [k, v] : r.headers) extra += k.size() + v.size() + 8;
            std::vector<unsigned char> buf(LWS_PRE + extra);
            unsigned char* start = buf.data() + LWS_PRE;
            unsigned char* p = start;
            unsigned char* end = buf.data() + buf.size() - 1;
            if (lws_add_http_common_headers(wsi, r.status, r.contentType.c_str(), r.body.size(), &p, end))
                return -1;
            for (const auto& [k, v] : r.headers)
                if (lws_add_http_header_by_name(wsi, reinterpret_cast<const unsigned char*>(k.c_str()),
                                                reinterpret_cast<const unsigned char*>(v.data()),
                                                static_cast<int>(v.size()), &p, end))
                    return -1;
            if (lws_finalize_write_http_header(wsi, start, &p, end)) return -1;
            x->headersSent = true;
            lws_callback_on_writable(wsi);
            return 0;
        }
        std::vector<unsigned char> body(LWS_PRE + r.body.size());
        std::memcpy(body.data() + LWS_PRE, r.body.data(), r.body.size());
        const int n = lws_write(wsi, body.data() + LWS_PRE, r.body.size(), LWS_WRITE_HTTP_FINAL);
        const bool closeAfter = pss->http->closeAfter;
        endExchange(wsi, pss);
        if (n < 0 || closeAfter) return -1;
        return lws_http_transaction_completed(wsi) ? -1 : 0;
    }

    int serveFile(lws* wsi, PerSession* pss, const std::string& uri) {
        std::string path = uri == "/" ? "/index.html" : uri;
        if (path.find("..") != std::string::npos || path.find('\\') != std::string::npos || path[0] != '/') {
            respond(wsi, pss, errorReply(400, "bad_path", "paths may not contain '..' or backslashes"));
            return 0;
        }
        char resolved[PATH_MAX];
        const std::string full = config.clientDir + path;
        if (!realpath(full.c_str(), resolved) || std::string(resolved).rfind(clientRoot + "/", 0) != 0) {
            respond(wsi, pss, errorReply(404, "not_found", "no such file: " + uri));
            return 0;
        }
        countHttp("static", 200);
        int n = lws_serve_http_file(wsi, resolved, mimeType(resolved).c_str(), nullptr, 0);
        if (n < 0 || (n > 0 && lws_http_transaction_completed(wsi))) return -1;
        return 0;
    }

    nlohmann::json scenesJson() const {
        nlohmann::json list = nlohmann::json::array();
        for (const auto& n : catalog->list()) list.push_back(n);
        return list;
    }

    int onHttpRequest(lws* wsi, PerSession* pss, const std::string& uri) {
        const bool post = lws_hdr_total_length(wsi, WSI_TOKEN_POST_URI) > 0;
        beginExchange(wsi, pss);
        pss->http->uri = uri;
        pss->http->post = post;
        pss->http->endpoint =
            uri.rfind("/api/", 0) == 0 || uri == "/metrics" || uri == "/healthz" ? uri : "static";
        if (!post) {
            pss->http->bodyDone = true;
            settle(wsi); // a GET is complete with its headers
        } else {
            auto peer = peers.find(wsi);
            const Clock::time_point start =
                peer != peers.end() && peer->second.pending ? peer->second.opened : Clock::now();
            pss->http->deadline = start + std::chrono::seconds(config.requestTimeoutS);
            bodiesPending.insert(wsi);
        }
        if (uri == "/healthz") {
            // 503 while draining: readiness probes and load balancers stop sending new clients here.
            const bool draining = phase != Phase::Running;
            nlohmann::json body = {
                {"status", draining ? "draining" : "ok"},
                {"sessions", sessions->size()},
                {"renders_active", gate->active()},
                {"renders_waiting", gate->waiting()},
                {"teardowns_pending", reaper->pending()},
                {"uptime_s", std::chrono::duration<double>(Clock::now() - started).count()}};
            if (draining)
                body["drain_remaining_s"] =
                    std::max(0.0, std::chrono::duration<double>(drainDeadline - Clock::now()).count());
            respond(wsi, pss, jsonReply(draining ? 503 : 200, body));
            return 0;
        }
        const bool api = uri.rfind("/api/", 0) == 0 || uri == "/metrics";
        if (api && !originAllowed(wsi)) {
            respond(wsi, pss, errorReply(403, "forbidden_origin", "this origin may not use the API"));
            return 0;
        }
        if (api && !bearerOk(wsi)) {
            HttpResponse r = errorReply(401, "unauthorized", "send 'Authorization: Bearer <token>'");
            r.headers.emplace_back("www-authenticate:", "Bearer");
            respond(wsi, pss, std::move(r));
            return 0;
        }
        if (post) {
            // lws reads bodies by Content-Length only: a chunked body would never complete, and a
            // malformed length would wait forever.
            if (!header(wsi, WSI_TOKEN_HTTP_TRANSFER_ENCODING).empty()) {
                respond(wsi, pss,
                        errorReply(411, "length_required",
                                   "send the body with a Content-Length header; chunked transfer "
                                   "encoding is not accepted"));
                return 0;
            }
            const std::string length = header(wsi, WSI_TOKEN_HTTP_CONTENT_LENGTH);
            if (length.empty()) {
                respond(wsi, pss, errorReply(411, "length_required", "POST needs a Content-Length header"));
                return 0;
            }
            if (length.size() > 12 || length.find_first_not_of("0123456789") != std::string::npos) {
                respond(wsi, pss,
                        errorReply(400, "bad_content_length",
                                   "Content-Length must be a non-negative decimal number, got '" +
                                       length.substr(0, 40) + "'"));
                return 0;
            }
            if (uri == "/api/render" && phase != Phase::Running) {
                HttpResponse r =
                    errorReply(503, "shutting_down",
                               "the server is shutting down; send the request to another instance");
                r.headers.emplace_back("retry-after:", "1");
                respond(wsi, pss, std::move(r));
                return 0;
            }
            if (uri == "/api/render") {
                pss->http->bodyLimit = kMaxRenderRequestBytes;
            } else if (uri == "/api/upload") {
                if (config.maxUploadMb == 0) {
                    respond(wsi, pss,
                            errorReply(403, "uploads_disabled", "this server does not accept uploads"));
                    return 0;
                }
                pss->http->bodyLimit = static_cast<std::size_t>(config.maxUploadMb) << 20;
            } else {
                respond(wsi, pss, errorReply(404, "not_found", "no POST endpoint " + uri));
                return 0;
            }
            if (std::stoull(length) > pss->http->bodyLimit) {
                // Refused from its header: the body is not read.
                respond(wsi, pss,
                        errorReply(413, "too_large",
                                   "the body of " + length + " bytes exceeds " +
                                       std::to_string(pss->http->bodyLimit) + " bytes for " + uri));
                return 0;
            }
            return 0; // the body follows (LWS_CALLBACK_HTTP_BODY)
        }
        if (uri == "/metrics") {
            updateGauges();
            respond(wsi, pss, {200, "text/plain; version=0.0.4; charset=utf-8", {}, metrics.render()});
            return 0;
        }
        if (uri == "/api/techniques") {
            respond(wsi, pss,
                    jsonReply(200, {{"techniques", techniquesJson()},
                                    {"frame_params_schema", frameParamTable().jsonSchema()}}));
            return 0;
        }
        if (uri == "/api/scenes") {
            respond(wsi, pss, jsonReply(200, {{"scenes", scenesJson()}}));
            return 0;
        }
        if (uri == "/api/render" || uri == "/api/upload") {
            HttpResponse r = errorReply(405, "method_not_allowed", uri + " takes POST");
            r.headers.emplace_back("allow:", "POST");
            respond(wsi, pss, std::move(r));
            return 0;
        }
        if (uri.rfind("/api/", 0) == 0) {
            respond(wsi, pss, errorReply(404, "not_found", "unknown API endpoint " + uri));
            return 0;
        }
        return serveFile(wsi, pss, uri);
    }

    void onHttpBody(lws* wsi, PerSession* pss) {
        HttpExchange* x = pss->http;
        bodiesPending.erase(wsi);
        if (x) x->bodyDone = true;
        settle(wsi);
        if (!x || x->ready) return; // already answered (auth, origin): the body is ignored
        if (x->bodyTooLarge) {
            respond(wsi, pss,
                    errorReply(413, "too_large",
                               "the body exceeds " + std::to_string(x->bodyLimit) + " bytes for " + x->uri));
            return;
        }
        if (x->uri == "/api/render")
            startRender(wsi, pss);
        else if (x->uri == "/api/upload")
            handleUpload(wsi, pss);
    }

    void startRender(lws* wsi, PerSession* pss) {
        HttpExchange* x = pss->http;
        std::string parseError;
        nlohmann::json request = parseJsonExplained(x->body, parseError);
        if (request.is_discarded() || !request.is_object()) {
            respond(
                wsi, pss,
                errorReply(400, "invalid_json",
                           request.is_discarded()
                               ? "the body is not valid JSON: " + parseError
                               : "the body must be a JSON object such as {\"scene\": \"builtin:cornell\"} "
                                 "(see PROTOCOL.md)"));
            return;
        }
        ApiReplyForm form = ApiReplyForm::Image;
        RenderLimits limits;
        limits.maxWidth = config.session.limits.maxWidth;
        limits.maxHeight = config.session.limits.maxHeight;
        std::shared_ptr<RenderJob> job;
        try {
            form = takeReplyForm(request);
            job = std::make_shared<RenderJob>(parseRenderRequest(request, limits));
        } catch (const InputError& e) {
            respond(wsi, pss, errorReply(400, "invalid_request", e.reason(), e.where()));
            return;
        }
        const std::uint64_t id = nextJobId++;
        auto catalogRef = catalog;
        auto sceneCache = scenes;
        lws_context* ctx = context;
        auto finish = [this, id, ctx](HttpResponse r) {
            {
                std::lock_guard lock(doneMutex);
                done[id] = std::move(r);
            }
            lws_cancel_service(ctx);
        };
        const long maxVpls = config.session.limits.maxVpls;
        auto work = [job, form, catalogRef, sceneCache, finish, maxVpls](FrameRenderer& renderer,
                                                                         double queueMs) {
            auto resolve = [&](const std::string& name) {
                return sceneCache->get(catalogRef->resolve(name), catalogRef->loadOptions(name));
            };
            finish(renderApiRequest(renderer, *job, resolve, maxVpls, queueMs, form));
        };
        auto fail = [finish](const std::string& message) {
            finish(errorReply(500, "render_failed", message));
        };
        if (!workers->submit(work, fail)) {
            HttpResponse r =
                errorReply(503, "busy", "every render slot and queue place is taken; retry shortly");
            r.headers.emplace_back("retry-after:", "1");
            respond(wsi, pss, std::move(r));
            return;
        }
        x->jobId = id;
        awaiting[id] = wsi;
    }

    /// A .zip upload: extracted beside on the unpacker's thread (SceneArchive checks every entry and
    /// the unpacked size against what the session's budget has left), then renamed over the old folder
    /// of that name; the answer is delivered on the loop like an API render's.
    void storeArchive(lws* wsi, PerSession* pss, const SessionEntry& entry, const std::string& name,
                      const fs::path& dir, std::uintmax_t room) {
        HttpExchange* x = pss->http;
        const std::uint64_t id = nextJobId++;
        lws_context* ctx = context;
        auto body = std::make_shared<const std::string>(std::move(x->body));
        x->body.clear();
        const std::string what = "net: session " + entry.session->id() + " stored upload:" + name + " (" +
                                 std::to_string(body->size()) + " bytes, scene ";
        const std::string from = ") from " + peerAddress(wsi);
        const int budgetMb = config.maxSessionUploadsMb;
        unpacker->retire([this, id, ctx, body, name, dir, room, what, from, budgetMb] {
            const fs::path partial = dir / ("." + name + ".part");
            std::error_code ec;
            fs::remove_all(partial, ec);
            HttpResponse response;
            try {
                const std::string sceneFile =
                    extractSceneArchive(*body, partial, ArchiveLimits{.maxBytes = room}, name);
                fs::remove_all(dir / name, ec);
                fs::rename(partial, dir / name, ec);
                if (ec) throw Error("cannot rename the extracted folder");
                logInfo(what + sceneFile + from);
                response = jsonReply(
                    201, {{"scene", "upload:" + name}, {"bytes", body->size()}, {"file", sceneFile}});
            } catch (const ArchiveTooLarge& e) {
                response = errorReply(413, "uploads_full",
                                      e.reason() + " (what this session's upload budget of " +
                                          std::to_string(budgetMb) + " MiB has left)");
            } catch (const InputError& e) {
                response = errorReply(400, "bad_archive", e.reason());
            } catch (const std::exception&) {
                fs::remove_all(partial, ec);
                response = errorReply(500, "upload_failed", "cannot store the upload");
            }
            {
                std::lock_guard lock(doneMutex);
                done[id] = std::move(response);
            }
            lws_cancel_service(ctx);
        });
        x->jobId = id;
        awaiting[id] = wsi;
    }

    void handleUpload(lws* wsi, PerSession* pss) {
        HttpExchange* x = pss->http;
        const std::string name = urlArg(wsi, "name=");
        try {
            SceneCatalog::checkUploadName(name);
        } catch (const InputError& e) {
            respond(wsi, pss, errorReply(400, "invalid_name", e.reason(), "name"));
            return;
        }
        const std::string token = customHeader(wsi, "x-gi-session:");
        const std::shared_ptr<SessionEntry> entry = sessions->byResumeToken(token);
        if (!entry) {
            respond(wsi, pss,
                    errorReply(404, "unknown_session",
                               "send the resume token of a live session in the X-GI-Session header"));
            return;
        }
        const bool zipped = name.ends_with(".zip");
        if (zipped && !looksLikeZip(x->body)) {
            respond(wsi, pss, errorReply(400, "not_zip", "the body is not a zip archive"));
            return;
        }
        if (!zipped && (x->body.size() < 12 || x->body.compare(0, 4, "glTF") != 0)) {
            respond(wsi, pss, errorReply(400, "not_glb", "the body is not a binary glTF (.glb) file"));
            return;
        }
        std::error_code ec;
        const fs::path dir = entry->session->uploadDir();
        fs::create_directories(dir, ec);
        // The session's uploads together (a replaced file no longer counts) stay within the budget;
        // an archive counts as what it unpacks to.
        std::uintmax_t stored = 0;
        for (auto it = fs::recursive_directory_iterator(dir, ec);
             !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
            if (it.depth() == 0 && it->path().filename() == name) {
                it.disable_recursion_pending();
                continue;
            }
            if (it->is_regular_file(ec)) stored += it->file_size(ec);
        }
        const std::uintmax_t budget = static_cast<std::uintmax_t>(config.maxSessionUploadsMb) << 20;
        if (zipped) {
            storeArchive(wsi, pss, *entry, name, dir, budget > stored ? budget - stored : 0);
            return;
        }
        if (stored + x->body.size() > budget) {
            respond(wsi, pss,
                    errorReply(413, "uploads_full",
                               "this session's uploads would take " +
                                   std::to_string((stored + x->body.size()) >> 20) +
                                   " MiB; a session may store " + std::to_string(config.maxSessionUploadsMb) +
                                   " MiB: upload under an existing name to replace a file"));
            return;
        }
        // Written beside, then renamed: a scene load never sees half a file.
        const fs::path partial = dir / ("." + name + ".part");
        {
            std::ofstream out(partial, std::ios::binary | std::ios::trunc);
            out.write(x->body.data(), static_cast<std::streamsize>(x->body.size()));
            if (!out) ec = std::make_error_code(std::errc::io_error);
        }
        if (!ec) fs::rename(partial, dir / name, ec);
        if (ec) {
            fs::remove(partial, ec);
            respond(wsi, pss, errorReply(500, "upload_failed", "cannot store the upload"));
            return;
        }
        logInfo("net: session " + entry->session->id() + " stored upload:" + name + " (" +
                std::to_string(x->body.size()) + " bytes) from " + peerAddress(wsi));
        respond(wsi, pss, jsonReply(201, {{"scene", "upload:" + name}, {"bytes", x->body.size()}}));
    }

    int onHttp(lws* wsi, lws_callback_reasons reason, PerSession* pss, void* in, size_t len) {
        switch (reason) {
        case LWS_CALLBACK_HTTP: {
            if (!pss) return -1;
            std::string uri(static_cast<const char*>(in),
                            strnlen(static_cast<const char*>(in), len ? len : 4096));
            return onHttpRequest(wsi, pss, uri);
        }
        case LWS_CALLBACK_HTTP_BODY:
            if (pss && pss->http && !pss->http->ready && !pss->http->closeAfter) {
                HttpExchange* x = pss->http;
                if (x->body.size() + len > x->bodyLimit) {
                    x->bodyTooLarge = true;
                    x->body.clear();
                } else if (!x->bodyTooLarge) {
                    x->body.append(static_cast<const char*>(in), len);
                }
            }
            return 0;
        case LWS_CALLBACK_HTTP_BODY_COMPLETION:
            if (pss) onHttpBody(wsi, pss);
            return 0;
        case LWS_CALLBACK_HTTP_WRITEABLE:
            return writeHttp(wsi, pss);
        case LWS_CALLBACK_HTTP_DROP_PROTOCOL:
        case LWS_CALLBACK_CLOSED_HTTP:
            bodiesPending.erase(wsi);
            if (pss && pss->http && pss->http->jobId)
                awaiting.erase(pss->http->jobId); // the result is discarded
            endExchange(wsi, pss);
            break;
        default:
            break;
        }
        return lws_callback_http_dummy(wsi, reason, pss, in, len);
    }

    void deliverFinishedJobs() {
        std::map<std::uint64_t, HttpResponse> finished;
        {
            std::lock_guard lock(doneMutex);
            finished.swap(done);
        }
        for (auto& [id, response] : finished) {
            auto it = awaiting.find(id);
            if (it == awaiting.end()) continue; // the client left
            lws* wsi = it->second;
            awaiting.erase(it);
            auto* pss = static_cast<PerSession*>(lws_wsi_user(wsi));
            if (!pss || !pss->http) continue;
            pss->http->jobId = 0;
            respond(wsi, pss, std::move(response));
        }
    }

    // --- WebSocket --------------------------------------------------------------------------
    void sendDirect(Connection& c, const nlohmann::json& msg) {
        if (msg.value("type", "") == "error") countError(msg.value("code", "unknown"));
        if (c.direct.size() >= kMaxDirectMessages) return; // a client that never reads loses replies
        c.direct.push_back(msg.dump());
        lws_callback_on_writable(c.wsi);
    }
    void sendError(Connection& c, const ProtocolError& e) { sendDirect(c, errorMessage(e)); }
    void closeWith(Connection& c, const ProtocolError& e, int code) {
        if (!c.helloDone) logRefusal(e.code, peerAddress(c.wsi) + ": " + e.message);
        sendError(c, e);
        c.closing = true;
        c.closeCode = code;
        c.closeReason = e.code;
        lws_callback_on_writable(c.wsi);
    }

    void endSession(const std::shared_ptr<SessionEntry>& entry, const std::string& code,
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

    nlohmann::json welcomeFor(const SessionEntry& entry, ClientRole role, bool resumed, int maxInFlight) {
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

    std::shared_ptr<ClientLink> makeLink(ClientRole role, int maxInFlight, bool acceptsPatches) {
        lws_context* ctx = context;
        return std::make_shared<ClientLink>(
            role, maxInFlight, [ctx] { lws_cancel_service(ctx); }, 64, acceptsPatches);
    }

    void onHello(Connection& c, const nlohmann::json& hello) {
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
                      {"unauthorized",
                       "this server needs its token in hello.token or an Authorization header", "/token",
                       "hello"},
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
            return hello.contains(key) ? std::optional<std::string>(hello[key].get<std::string>())
                                       : std::nullopt;
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
                closeWith(c,
                          {"render_failed", std::string("cannot start a session: ") + e.what(), "", "hello"},
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

    void onMessage(Connection& c, const std::string& text) {
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
                closeWith(c, {"hello_required", "send hello first (protocol/PROTOCOL.md)", "/type", type},
                          1008);
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

    /// The client messages the stream endpoint answers itself (`handler` "connection" in
    /// protocol/messages.json); the rest go to the session. Checked against the table at start.
    using ConnectionHandler = void (Impl::*)(Connection&, const nlohmann::json&);
    static const std::map<std::string, ConnectionHandler>& connectionHandlers() {
        static const std::map<std::string, ConnectionHandler> handlers = {
            {"hello", &Impl::onHelloAgain}, {"ping", &Impl::onPing}, {"ack", &Impl::onAck}};
        return handlers;
    }

    void onHelloAgain(Connection& c, const nlohmann::json&) {
        sendError(c, {"invalid_message", "hello was already accepted on this connection", "/type", "hello"});
    }

    void onPing(Connection& c, const nlohmann::json& msg) {
        nlohmann::json pong = {{"type", "pong"}};
        if (msg.contains("t")) pong["t"] = msg["t"];
        sendDirect(c, pong);
    }

    void onAck(Connection& c, const nlohmann::json& msg) {
        if (!c.entry || !c.link) return; // the session ended; the close is on its way
        try {
            c.entry->session->ack(c.link, msg["frame"].get<std::uint32_t>());
        } catch (const ProtocolError& e) {
            sendError(c, e);
        }
    }

    int onStream(lws* wsi, lws_callback_reasons reason, PerSession* pss, void* in, size_t len) {
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
                logRefusal("hello_required", peerAddress(wsi) + " sent a " +
                                                 (tooLarge ? "too large" : "binary") + " first message");
                closeWith(*c,
                          {"hello_required",
                           tooLarge ? "the first message must be a hello of at most " +
                                          std::to_string(config.maxMessageBytes) + " bytes"
                                    : "the first message must be a JSON text hello",
                           "", ""},
                          tooLarge ? 1009 : 1003);
            } else if (tooLarge)
                sendError(*c, {"message_too_large",
                               "messages are limited to " + std::to_string(config.maxMessageBytes) + " bytes",
                               "", ""});
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
                                 reinterpret_cast<unsigned char*>(c->closeReason.data()),
                                 c->closeReason.size());
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
            const int n = lws_write(wsi, c->tx.data() + LWS_PRE, data.size(),
                                    binary ? LWS_WRITE_BINARY : LWS_WRITE_TEXT);
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

    // --- shutdown -------------------------------------------------------------------------------
    static ProtocolError shuttingDown(const std::string& request, const std::string& message) {
        return {"shutting_down", message, "", request};
    }

    /// On the service thread after every lws_service() return: signals interrupt the wait and
    /// requestStop() wakes it, and the 0.5 s housekeeping timer bounds it, so deadlines are checked
    /// at least twice a second.
    void pollShutdown() {
        for (const int requests = stopRequests.load(); handledStopRequests < requests;) {
            ++handledStopRequests;
            if (phase == Phase::Running) {
                beginDrain();
            } else if (phase == Phase::Draining) {
                logInfo("net: second stop request: ending the drain now");
                beginClosing(std::chrono::milliseconds(500));
            } else {
                stop = true;
                return;
            }
        }
        if (phase == Phase::Running) return;
        const auto now = Clock::now();
        if (phase == Phase::Draining && ((sessions->empty() && awaiting.empty()) || now >= drainDeadline))
            beginClosing(std::chrono::seconds(2));
        if (phase == Phase::Closing && (connections.empty() || now >= closeDeadline)) stop = true;
    }

    void beginDrain() {
        phase = Phase::Draining;
        drainDeadline = Clock::now() + std::chrono::seconds(config.drainSeconds);
        logInfo("net: draining: new sessions are refused; " + std::to_string(sessions->size()) +
                " session(s) and " + std::to_string(awaiting.size()) + " HTTP render(s) have up to " +
                std::to_string(config.drainSeconds) + " s to finish (a second signal stops at once)");
        // A detached session waits for a resume that can no longer come (hello is refused).
        for (const auto& e : sessions->detached())
            endSession(e, "shutting_down",
                       "the server is shutting down and the session's controller is gone");
        const nlohmann::json notice = {
            {"type", "shutdown"},
            {"grace_s", config.drainSeconds},
            {"message", "the server is shutting down: this session may continue for up to " +
                            std::to_string(config.drainSeconds) +
                            " s; connect again (without resume) to reach another instance"}};
        for (auto& [wsi, c] : connections) {
            if (c->closing) continue;
            if (!c->helloDone)
                closeWith(*c, shuttingDown("", "the server is shutting down"), 1001);
            else if (c->entry)
                sendDirect(*c, notice);
        }
        updateGauges();
    }

    /// Ends every session (clients get `shutting_down` and close 1001) and gives the close frames
    /// `flush` to go out before the loop ends.
    void beginClosing(Clock::duration flush) {
        phase = Phase::Closing;
        closeDeadline = Clock::now() + flush;
        if (!sessions->empty())
            logInfo("net: drain over: closing " + std::to_string(sessions->size()) + " session(s)");
        for (const auto& e : sessions->all())
            endSession(e, "shutting_down", "the server's drain period is over");
        for (auto& [wsi, c] : connections)
            if (!c->closing) closeWith(*c, shuttingDown("", "the server is shutting down"), 1001);
    }

    void onWake() {
        endFailedSessions();
        for (auto& [w, c] : connections)
            if (!c->direct.empty() || (c->link && c->link->hasOutgoing())) lws_callback_on_writable(w);
        deliverFinishedJobs();
    }

    /// A session whose renderer failed ends alone, with the reason; the process and every other
    /// session go on.
    void endFailedSessions() {
        for (const auto& e : sessions->all())
            if (e->session->failed()) endSession(e, "render_failed", e->session->failure());
    }

    void housekeep() {
        const auto now = Clock::now();
        flushRefusalLog();
        endFailedSessions();
        for (lws* wsi : std::set<lws*>(bodiesPending)) {
            auto* pss = static_cast<PerSession*>(lws_wsi_user(wsi));
            if (!pss || !pss->http) {
                bodiesPending.erase(wsi);
                continue;
            }
            if (now < pss->http->deadline) continue;
            respond(wsi, pss,
                    errorReply(408, "request_timeout",
                               "the request did not arrive within " + std::to_string(config.requestTimeoutS) +
                                   " s (--request-timeout)"));
        }
        for (auto& [w, c] : connections)
            if (!c->helloDone && !c->closing && now - c->opened > std::chrono::seconds(config.helloTimeoutS))
                closeWith(*c,
                          {"hello_required", "no hello within " + std::to_string(config.helloTimeoutS) + " s",
                           "", ""},
                          1008);
        for (const auto& expiry : sessions->expired(now))
            endSession(expiry.entry, expiry.code, expiry.message);
        updateGauges();
        if (!stop) scheduleHousekeeping();
    }

    void scheduleHousekeeping() {
        housekeeping.self = this;
        lws_sul_schedule(
            context, 0, &housekeeping.sul,
            [](lws_sorted_usec_list_t* sul) { reinterpret_cast<Housekeeping*>(sul)->self->housekeep(); },
            500 * LWS_US_PER_MS);
    }

    /// protocols[0] sees every connection first: accept filter, creation and destruction, upgrades.
    int onConnectionEvent(lws* wsi, lws_callback_reasons reason, void* user, bool& handled) {
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
                const char* why = uri != "/ws"
                                      ? "WebSocket upgrades are served on /ws only"
                                      : "send Sec-WebSocket-Protocol: gi-stream (protocol/PROTOCOL.md)";
                lws_return_http_status(wsi, uri != "/ws" ? HTTP_STATUS_NOT_FOUND : HTTP_STATUS_BAD_REQUEST,
                                       why);
                return 1;
            }
            return 0;
        }
        default:
            handled = false;
            return 0;
        }
    }

    static int httpCallback(lws* wsi, lws_callback_reasons reason, void* user, void* in, size_t len) {
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
    static int streamCallback(lws* wsi, lws_callback_reasons reason, void* user, void* in, size_t len) {
        Impl* self = from(wsi);
        return self ? self->onStream(wsi, reason, static_cast<PerSession*>(user), in, len) : 0;
    }
};

WsServer::WsServer(ServerConfig config) : mImpl(std::make_unique<Impl>()) {
    Impl& m = *mImpl;
    m.config = std::move(config);
    for (const ClientMessageSpec& spec : clientMessages())
        if (spec.connection != (Impl::connectionHandlers().count(spec.type) == 1))
            throw Error("net: protocol/messages.json says '" + spec.type + "' is answered by the " +
                        (spec.connection ? "connection" : "session") + ", and the stream endpoint disagrees");
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
