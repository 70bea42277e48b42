// gi-server's settings, declared once: each option has a flag, an environment variable, a config-file
// key, a range and a help line. --help, the startup summary, config files and validation all come
// from the table in ServerOptions.cpp. Precedence: defaults < config file < environment < flags.
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "session/Session.h"

namespace gis {

struct ServerConfig {
    std::string host = "127.0.0.1";
    int port = 8080;                       ///< [1, 65535]
    std::string clientDir;                 ///< directory served at /
    SessionConfig session;                 ///< defaults for every new session
    bool techniqueGiven = false;           ///< --technique / GI_TECHNIQUE set it (else the presets' default)
    int jpegQuality = 85;                  ///< default stream quality for JPEG/WebP [1, 100]
    int maxSessions = 8;                   ///< more are refused with 'busy'
    int renderSlots = 2;                   ///< renders at once across sessions and the HTTP API
    int httpRenderQueue = 8;               ///< waiting POST /api/render jobs before 503
    std::size_t maxMessageBytes = 65536;   ///< larger client messages: message_too_large
    double messagesPerSecond = 200;        ///< per connection; 0 = unlimited
    std::string token;                     ///< bearer token; empty = no authentication
    std::vector<std::string> allowOrigins; ///< besides the server's own origin
    int resumeGraceS = 30;                 ///< a dropped controller's session waits this long
    int idleTimeoutS = 900;                ///< sessions without steering input end
    int helloTimeoutS = 10;                ///< connections that never say hello are closed
    int drainSeconds = 20;                 ///< on SIGTERM: running sessions may finish this long
    std::vector<std::string> sceneDirs;    ///< file: scenes
    std::string uploadDir;                 ///< per-session upload sandboxes live below it
    int maxUploadMb = 32;
    int maxDecodedMb = 512;        ///< one client-chosen scene once decoded (buffers, images, geometry)
    int maxSessionUploadsMb = 128; ///< a session's uploads together, on disk
    int maxConnections = 0;        ///< HTTP + WebSocket connections; 0: from RLIMIT_NOFILE
    int maxPendingPerIp = 32;      ///< per address: connections before their request or hello is done
    int requestTimeoutS = 30;      ///< an HTTP request, first byte to the end of its body
    std::string glName;            ///< egl, osmesa or empty (default)
};

struct ServerOption {
    std::string flag;                                           ///< "--max-sessions"
    std::string env;                                            ///< "GI_MAX_SESSIONS"
    std::string valueName;                                      ///< "N" (empty for none)
    std::string help;                                           ///< one line with range and default
    std::function<void(ServerConfig&, const std::string&)> set; ///< parses and validates; throws InputError
    std::function<std::string(const ServerConfig&)> show;       ///< for the startup summary
    bool secret = false;                                        ///< masked in the summary
    bool repeatable = false; ///< list options: flags append, env and config use commas
};

const std::vector<ServerOption>& serverOptions();

/// --help text, generated from the table.
std::string serverUsage();

/// The configuration reference as a Markdown table (flag, environment variable, config-file key,
/// description), generated from the same table; docs/operations.md embeds it verbatim and a test
/// checks that it is current (`gi-server --config-reference`).
std::string serverConfigReference();

/// Result of parsing: the config, or a request to print help.
struct ParsedServerArgs {
    ServerConfig config;
    bool help = false;
    bool configReference = false; ///< --config-reference: print serverConfigReference() and exit
    std::map<std::string, std::string> sources; ///< flag -> "flag", "env GI_X", "config FILE"
};
/// Applies defaults, then the config file (--config FILE or $GI_CONFIG: a JSON object whose keys are
/// the flag names without dashes, e.g. {"max-sessions": 4, "scene-dir": ["scenes"]}), then the
/// environment (through `getenv`), then `args`. Throws InputError naming the flag, variable or file
/// and key, the accepted range, and the rejected value.
ParsedServerArgs parseServerArgs(const std::vector<std::string>& args,
                                 const std::function<const char*(const char*)>& getenv);

/// One line per option: `--flag value (source)` with secrets masked, for the startup log.
std::string describeServerConfig(const ServerConfig& config,
                                 const std::map<std::string, std::string>& sources = {});

} // namespace gis
