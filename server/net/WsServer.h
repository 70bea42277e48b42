// The network front end on libwebsockets 4.1: static client files, the HTTP API (render, scenes,
// techniques, upload, health, Prometheus metrics) and the gi-stream WebSocket (protocol/PROTOCOL.md).
//
// Threading follows the lws rules: one service thread runs the event loop and is the only one that
// touches sockets. Render workers never write; they queue output in ClientLinks (or finished HTTP
// jobs in a list) and call lws_cancel_service(), which wakes the loop
// (LWS_CALLBACK_EVENT_WAIT_CANCELLED) to ask for writable callbacks. One lws_write per writable
// callback. The loop never renders or blocks: session teardown (joining a render thread) happens on a
// reaper thread, and a housekeeping timer ends sessions whose resume grace or idle time ran out.
//
// Shutdown is a drain, driven by the loop itself: requestStop() (from a signal handler) only counts
// the request and wakes the loop. On the first request the loop stops taking sessions (hello gets
// `shutting_down`, /healthz answers 503 "draining"), tells every client `shutdown` with the grace
// period, and keeps serving running sessions until they end or `--drain-seconds` pass; then it closes
// the rest with 1001 and run() returns. A second request ends the drain at once: the close frames get
// half a second, and gi-server exits without waiting for frames still rendering.
//
// Hostile input (docs/service.md, "Limits"): every connection passes an overall cap below the
// open-file limit and a per-address cap on connections that have not finished their request or
// hello; HTTP requests have a whole-request deadline and bodies are read only for requests that were
// not already answered; the stream is served on /ws with the gi-stream sub-protocol only.
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
    /// Runs the event loop until the drain after requestStop() is over.
    void run();
    /// Starts the drain, or ends it when one is running. Async-signal-safe (an atomic increment and
    /// lws_cancel_service) and safe from any thread.
    void requestStop();
    /// True when run() returned because of a second stop request: the caller should exit within a
    /// second instead of waiting for frames still rendering.
    bool stoppedAtOnce() const;

    struct Impl;

private:
    std::unique_ptr<Impl> mImpl;
    int mPort = 0;
};

} // namespace gis
