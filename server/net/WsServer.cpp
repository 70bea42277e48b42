#include "net/WsServer.h"

#include <libwebsockets.h>

#include <climits>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

#include "core/Error.h"
#include "core/Log.h"
#include "gi/Technique.h"
#include "render/FrameParams.h"
#include "scene/SceneLoader.h"

namespace gis {
namespace {

/// Joins finished sessions' render threads away from the service thread.
class Reaper {
public:
    Reaper() : mThread([this] { loop(); }) {}
    ~Reaper() {
        {
            std::lock_guard lock(mMutex);
            mStop = true;
        }
        mCv.notify_all();
        mThread.join();
    }
    void retire(std::shared_ptr<Session> s) {
        {
            std::lock_guard lock(mMutex);
            mQueue.push_back(std::move(s));
        }
        mCv.notify_all();
    }

private:
    void loop() {
        std::unique_lock lock(mMutex);
        while (true) {
            mCv.wait(lock, [&] { return mStop || !mQueue.empty(); });
            while (!mQueue.empty()) {
                auto s = std::move(mQueue.front());
                mQueue.pop_front();
                lock.unlock();
                s->stop();
                s.reset();
                lock.lock();
            }
            if (mStop) return;
        }
    }
    std::mutex mMutex;
    std::condition_variable mCv;
    std::deque<std::shared_ptr<Session>> mQueue;
    bool mStop = false;
    std::thread mThread;
};

struct Connection {
    std::shared_ptr<Session> session;
    std::string rx;
    bool rxTooLarge = false;
    std::vector<unsigned char> tx; // LWS_PRE headroom + message
};

struct HttpReply {
    std::vector<unsigned char> body; // LWS_PRE headroom + body
};

// Per-connection storage lws allocates (zeroed, plain memory): pointers to our objects only.
struct PerSession {
    Connection* connection;
    HttpReply* reply;
};

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
    return {{"techniques", list}, {"frame_params_schema", frameParamTable().jsonSchema()}};
}

} // namespace

struct WsServer::Impl {
    ServerConfig config;
    std::string clientRoot; // realpath of config.clientDir
    lws_context* context = nullptr;
    std::atomic<bool> stop{false};
    std::shared_ptr<SceneCache> scenes = std::make_shared<SceneCache>();
    std::map<lws*, std::unique_ptr<Connection>> connections;
    std::unique_ptr<Reaper> reaper = std::make_unique<Reaper>();
    std::uint64_t nextSessionId = 1;
    lws_protocols protocols[3];

    static Impl* from(lws* wsi) { return static_cast<Impl*>(lws_context_user(lws_get_context(wsi))); }

    // --- HTTP -------------------------------------------------------------------------------
    int replyJson(lws* wsi, PerSession* pss, unsigned status, const nlohmann::json& body) {
        const std::string text = body.dump();
        unsigned char headers[LWS_PRE + 1024];
        unsigned char* start = headers + LWS_PRE;
        unsigned char* p = start;
        unsigned char* end = headers + sizeof headers - 1;
        if (lws_add_http_common_headers(wsi, status, "application/json", text.size(), &p, end)) return 1;
        if (lws_finalize_write_http_header(wsi, start, &p, end)) return 1;
        delete pss->reply;
        pss->reply = new HttpReply;
        pss->reply->body.resize(LWS_PRE + text.size());
        std::memcpy(pss->reply->body.data() + LWS_PRE, text.data(), text.size());
        lws_callback_on_writable(wsi);
        return 0;
    }

    int serveFile(lws* wsi, PerSession* pss, const std::string& uri) {
        std::string path = uri == "/" ? "/index.html" : uri;
        if (path.find("..") != std::string::npos || path.find('\\') != std::string::npos || path[0] != '/')
            return replyJson(wsi, pss, HTTP_STATUS_BAD_REQUEST, {{"error", "bad path"}});
        char resolved[PATH_MAX];
        const std::string full = config.clientDir + path;
        if (!realpath(full.c_str(), resolved) || std::string(resolved).rfind(clientRoot + "/", 0) != 0)
            return replyJson(wsi, pss, HTTP_STATUS_NOT_FOUND, {{"error", "not found"}, {"path", uri}});
        int n = lws_serve_http_file(wsi, resolved, mimeType(resolved).c_str(), nullptr, 0);
        if (n < 0 || (n > 0 && lws_http_transaction_completed(wsi))) return -1;
        return 0;
    }

    int onHttp(lws* wsi, lws_callback_reasons reason, PerSession* pss, void* in, size_t len) {
        switch (reason) {
        case LWS_CALLBACK_HTTP: {
            std::string uri(static_cast<const char*>(in), strnlen(static_cast<const char*>(in), len ? len : 4096));
            if (uri == "/healthz")
                return replyJson(wsi, pss, HTTP_STATUS_OK, {{"status", "ok"}, {"sessions", connections.size()}});
            if (uri == "/api/techniques") return replyJson(wsi, pss, HTTP_STATUS_OK, techniquesJson());
            if (uri == "/api/scenes") {
                nlohmann::json list = nlohmann::json::array();
                for (const auto& n : builtinSceneNames()) list.push_back("builtin:" + n);
                return replyJson(wsi, pss, HTTP_STATUS_OK, {{"scenes", list}});
            }
            if (uri.rfind("/api/", 0) == 0)
                return replyJson(wsi, pss, HTTP_STATUS_NOT_FOUND, {{"error", "unknown API endpoint"}, {"path", uri}});
            return serveFile(wsi, pss, uri);
        }
        case LWS_CALLBACK_HTTP_WRITEABLE: {
            if (!pss || !pss->reply) break;
            auto& b = pss->reply->body;
            int n = lws_write(wsi, b.data() + LWS_PRE, b.size() - LWS_PRE, LWS_WRITE_HTTP_FINAL);
            delete pss->reply;
            pss->reply = nullptr;
            if (n < 0) return -1;
            if (lws_http_transaction_completed(wsi)) return -1;
            return 0;
        }
        case LWS_CALLBACK_HTTP_DROP_PROTOCOL:
        case LWS_CALLBACK_CLOSED_HTTP:
            if (pss) {
                delete pss->reply;
                pss->reply = nullptr;
            }
            break;
        default: break;
        }
        return lws_callback_http_dummy(wsi, reason, pss, in, len);
    }

    // --- WebSocket --------------------------------------------------------------------------
    int onStream(lws* wsi, lws_callback_reasons reason, PerSession* pss, void* in, size_t len) {
        switch (reason) {
        case LWS_CALLBACK_ESTABLISHED: {
            if (static_cast<int>(connections.size()) >= config.maxSessions) {
                const char msg[] = "busy: the server has reached its session limit";
                // 1013 "try again later" (RFC 6455 registry) is not in lws 4.1's enum.
                lws_close_reason(wsi, static_cast<lws_close_status>(1013),
                                 reinterpret_cast<unsigned char*>(const_cast<char*>(msg)), sizeof msg - 1);
                logWarn("net: refused a session: " + std::to_string(connections.size()) + " sessions open");
                return -1;
            }
            auto conn = std::make_unique<Connection>();
            lws_context* ctx = context;
            try {
                conn->session = std::make_shared<Session>("s" + std::to_string(nextSessionId++), config.session,
                                                          scenes, [ctx] { lws_cancel_service(ctx); });
                conn->session->start();
            } catch (const std::exception& e) {
                logError(std::string("net: cannot start a session: ") + e.what());
                return -1;
            }
            pss->connection = conn.get();
            logInfo("net: session " + conn->session->id() + " opened (" + std::to_string(connections.size() + 1) +
                    " open)");
            connections[wsi] = std::move(conn);
            lws_callback_on_writable(wsi);
            break;
        }
        case LWS_CALLBACK_RECEIVE: {
            Connection* c = pss ? pss->connection : nullptr;
            if (!c) break;
            if (!c->rxTooLarge) {
                if (c->rx.size() + len > config.maxMessageBytes) {
                    c->rxTooLarge = true;
                    c->rx.clear();
                } else {
                    c->rx.append(static_cast<const char*>(in), len);
                }
            }
            if (!lws_is_final_fragment(wsi) || lws_remaining_packet_payload(wsi) > 0) break;
            if (c->rxTooLarge) {
                c->session->queueError({"message_too_large",
                                        "messages are limited to " + std::to_string(config.maxMessageBytes) + " bytes",
                                        "", ""});
            } else if (lws_frame_is_binary(wsi)) {
                c->session->queueError({"binary_not_accepted", "clients send JSON text messages only", "", ""});
            } else {
                c->session->handleText(c->rx);
            }
            c->rx.clear();
            c->rxTooLarge = false;
            if (c->session->hasOutgoing()) lws_callback_on_writable(wsi);
            break;
        }
        case LWS_CALLBACK_SERVER_WRITEABLE: {
            Connection* c = pss ? pss->connection : nullptr;
            if (!c) break;
            OutgoingMessage m;
            if (!c->session->popOutgoing(m)) break;
            c->tx.resize(LWS_PRE + m.data.size());
            std::memcpy(c->tx.data() + LWS_PRE, m.data.data(), m.data.size());
            int n = lws_write(wsi, c->tx.data() + LWS_PRE, m.data.size(), m.binary ? LWS_WRITE_BINARY : LWS_WRITE_TEXT);
            if (n < static_cast<int>(m.data.size())) {
                logWarn("net: write failed on session " + c->session->id());
                return -1;
            }
            if (c->session->hasOutgoing()) lws_callback_on_writable(wsi);
            break;
        }
        case LWS_CALLBACK_CLOSED: {
            auto it = connections.find(wsi);
            if (it != connections.end()) {
                logInfo("net: session " + it->second->session->id() + " closed after " +
                        std::to_string(it->second->session->framesSent()) + " frames");
                reaper->retire(std::move(it->second->session));
                connections.erase(it);
            }
            if (pss) pss->connection = nullptr;
            break;
        }
        case LWS_CALLBACK_EVENT_WAIT_CANCELLED:
            for (auto& [w, c] : connections)
                if (c->session->hasOutgoing()) lws_callback_on_writable(w);
            break;
        default: break;
        }
        return 0;
    }

    static int httpCallback(lws* wsi, lws_callback_reasons reason, void* user, void* in, size_t len) {
        Impl* self = from(wsi);
        return self ? self->onHttp(wsi, reason, static_cast<PerSession*>(user), in, len)
                    : lws_callback_http_dummy(wsi, reason, user, in, len);
    }
    static int streamCallback(lws* wsi, lws_callback_reasons reason, void* user, void* in, size_t len) {
        Impl* self = from(wsi);
        return self ? self->onStream(wsi, reason, static_cast<PerSession*>(user), in, len) : 0;
    }
};

WsServer::WsServer(ServerConfig config) : mImpl(std::make_unique<Impl>()) {
    mImpl->config = std::move(config);
    char resolved[PATH_MAX];
    if (!realpath(mImpl->config.clientDir.c_str(), resolved))
        throw InputError("--client-dir", "directory '" + mImpl->config.clientDir + "' does not exist");
    mImpl->clientRoot = resolved;
    mImpl->config.clientDir = resolved;
}

WsServer::~WsServer() {
    if (mImpl->context) lws_context_destroy(mImpl->context); // closes connections: sessions retire
    mImpl->reaper.reset();                                    // joins every render thread
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
    mImpl->context = lws_create_context(&info);
    if (!mImpl->context)
        throw Error("net: cannot listen on " + mImpl->config.host + ":" + std::to_string(mImpl->config.port) +
                    " (address in use or not available?)");
    mPort = mImpl->config.port;
}

void WsServer::run() {
    while (!mImpl->stop.load()) {
        if (lws_service(mImpl->context, 0) < 0) break;
    }
}

void WsServer::requestStop() {
    mImpl->stop = true;
    if (mImpl->context) lws_cancel_service(mImpl->context);
}

} // namespace gis
