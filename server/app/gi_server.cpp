// gi-server: the interactive rendering service. Serves the web client, streams frames with per-pass
// stats over WebSockets (one render worker with its own GL context per session), answers one-shot
// HTTP render requests and exposes health and Prometheus metrics. Settings: net/ServerOptions.h.
// Exit codes: 0 clean shutdown, 1 runtime failure, 2 bad usage.
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>

#include "core/Error.h"
#include "core/Log.h"
#include "gi/Technique.h"
#include "gl/Platform.h"
#include "net/ServerOptions.h"
#include "net/WsServer.h"
#include "scene/SceneLoader.h"

#ifndef GIS_DEFAULT_CLIENT_DIR
#define GIS_DEFAULT_CLIENT_DIR "client"
#endif

namespace {

gis::WsServer* gServer = nullptr;

void onSignal(int) {
    if (gServer) gServer->requestStop();
}

int run(int argc, char** argv) {
    gis::ParsedServerArgs parsed = gis::parseServerArgs(std::vector<std::string>(argv + 1, argv + argc),
                                                        [](const char* n) { return std::getenv(n); });
    if (parsed.help) {
        std::cout << gis::serverUsage();
        return 0;
    }
    gis::ServerConfig& config = parsed.config;
    if (config.clientDir.empty()) config.clientDir = GIS_DEFAULT_CLIENT_DIR;
    if (config.glName.empty()) config.session.backend = gis::gl::defaultBackend();
    // Fail at start, not at the first connection.
    gis::findTechnique(config.session.technique, "--technique");
    (void)gis::loadScene(config.session.scene);

    gis::WsServer server(config);
    server.listen();
    gServer = &server;
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    std::signal(SIGPIPE, SIG_IGN);
    gis::logInfo("gi-server: settings\n" + gis::describeServerConfig(config, parsed.sources));
    gis::logInfo("gi-server: listening on http://" + config.host + ":" + std::to_string(server.port()) +
                 "/ (scene " + config.session.scene + ", technique " + config.session.technique + ", GL " +
                 gis::gl::backendName(config.session.backend) + ")");
    server.run();
    gis::logInfo("gi-server: shutting down");
    gServer = nullptr;
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const gis::InputError& e) {
        std::fprintf(stderr, "gi-server: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "gi-server: %s\n", e.what());
        return 1;
    }
}
