// What the server's parts share (WsServer.cpp, HttpApi.cpp, StreamEndpoint.cpp, Drain.cpp): the
// per-connection records, the lws helpers and WsServer::Impl's declaration. Internal to server/net:
// nothing outside this folder includes it (it brings the wsserver names into namespace gis).
#pragma once

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
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <thread>
#include <vector>
#include "core/Error.h"
#include "core/JsonSchema.h"
#include "core/Log.h"
#include "core/Memory.h"
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
namespace wsserver {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
constexpr const char* kServerName = "gi-server/0.2.0";
constexpr std::size_t kMaxViewersPerSession = 32;
constexpr std::size_t kMaxRenderRequestBytes = 1 << 20;
constexpr std::size_t kMaxDirectMessages = 64;

/// Runs slow work away from the loop, in order, on one thread of its own: teardowns (joining render
/// threads, deleting upload sandboxes) on one queue, unpacking zipped uploads on another.
/// `whenDrained` runs on that thread each time the queue empties, before pending() falls to 0.
class BackgroundQueue {
public:
    explicit BackgroundQueue(std::function<void()> whenDrained = {})
        : mWhenDrained(std::move(whenDrained)), mThread([this] { loop(); }) {}
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
                if (mQueue.empty() && mWhenDrained) {
                    lock.unlock();
                    mWhenDrained();
                    lock.lock();
                }
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
    std::function<void()> mWhenDrained;
    std::thread mThread; // last: started once every other member is ready
};

inline std::string header(lws* wsi, lws_token_indexes token) {
    const int len = lws_hdr_total_length(wsi, token);
    if (len <= 0) return {};
    std::string out(static_cast<std::size_t>(len) + 1, '\0');
    if (lws_hdr_copy(wsi, out.data(), len + 1, token) < 0) return {};
    out.resize(static_cast<std::size_t>(len));
    return out;
}

inline std::string customHeader(lws* wsi, const char* name) {
    const int nameLen = static_cast<int>(std::strlen(name));
    const int len = lws_hdr_custom_length(wsi, name, nameLen);
    if (len <= 0) return {};
    std::string out(static_cast<std::size_t>(len) + 1, '\0');
    if (lws_hdr_custom_copy(wsi, out.data(), len + 1, name, nameLen) < 0) return {};
    out.resize(static_cast<std::size_t>(len));
    return out;
}

inline std::string addressText(const sockaddr_storage& address) {
    char text[INET6_ADDRSTRLEN] = {};
    if (address.ss_family == AF_INET)
        inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in&>(address).sin_addr, text, sizeof text);
    else if (address.ss_family == AF_INET6)
        inet_ntop(AF_INET6, &reinterpret_cast<const sockaddr_in6&>(address).sin6_addr, text, sizeof text);
    return text[0] ? text : "unknown";
}

inline std::string lowerCase(std::string text) {
    for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return text;
}

/// The token of an `Authorization: Bearer <token>` header; the scheme is case-insensitive (RFC 9110
/// 11.1) and surrounding blanks are ignored. Empty for any other header.
inline std::string bearerToken(const std::string& header) {
    const std::size_t space = header.find(' ');
    if (space == std::string::npos || lowerCase(header.substr(0, space)) != "bearer") return {};
    const std::size_t start = header.find_first_not_of(' ', space);
    if (start == std::string::npos) return {};
    const std::size_t end = header.find_last_not_of(" \t");
    return header.substr(start, end + 1 - start);
}

/// Default connection cap: the open-file limit less what sessions (GL contexts, upload files), the
/// listening socket, logs and libraries need, so that accept() never fails with EMFILE.
inline int connectionCapFromFileLimit(int maxSessions) {
    rlimit limit{};
    long files = 1024; // the common default, when the limit cannot be read
    if (getrlimit(RLIMIT_NOFILE, &limit) == 0)
        files = limit.rlim_cur == RLIM_INFINITY ? 1L << 20 : static_cast<long>(limit.rlim_cur);
    const long reserve = 64 + 16L * maxSessions;
    return static_cast<int>(std::clamp(files - reserve, 16L, 1L << 20));
}

inline std::string urlArg(lws* wsi, const char* name) {
    char buf[512];
    const char* v = lws_get_urlarg_by_name(wsi, name, buf, sizeof buf);
    return v ? std::string(v) : std::string();
}

inline std::string mimeType(const std::string& path) {
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

inline nlohmann::json techniquesJson() {
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

} // namespace wsserver
using namespace wsserver;

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
    /// Session teardowns. A session frees tens of MiB (GL context, frame resources, its scene's
    /// share) across the allocator arenas of its threads; trimming once the queue is empty gives
    /// them back, so the resident size after sessions end is what is still live (core/Memory.h).
    std::unique_ptr<BackgroundQueue> reaper = std::make_unique<BackgroundQueue>(releaseFreedMemory);
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

    // --- metrics, connections, access control, the loop's callbacks (WsServer.cpp)
    static Impl* from(lws* wsi);

    void countError(const std::string& code);
    void countHttp(const std::string& endpoint, unsigned status);
    void onFrame(const FrameReport& r);
    void updateGauges();

    void logRefusal(const std::string& reason, const std::string& detail);
    void flushRefusalLog();
    std::string peerAddress(lws* wsi) const;
    /// Before lws reads a byte: the overall cap (below the open-file limit) and the per-address cap on
    /// connections that have not finished their request or hello.
    bool admitConnection(const lws_filter_network_conn_args& args);
    void peerCreated(lws* wsi);
    void settle(lws* wsi);
    void peerDestroyed(lws* wsi);

    bool originAllowed(lws* wsi);
    bool bearerOk(lws* wsi);

    /// A fresh exchange for the request on `wsi`, owned by `exchanges` (lws's per-connection memory
    /// is plain and zeroed: it can only point); the previous one on the connection goes.
    // --- the HTTP API: routes, static files, render and upload requests (HttpApi.cpp)
    HttpExchange& beginExchange(lws* wsi, PerSession* pss);
    void endExchange(lws* wsi, PerSession* pss);

    void respond(lws* wsi, PerSession* pss, HttpResponse response);

    int writeHttp(lws* wsi, PerSession* pss);

    int serveFile(lws* wsi, PerSession* pss, const std::string& uri);

    nlohmann::json scenesJson() const;

    int onHttpRequest(lws* wsi, PerSession* pss, const std::string& uri);

    void onHttpBody(lws* wsi, PerSession* pss);

    void startRender(lws* wsi, PerSession* pss);

    /// A .zip upload: extracted beside on the unpacker's thread (SceneArchive checks every entry and
    /// the unpacked size against what the session's budget has left), then renamed over the old folder
    /// of that name; the answer is delivered on the loop like an API render's.
    void storeArchive(lws* wsi, PerSession* pss, const SessionEntry& entry, const std::string& name,
                      const fs::path& dir, std::uintmax_t room);

    void handleUpload(lws* wsi, PerSession* pss);

    int onHttp(lws* wsi, lws_callback_reasons reason, PerSession* pss, void* in, size_t len);

    void deliverFinishedJobs();

    // --- the gi-stream endpoint: hello, messages, welcome, closing (StreamEndpoint.cpp)
    void sendDirect(Connection& c, const nlohmann::json& msg);
    void sendError(Connection& c, const ProtocolError& e);
    void closeWith(Connection& c, const ProtocolError& e, int code);

    void endSession(const std::shared_ptr<SessionEntry>& entry, const std::string& code,
                    const std::string& message);

    nlohmann::json welcomeFor(const SessionEntry& entry, ClientRole role, bool resumed, int maxInFlight);

    std::shared_ptr<ClientLink> makeLink(ClientRole role, int maxInFlight, bool acceptsPatches);

    void onHello(Connection& c, const nlohmann::json& hello);

    void onMessage(Connection& c, const std::string& text);

    /// The client messages the stream endpoint answers itself (`handler` "connection" in
    /// protocol/messages.json); the rest go to the session. Checked against the table at start.
    using ConnectionHandler = void (Impl::*)(Connection&, const nlohmann::json&);
    static const std::map<std::string, ConnectionHandler>& connectionHandlers();

    void onHelloAgain(Connection& c, const nlohmann::json&);

    void onPing(Connection& c, const nlohmann::json& msg);

    void onAck(Connection& c, const nlohmann::json& msg);

    int onStream(lws* wsi, lws_callback_reasons reason, PerSession* pss, void* in, size_t len);

    // --- drain, wake-ups and housekeeping (Drain.cpp)
    static ProtocolError shuttingDown(const std::string& request, const std::string& message);

    /// On the service thread after every lws_service() return: signals interrupt the wait and
    /// requestStop() wakes it, and the 0.5 s housekeeping timer bounds it, so deadlines are checked
    /// at least twice a second.
    void pollShutdown();

    void beginDrain();

    /// Ends every session (clients get `shutting_down` and close 1001) and gives the close frames
    /// `flush` to go out before the loop ends.
    void beginClosing(Clock::duration flush);

    void onWake();

    /// A session whose renderer failed ends alone, with the reason; the process and every other
    /// session go on.
    void endFailedSessions();

    void housekeep();

    void scheduleHousekeeping();

    /// protocols[0] sees every connection first: accept filter, creation and destruction, upgrades.
    int onConnectionEvent(lws* wsi, lws_callback_reasons reason, void* user, bool& handled);

    static int httpCallback(lws* wsi, lws_callback_reasons reason, void* user, void* in, size_t len);
    static int streamCallback(lws* wsi, lws_callback_reasons reason, void* user, void* in, size_t len);
};

} // namespace gis
