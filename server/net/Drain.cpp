// Stopping well: the drain after SIGTERM (no new sessions, clients told, running sessions finish), closing,
// the wake-ups from workers, and the 0.5 s housekeeping (request and hello deadlines, expired and failed
// sessions, gauges).
#include "net/ServerInternals.h"

namespace gis {

ProtocolError WsServer::Impl::shuttingDown(const std::string& request, const std::string& message) {
    return {"shutting_down", message, "", request};
}

void WsServer::Impl::pollShutdown() {
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

void WsServer::Impl::beginDrain() {
    phase = Phase::Draining;
    drainDeadline = Clock::now() + std::chrono::seconds(config.drainSeconds);
    logInfo("net: draining: new sessions are refused; " + std::to_string(sessions->size()) +
            " session(s) and " + std::to_string(awaiting.size()) + " HTTP render(s) have up to " +
            std::to_string(config.drainSeconds) + " s to finish (a second signal stops at once)");
    // A detached session waits for a resume that can no longer come (hello is refused).
    for (const auto& e : sessions->detached())
        endSession(e, "shutting_down", "the server is shutting down and the session's controller is gone");
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

void WsServer::Impl::beginClosing(Clock::duration flush) {
    phase = Phase::Closing;
    closeDeadline = Clock::now() + flush;
    if (!sessions->empty())
        logInfo("net: drain over: closing " + std::to_string(sessions->size()) + " session(s)");
    for (const auto& e : sessions->all()) endSession(e, "shutting_down", "the server's drain period is over");
    for (auto& [wsi, c] : connections)
        if (!c->closing) closeWith(*c, shuttingDown("", "the server is shutting down"), 1001);
}

void WsServer::Impl::onWake() {
    endFailedSessions();
    for (auto& [w, c] : connections)
        if (!c->direct.empty() || (c->link && c->link->hasOutgoing())) lws_callback_on_writable(w);
    deliverFinishedJobs();
}

void WsServer::Impl::endFailedSessions() {
    for (const auto& e : sessions->all())
        if (e->session->failed()) endSession(e, "render_failed", e->session->failure());
}

void WsServer::Impl::housekeep() {
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
            closeWith(
                *c,
                {"hello_required", "no hello within " + std::to_string(config.helloTimeoutS) + " s", "", ""},
                1008);
    for (const auto& expiry : sessions->expired(now)) endSession(expiry.entry, expiry.code, expiry.message);
    updateGauges();
    if (!stop) scheduleHousekeeping();
}

void WsServer::Impl::scheduleHousekeeping() {
    housekeeping.self = this;
    lws_sul_schedule(
        context, 0, &housekeeping.sul,
        [](lws_sorted_usec_list_t* sul) { reinterpret_cast<Housekeeping*>(sul)->self->housekeep(); },
        500 * LWS_US_PER_MS);
}

} // namespace gis
