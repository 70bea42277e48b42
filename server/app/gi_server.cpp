// gi-server: the interactive rendering service. Serves the web client and streams frames with
// per-pass stats over WebSockets, one render worker (thread + GL context) per session.
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
#include "net/WsServer.h"
#include "scene/SceneLoader.h"

#ifndef GIS_DEFAULT_CLIENT_DIR
#define GIS_DEFAULT_CLIENT_DIR "client"
#endif

namespace {

constexpr const char* kUsage = R"(usage: gi-server [options]

Serves the web client and streams interactive global illumination over WebSockets.

  --host ADDR           address to listen on (default 127.0.0.1; $GI_HOST)
  --port N              TCP port, 1..65535 (default 8080; $GI_PORT)
  --scene NAME          default scene: builtin:NAME or a .gltf/.glb file (default builtin:cornell)
  --technique NAME      default technique (default rsm_gather)
  --size WxH            default frame size, 16..2048 each (default 512x512)
  --jpeg-quality N      1..100 (default 85)
  --max-sessions N      concurrent sessions, 1..256 (default 8); more are refused as busy
  --client-dir DIR      directory served at / (default: the source tree's client/; $GI_CLIENT_DIR)
  --gl egl|osmesa       headless GL backend (default: $GI_GL, else egl)
  --help                this text
)";

gis::WsServer* gServer = nullptr;

void onSignal(int) {
    if (gServer) gServer->requestStop();
}

struct UsageError {
    std::string message;
};

int parseInt(const std::string& flag, const std::string& text, int lo, int hi) {
    try {
        size_t used = 0;
        long v = std::stol(text, &used);
        if (used == text.size() && v >= lo && v <= hi) return static_cast<int>(v);
    } catch (...) {
    }
    throw UsageError{flag + " must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got '" +
                     text + "'"};
}

int run(int argc, char** argv) {
    gis::ServerConfig config;
    if (const char* h = std::getenv("GI_HOST")) config.host = h;
    if (const char* p = std::getenv("GI_PORT")) config.port = parseInt("GI_PORT", p, 1, 65535);
    config.clientDir = std::getenv("GI_CLIENT_DIR") ? std::getenv("GI_CLIENT_DIR") : GIS_DEFAULT_CLIENT_DIR;
    std::string gl;
    std::vector<std::string> args(argv + 1, argv + argc);
    auto value = [&](size_t& i) -> const std::string& {
        if (i + 1 >= args.size()) throw UsageError{args[i] + " needs a value"};
        return args[++i];
    };
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "--help" || a == "-h") {
            std::cout << kUsage;
            return 0;
        } else if (a == "--host") config.host = value(i);
        else if (a == "--port") config.port = parseInt("--port", value(i), 1, 65535);
        else if (a == "--scene") config.session.scene = value(i);
        else if (a == "--technique") config.session.technique = value(i);
        else if (a == "--size") {
            const std::string& s = value(i);
            auto x = s.find('x');
            if (x == std::string::npos) throw UsageError{"--size must look like 512x512, got '" + s + "'"};
            config.session.width = parseInt("--size width", s.substr(0, x), 16, 2048);
            config.session.height = parseInt("--size height", s.substr(x + 1), 16, 2048);
        } else if (a == "--jpeg-quality") config.session.jpegQuality = parseInt("--jpeg-quality", value(i), 1, 100);
        else if (a == "--max-sessions") config.maxSessions = parseInt("--max-sessions", value(i), 1, 256);
        else if (a == "--client-dir") config.clientDir = value(i);
        else if (a == "--gl") gl = value(i);
        else throw UsageError{"unknown option '" + a + "' (see --help)"};
    }
    try {
        config.session.backend = gl.empty() ? gis::gl::defaultBackend() : gis::gl::parseBackend(gl);
        gis::findTechnique(config.session.technique, "--technique");
        (void)gis::loadScene(config.session.scene); // fail at start, not at the first connection
    } catch (const gis::InputError& e) {
        throw UsageError{e.what()};
    }

    gis::WsServer server(config);
    server.listen();
    gServer = &server;
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    std::signal(SIGPIPE, SIG_IGN);
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
    } catch (const UsageError& e) {
        std::fprintf(stderr, "gi-server: %s\n", e.message.c_str());
        return 2;
    } catch (const gis::InputError& e) {
        std::fprintf(stderr, "gi-server: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "gi-server: %s\n", e.what());
        return 1;
    }
}
