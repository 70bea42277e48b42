#include "net/ServerOptions.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>
#include <thread>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "core/CommandLine.h"
#include "core/Error.h"
#include "core/JsonSchema.h"
#include "gi/Technique.h"
#include "gl/Platform.h"

namespace gis {
namespace {

using cli::numberText;
using cli::parseInteger;
using cli::parseNumber;
using cli::splitList;

/// A list setting as the startup summary shows it.
std::string shownList(const std::vector<std::string>& items) {
    return items.empty() ? "(none)" : cli::joinList(items, ",");
}

// Builders keep the table below one entry per line of meaning. A field is a generic lambda returning
// the setting's reference in a ServerConfig (const or not). Numeric options append their range and
// default to the help line, so both are stated once: in the call and in ServerConfig.

/// The defaults as declared (not defaultConfig(): the help must not depend on the machine).
const ServerConfig& declaredDefaults() {
    static const ServerConfig defaults;
    return defaults;
}

template <typename Field>
ServerOption integerOption(std::string flag, std::string env, std::string valueName, std::string help,
                           long lo, long hi, Field field, const std::string& defaultText = {}) {
    help += ", " + std::to_string(lo) + ".." + std::to_string(hi) +
            (defaultText.empty() ? " (default " + std::to_string(field(declaredDefaults())) + ")"
                                 : " (default: " + defaultText + ")");
    ServerOption o{flag, std::move(env), std::move(valueName), std::move(help), nullptr, nullptr};
    o.set = [flag, lo, hi, field](ServerConfig& c, const std::string& v) {
        auto& target = field(c);
        target = static_cast<std::remove_reference_t<decltype(target)>>(parseInteger(flag, v, lo, hi));
    };
    o.show = [field](const ServerConfig& c) { return std::to_string(field(c)); };
    return o;
}

template <typename Field>
ServerOption numberOption(std::string flag, std::string env, std::string valueName, std::string help,
                          double lo, double hi, Field field) {
    help += ", " + numberText(lo) + ".." + numberText(hi) + " (default " +
            numberText(field(declaredDefaults())) + ")";
    ServerOption o{flag, std::move(env), std::move(valueName), std::move(help), nullptr, nullptr};
    o.set = [flag, lo, hi, field](ServerConfig& c, const std::string& v) {
        field(c) = parseNumber(flag, v, lo, hi);
    };
    o.show = [field](const ServerConfig& c) { return numberText(field(c)); };
    return o;
}

/// WxH, each side 16..kMaxFrameSide; `width` and `height` are fields as above.
constexpr int kMaxFrameSide = 8192;
template <typename Width, typename Height>
ServerOption sizeOption(std::string flag, std::string env, std::string help, Width width, Height height) {
    const ServerConfig& d = declaredDefaults();
    help += ", 16.." + std::to_string(kMaxFrameSide) + " each (default " + std::to_string(width(d)) + "x" +
            std::to_string(height(d)) + ")";
    ServerOption o{flag, std::move(env), "WxH", std::move(help), nullptr, nullptr};
    o.set = [flag, width, height](ServerConfig& c, const std::string& v) {
        cli::parseSize(flag, v, kMaxFrameSide, width(c), height(c));
    };
    o.show = [width, height](const ServerConfig& c) {
        return std::to_string(width(c)) + "x" + std::to_string(height(c));
    };
    return o;
}

#define GIS_FIELD(expr)                                                                                      \
    [](auto& c) -> auto& {                                                                                   \
        return c.expr;                                                                                       \
    }

ServerOption stringOption(std::string flag, std::string env, std::string valueName, std::string help,
                          std::string ServerConfig::*field) {
    ServerOption o{flag, env, std::move(valueName), std::move(help), nullptr, nullptr};
    o.set = [field](ServerConfig& c, const std::string& v) { c.*field = v; };
    o.show = [field](const ServerConfig& c) { return (c.*field).empty() ? std::string("(none)") : c.*field; };
    return o;
}

ServerOption listOption(std::string flag, std::string env, std::string valueName, std::string help,
                        std::vector<std::string> ServerConfig::*field) {
    ServerOption o{flag, env, std::move(valueName), std::move(help), nullptr, nullptr};
    o.set = [field](ServerConfig& c, const std::string& v) {
        for (auto& item : splitList(v)) (c.*field).push_back(item);
    };
    o.show = [field](const ServerConfig& c) { return shownList(c.*field); };
    o.repeatable = true;
    return o;
}

std::vector<ServerOption> buildOptions() {
    std::vector<ServerOption> t;
    t.push_back(stringOption("--host", "GI_HOST", "ADDR", "address to listen on (default 127.0.0.1)",
                             &ServerConfig::host));
    t.push_back(integerOption("--port", "GI_PORT", "N", "TCP port", 1, 65535, GIS_FIELD(port)));
    t.push_back(stringOption("--client-dir", "GI_CLIENT_DIR", "DIR",
                             "directory served at / (default: the source tree's client/)",
                             &ServerConfig::clientDir));
    {
        ServerOption o{"--scene", "GI_SCENE", "NAME",
                       "default scene: builtin:NAME or a .gltf/.glb file (default builtin:cornell)"};
        o.set = [](ServerConfig& c, const std::string& v) { c.session.scene = v; };
        o.show = [](const ServerConfig& c) { return c.session.scene; };
        t.push_back(o);
    }
    {
        ServerOption o{
            "--technique", "GI_TECHNIQUE", "NAME",
            "default technique (default: the presets file's default_technique, the most accurate "
            "within the interactive budget as measured by gi-bench report; rsm_gather without one)"};
        o.set = [](ServerConfig& c, const std::string& v) {
            findTechnique(v, "--technique");
            c.session.technique = v;
            c.techniqueGiven = true;
        };
        o.show = [](const ServerConfig& c) { return c.session.technique; };
        t.push_back(o);
    }
    t.push_back(sizeOption("--size", "GI_SIZE", "default frame size", GIS_FIELD(session.width),
                           GIS_FIELD(session.height)));
    t.push_back(sizeOption("--max-size", "GI_MAX_SIZE",
                           "largest frame a client may ask for; larger viewports are scaled down",
                           GIS_FIELD(session.limits.maxWidth), GIS_FIELD(session.limits.maxHeight)));
    t.push_back(integerOption("--max-vpls", "GI_MAX_VPLS", "N", "most VPLs a parameter set may ask for", 1,
                              16777216, GIS_FIELD(session.limits.maxVpls)));
    t.push_back(integerOption("--jpeg-quality", "GI_JPEG_QUALITY", "N", "default JPEG/WebP stream quality", 1,
                              100, GIS_FIELD(jpegQuality)));
    t.push_back(numberOption("--interactive-scale", "GI_INTERACTIVE_SCALE", "F",
                             "largest size factor of interactive frames while input arrives (the frame "
                             "budget picks one up to it; with --frame-target-ms 0, the factor)",
                             0.1, 1.0, GIS_FIELD(session.limits.interactiveScale)));
    t.push_back(numberOption("--interactive-lod-px", "GI_INTERACTIVE_LOD_PX", "PX",
                             "level-of-detail tolerance of interactive frames (their lod_pixels unless the "
                             "client set it): big meshes are drawn simplified where the error spans at most "
                             "this many of the frame's pixels; above 0 every live frame's light views are "
                             "drawn within one texel as well (light_lod_texels); 0 = every triangle",
                             0.0, 8.0, GIS_FIELD(session.limits.interactiveLodPixels)));
    t.push_back(
        integerOption("--frame-target-ms", "GI_FRAME_TARGET_MS", "MS",
                      "render + encode time an interactive frame should take: each session sizes its "
                      "interactive frames and caps their VPLs from what its frames measured; a client "
                      "may ask for its own; 0 = no budget",
                      0, 2000, GIS_FIELD(session.limits.frameTargetMs)));
    t.push_back(
        integerOption("--slice-ms", "GI_SLICE_MS", "MS",
                      "time one tile of a refinement step should take: input waits at most about this "
                      "long for the tile in progress",
                      5, 1000, GIS_FIELD(session.limits.sliceMs)));
    t.push_back(integerOption("--settle-ms", "GI_SETTLE_MS", "MS",
                              "quiet time before refinement to the balanced and final presets", 0, 10000,
                              GIS_FIELD(session.limits.settleMs)));
    t.push_back(integerOption("--refine-budget-ms", "GI_REFINE_BUDGET_MS", "MS",
                              "skip a refinement step predicted to take longer in all (steps render in tiles "
                              "input interrupts: this bounds the work, not the wait); 0 = no limit",
                              0, 600000, GIS_FIELD(session.limits.refineBudgetMs)));
    t.push_back(integerOption("--max-sessions", "GI_MAX_SESSIONS", "N",
                              "concurrent sessions (more are refused as busy)", 1, 256,
                              GIS_FIELD(maxSessions)));
    // The default is the machine's core count, not printed here: docs/operations.md embeds this text
    // and must not depend on the machine that generated it (the startup summary shows the value).
    t.push_back(integerOption("--render-slots", "GI_RENDER_SLOTS", "N",
                              "renders at once across all sessions and the HTTP API", 1, 256,
                              GIS_FIELD(renderSlots), "the number of cores"));
    t.push_back(integerOption("--http-queue", "GI_HTTP_QUEUE", "N",
                              "POST /api/render jobs waiting before 503", 0, 1024,
                              GIS_FIELD(httpRenderQueue)));
    t.push_back(integerOption("--max-message-bytes", "GI_MAX_MESSAGE_BYTES", "N", "largest client message",
                              256, 16777216, GIS_FIELD(maxMessageBytes)));
    t.push_back(numberOption("--rate-limit", "GI_RATE_LIMIT", "N",
                             "messages per second per connection (bursts of twice that), 0 = unlimited", 0,
                             100000, GIS_FIELD(messagesPerSecond)));
    {
        ServerOption o =
            stringOption("--token", "GI_TOKEN", "TOKEN",
                         "require this bearer token on the WebSocket (hello or handshake) and the HTTP "
                         "API; /healthz stays open (default: none)",
                         &ServerConfig::token);
        o.secret = true;
        t.push_back(o);
    }
    t.push_back(
        listOption("--allow-origin", "GI_ALLOW_ORIGIN", "ORIGIN",
                   "also accept requests from this origin, e.g. https://demo.example (repeatable; default: "
                   "the server's own origin only)",
                   &ServerConfig::allowOrigins));
    t.push_back(integerOption("--resume-grace", "GI_RESUME_GRACE", "N",
                              "a dropped controller's session waits this many seconds for a resume", 0, 3600,
                              GIS_FIELD(resumeGraceS)));
    t.push_back(integerOption("--idle-timeout", "GI_IDLE_TIMEOUT", "N",
                              "end sessions without steering input for this many seconds", 10, 604800,
                              GIS_FIELD(idleTimeoutS)));
    t.push_back(integerOption("--hello-timeout", "GI_HELLO_TIMEOUT", "N",
                              "close connections that send no hello within this many seconds", 1, 300,
                              GIS_FIELD(helloTimeoutS)));
    t.push_back(
        integerOption("--drain-seconds", "GI_DRAIN_SECONDS", "N",
                      "on SIGTERM or SIGINT refuse new sessions, tell clients and let running sessions "
                      "finish for up to this many seconds, then close them and exit 0; a second signal "
                      "stops at once; 0 = no wait",
                      0, 3600, GIS_FIELD(drainSeconds)));
    t.push_back(listOption("--scene-dir", "GI_SCENE_DIR", "DIR",
                           "offer the .gltf/.glb files below DIR as file:NAME scenes (repeatable)",
                           &ServerConfig::sceneDirs));
    t.push_back(
        stringOption("--upload-dir", "GI_UPLOAD_DIR", "DIR",
                     "where per-session upload sandboxes live (default: a private directory under $TMPDIR)",
                     &ServerConfig::uploadDir));
    t.push_back(integerOption("--max-upload-mb", "GI_MAX_UPLOAD_MB", "N",
                              "largest uploaded .glb or .zip in MiB (0 disables uploads)", 0, 1024,
                              GIS_FIELD(maxUploadMb)));
    t.push_back(
        integerOption("--max-decoded-mb", "GI_MAX_DECODED_MB", "N",
                      "most memory in MiB one uploaded or file: scene may take once decoded (buffers, "
                      "images, geometry), checked from image headers before decoding",
                      16, 65536, GIS_FIELD(maxDecodedMb)));
    t.push_back(integerOption("--max-session-uploads-mb", "GI_MAX_SESSION_UPLOADS_MB", "N",
                              "all uploads of one session together, in MiB", 1, 65536,
                              GIS_FIELD(maxSessionUploadsMb)));
    t.push_back(
        integerOption("--max-connections", "GI_MAX_CONNECTIONS", "N",
                      "open HTTP and WebSocket connections; more are closed at accept; 0 = the open-file "
                      "limit less a reserve for sessions and files",
                      0, 1000000, GIS_FIELD(maxConnections)));
    t.push_back(
        integerOption("--max-pending-per-ip", "GI_MAX_PENDING_PER_IP", "N",
                      "connections from one address that have not finished their HTTP request or hello", 1,
                      100000, GIS_FIELD(maxPendingPerIp)));
    t.push_back(integerOption("--request-timeout", "GI_REQUEST_TIMEOUT", "N",
                              "seconds an HTTP request may take from its first byte to the end of its body",
                              1, 3600, GIS_FIELD(requestTimeoutS)));
    {
        ServerOption o{"--gl", "GI_GL", "egl|osmesa", "headless GL backend (default egl)"};
        o.set = [](ServerConfig& c, const std::string& v) {
            c.session.backend = gl::parseBackend(v);
            c.glName = v;
        };
        o.show = [](const ServerConfig& c) { return std::string(gl::backendName(c.session.backend)); };
        t.push_back(o);
    }
    return t;
}

#undef GIS_FIELD

const ServerOption* findOption(const std::string& flag) {
    for (const auto& o : serverOptions())
        if (o.flag == flag) return &o;
    return nullptr;
}

ServerConfig defaultConfig() {
    ServerConfig c;
    c.renderSlots = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    return c;
}

} // namespace

const std::vector<ServerOption>& serverOptions() {
    static const std::vector<ServerOption> table = buildOptions();
    return table;
}

std::string serverUsage() {
    std::ostringstream out;
    out << "usage: gi-server [options]\n\n"
           "Serves the web client and streams interactive global illumination over WebSockets\n"
           "(protocol/PROTOCOL.md), plus a one-shot HTTP render API, health and Prometheus metrics.\n\n";
    for (const auto& o : serverOptions()) {
        std::string head = "  " + o.flag + (o.valueName.empty() ? "" : " " + o.valueName);
        if (head.size() < 26)
            head.resize(26, ' ');
        else
            head += "\n" + std::string(26, ' ');
        out << head << o.help << " [$" << o.env << "]\n";
    }
    out << "  --config FILE           read settings from a JSON file: {\"max-sessions\": 4, \"scene-dir\": "
           "[\"scenes\"]}\n"
           "                          [$GI_CONFIG]; precedence: defaults < file < environment < flags\n"
           "  --config-reference      print the settings as a Markdown table (docs/operations.md)\n"
           "  --help                  this text\n";
    return out.str();
}

std::string serverConfigReference() {
    // Markdown table cells: a '|' inside a value name or help text would end the cell (GitHub's tables
    // take '\|' as a literal bar, inside code spans too).
    auto cell = [](std::ostream& out, const std::string& text) -> std::ostream& {
        for (char ch : text) {
            if (ch == '|') out << '\\';
            out << ch;
        }
        return out;
    };
    std::ostringstream out;
    out << "| flag | environment | config-file key | description |\n|---|---|---|---|\n";
    for (const auto& o : serverOptions()) {
        out << "| `" << o.flag;
        if (!o.valueName.empty()) cell(out << ' ', o.valueName);
        out << "` | `" << o.env << "` | `" << o.flag.substr(2) << "` | ";
        cell(out, o.help);
        if (o.repeatable) out << " (environment: comma-separated; file: a JSON array)";
        if (o.secret) out << " (masked in the startup log)";
        out << " |\n";
    }
    out << "| `--config FILE` | `GI_CONFIG` | | read settings from a JSON object whose keys are the flag "
           "names "
           "without dashes; precedence: defaults < file < environment < flags |\n";
    return out.str();
}

ParsedServerArgs parseServerArgs(const std::vector<std::string>& args,
                                 const std::function<const char*(const char*)>& getenv) {
    ParsedServerArgs result;
    result.config = defaultConfig();
    ServerConfig& c = result.config;

    std::string configFile;
    if (const char* f = getenv("GI_CONFIG"); f && *f) configFile = f;
    for (std::size_t i = 0; i < args.size(); ++i) {
        if (args[i] == "--help" || args[i] == "-h") result.help = true;
        if (args[i] == "--config-reference") result.configReference = true;
        if (args[i] == "--config") {
            if (i + 1 >= args.size()) throw InputError("--config", "needs a value");
            configFile = args[i + 1];
        }
    }
    if (result.help || result.configReference) return result;

    if (!configFile.empty()) {
        std::ifstream in(configFile);
        if (!in) throw InputError(configFile, "cannot read the config file");
        const std::string fileText((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        std::string parseError;
        nlohmann::json doc = parseJsonExplained(fileText, parseError);
        if (doc.is_discarded()) throw InputError(configFile, "not valid JSON: " + parseError);
        if (!doc.is_object())
            throw InputError(configFile, "the config file must be a JSON object of option names, e.g. "
                                         "{\"max-sessions\": 4}");
        for (const auto& [key, value] : doc.items()) {
            const ServerOption* o = findOption("--" + key);
            if (!o)
                throw InputError(configFile + ": " + key, "unknown setting (the names are gi-server's flags "
                                                          "without the dashes; see gi-server --help)");
            auto apply = [&](const nlohmann::json& v) {
                const std::string text = v.is_string() ? v.get<std::string>() : v.dump();
                try {
                    o->set(c, text);
                } catch (const InputError& e) {
                    throw InputError(configFile + ": " + key, e.reason());
                }
            };
            if (value.is_array() && o->repeatable)
                for (const auto& v : value) apply(v);
            else
                apply(value);
            result.sources[o->flag] = "config " + configFile;
        }
    }
    for (const auto& o : serverOptions()) {
        const char* v = getenv(o.env.c_str());
        if (!v || !*v) continue;
        try {
            o.set(c, v); // lists (comma-separated) add to the config file's
        } catch (const InputError& e) {
            throw InputError("$" + o.env, e.reason());
        }
        result.sources[o.flag] = "env " + o.env;
    }
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "--config") {
            ++i;
            continue;
        }
        const ServerOption* o = findOption(a);
        if (!o) throw InputError(a, "unknown option (see gi-server --help)");
        if (i + 1 >= args.size()) throw InputError(a, "needs a value (" + o->valueName + ")");
        o->set(c, args[++i]);
        result.sources[o->flag] = "flag";
    }
    return result;
}

std::string describeServerConfig(const ServerConfig& config,
                                 const std::map<std::string, std::string>& sources) {
    std::ostringstream out;
    for (const auto& o : serverOptions()) {
        std::string value = o.show(config);
        if (o.secret && !config.token.empty()) value = "(set)";
        auto src = sources.find(o.flag);
        out << "  " << o.flag << " " << value << (src == sources.end() ? "" : " (" + src->second + ")")
            << "\n";
    }
    return out.str();
}

} // namespace gis
