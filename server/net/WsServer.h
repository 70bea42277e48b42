// The network front end on libwebsockets 4.1: static client files and a small JSON API over HTTP,
// and one WebSocket session (sub-protocol "gi-stream") per viewer.
//
// Threading follows the lws rules: one service thread runs the event loop and is the only one that
// touches sockets. Render workers never write; they queue output in their Session and call
// lws_cancel_service(), which wakes the loop (LWS_CALLBACK_EVENT_WAIT_CANCELLED) to ask for
// writable callbacks. One lws_write per writable callback. The loop never renders or blocks:
// session teardown (joining a render thread) happens on a reaper thread.
#pragma once

#include <atomic>
#include <cstddef>
#include <memory>
#include <string>

#include "session/Session.h"

namespace gis {

struct ServerConfig {
    std::string host = "127.0.0.1";
    int port = 8080;                  ///< [1, 65535]
    std::string clientDir;            ///< directory served at /
    SessionConfig session;            ///< defaults for every new session
    int maxSessions = 8;              ///< further WebSocket connections are refused with 'busy'
    std::size_t maxMessageBytes = 65536; ///< larger client messages are rejected (message_too_large)
};

class WsServer {
public:
    explicit WsServer(ServerConfig config);
    ~WsServer();
    /// Creates the listening socket; throws gis::Error when it cannot (port in use, bad address).
    void listen();
    int port() const { return mPort; }
    /// Runs the event loop until requestStop() (safe from signal handlers and other threads).
    void run();
    void requestStop();

    struct Impl;

private:
    std::unique_ptr<Impl> mImpl;
    int mPort = 0;
};

} // namespace gis
