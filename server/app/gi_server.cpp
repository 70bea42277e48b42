// gi-server: the interactive rendering service. Serves the web client, streams frames with per-pass
// stats over WebSockets (one render worker with its own GL context per session), answers one-shot
// HTTP render requests and exposes health and Prometheus metrics. Settings: net/ServerOptions.h.
// Exit codes: 0 clean shutdown (also after SIGTERM/SIGINT: docs/operations.md, graceful drain),
// 1 runtime failure, 2 bad usage.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <thread>

#include "core/CommandLine.h"
#include "core/Error.h"
#include "core/Log.h"
#include "frame/Presets.h"
#include "gi/Technique.h"
#include "gl/Platform.h"
#include "net/ServerOptions.h"
#include "net/WsServer.h"
#include "scene/SceneLoader.h"

#ifndef GIS_DEFAULT_CLIENT_DIR
#define GIS_DEFAULT_CLIENT_DIR "client"
#endif

namespace {

// Read by the signal handler: an atomic pointer, so that clearing it after the loop is not a data race.
std::atomic<gis::WsServer*> gServer{nullptr};
static_assert(std::atomic<gis::WsServer*>::is_always_lock_free);

// Async-signal-safe: requestStop() only bumps an atomic counter and wakes the loop. The first signal
// starts the drain (--drain-seconds), the second ends it at once; the loop does the rest. Linux hands
// a process-directed signal to the main thread when it does not block it, so the handler runs on
// the loop's own thread and never beside the server's destruction.
void onSignal(int) {
    if (gis::WsServer* server = gServer.load()) server->requestStop();
}

int run(int argc, char** argv) {
    gis::ParsedServerArgs parsed = gis::parseServerArgs(std::vector<std::string>(argv + 1, argv + argc),
                                                        [](const char* n) { return std::getenv(n); });
    if (parsed.help) {
        std::cout << gis::serverUsage();
        return 0;
    }
    if (parsed.configReference) {
        std::cout << gis::serverConfigReference();
        return 0;
    }
    gis::ServerConfig& config = parsed.config;
    if (config.clientDir.empty()) config.clientDir = GIS_DEFAULT_CLIENT_DIR;
    if (config.glName.empty()) config.session.backend = gis::gl::defaultBackend();
    // The default technique is measured, not chosen by hand (presets/presets.json, docs/accuracy.md).
    if (!config.techniqueGiven) {
        try {
            const std::string measured =
                gis::presetDefaultTechnique(gis::loadPresets(gis::defaultPresetsPath()));
            if (!measured.empty()) {
                gis::findTechnique(measured, "default_technique");
                config.session.technique = measured;
            }
        } catch (const gis::InputError& e) {
            gis::logWarn(std::string("gi-server: no default technique from the presets (") + e.what() +
                         "); using " + config.session.technique);
        }
    }
    // Fail at start, not at the first connection.
    gis::findTechnique(config.session.technique, "--technique");
    (void)gis::loadScene(config.session.scene);
    // A machine whose GL does not work fails here, once and visibly (a pod crash-loops instead of
    // turning ready and failing every session); the line names the device that renders, which is how
    // an operator tells a GPU node from a fallback to llvmpipe (docs/operations.md, "GPU nodes").
    {
        const auto probe = gis::gl::createContext(config.session.backend);
        const gis::gl::ContextInfo& gl = probe->info();
        gis::logInfo("gi-server: GL " + gl.backend + ": " + gl.renderer + ", " + gl.version + " (" +
                     gl.vendor + ")");
    }

    gis::WsServer server(config);
    server.listen();
    gServer = &server;
    struct sigaction action {};
    action.sa_handler = onSignal;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
    std::signal(SIGPIPE, SIG_IGN);
    gis::logInfo("gi-server: settings\n" + gis::describeServerConfig(config, parsed.sources));
    gis::logInfo("gi-server: listening on http://" + config.host + ":" + std::to_string(server.port()) +
                 "/ (scene " + config.session.scene + ", technique " + config.session.technique + ", GL " +
                 gis::gl::backendName(config.session.backend) + ")");
    server.run();
    gServer = nullptr;
    if (server.stoppedAtOnce()) {
        // The second signal means now: frames still rendering are not waited for. The watchdog ends
        // the process if the teardown (which joins render threads) is not over within half a second.
        gis::logInfo("gi-server: stopping at once (second signal)");
        std::thread([] {
            std::this_thread::sleep_for(std::chrono::milliseconds(500));
            std::fflush(stdout);
            std::fflush(stderr);
            std::_Exit(0);
        }).detach();
    }
    // Teardown joins the render threads (a frame in progress finishes first); a further signal while
    // that runs takes the default action rather than being ignored.
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    gis::logInfo("gi-server: shutting down");
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    return gis::cli::runMain("gi-server", [&] { return run(argc, argv); });
}
