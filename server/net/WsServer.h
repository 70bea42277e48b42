// The network front end on libwebsockets 4.1: static client files, the HTTP API (render, scenes,
// techniques, upload, health, Prometheus metrics) and the gi-stream WebSocket (protocol/PROTOCOL.md).
//
// Threading follows the lws rules: one service thread runs the event loop and is the only one that
// touches sockets. Render workers never write; they queue output in ClientLinks (or finished HTTP
// jobs in a list) and call lws_cancel_service(), which wakes the loop
// (LWS_CALLBACK_EVENT_WAIT_CANCELLED) to ask for writable callbacks. One lws_write per writable
// callback. The loop never renders or blocks: session teardown (joining a render thread) happens on a
// reaper thread, and a housekeeping timer ends sessions whose resume grace or idle time ran out.
#pragma once

#include <memory>
#include <string>

#include "net/ServerOptions.h"

namespace gis {

class WsServer {
public:
    /// Throws InputError for a client directory, scene directory or upload directory that is unusable.
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
