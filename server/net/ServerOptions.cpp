#include "net/ServerOptions.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "core/JsonSchema.h"
#include "gi/Technique.h"
#include "gl/Platform.h"

namespace gis {
namespace {

long parseInteger(const std::string& who, const std::string& text, long lo, long hi) {
    try {
        std::size_t used = 0;
        const long v = std::stol(text, &used);
        if (used == text.size() && v >= lo && v <= hi) return v;
    } catch (...) {
    }
    throw InputError(who, "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                              "], got '" + text + "'");
}

double parseNumber(const std::string& who, const std::string& text, double lo, double hi) {
    try {
        std::size_t used = 0;
        const double v = std::stod(text, &used);
        if (used == text.size() && std::isfinite(v) && v >= lo && v <= hi) return v;
    } catch (...) {
    }
    std::ostringstream range;
    range << "[" << lo << ", " << hi << "]";
    throw InputError(who, "must be a number in " + range.str() + ", got '" + text + "'");
}

void parseSize(const std::string& who, const std::string& text, int& w, int& h) {
    const auto x = text.find('x');
    if (x == std::string::npos) throw InputError(who, "must look like 512x512, got '" + text + "'");
    w = static_cast<int>(parseInteger(who + " width", text.substr(0, x), 16, 8192));
    h = static_cast<int>(parseInteger(who + " height", text.substr(x + 1), 16, 8192));
}

std::vector<std::string> splitList(const std::string& text) {
    std::vector<std::string> out;
    std::stringstream in(text);
    for (std::string item; std::getline(in, item, ',');)
        if (!item.empty()) out.push_back(item);
    return out;
}

std::string joinList(const std::vector<std::string>& items) {
    std::string out;
    for (const auto& i : items) out += (out.empty() ? "" : ",") + i;
    return out.empty() ? "(none)" : out;
}

std::string numberText(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

// Builders keep the table below one entry per line of meaning.
ServerOption intOption(std::string flag, std::string env, std::string help, long lo, long hi,
                       int ServerConfig::*field) {
    ServerOption o{flag, env, "N", std::move(help), nullptr, nullptr};
    o.set = [flag, lo, hi, field](ServerConfig& c, const std::string& v) {
        c.*field = static_cast<int>(parseInteger(flag, v, lo, hi));
    };
    o.show = [field](const ServerConfig& c) { return std::to_string(c.*field); };
    return o;
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
    o.show = [field](const ServerConfig& c) { return joinList(c.*field); };
    o.repeatable = true;
    return o;
}

std::vector<ServerOption> buildOptions() {
    std::vector<ServerOption> t;
    t.push_back(stringOption("--host", "GI_HOST", "ADDR", "address to listen on (default 127.0.0.1)",
                             &ServerConfig::host));
    t.push_back(
        intOption("--port", "GI_PORT", "TCP port, 1..65535 (default 8080)", 1, 65535, &ServerConfig::port));
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
    {
        ServerOption o{"--size", "GI_SIZE", "WxH", "default frame size, 16..8192 each (default 512x512)"};
        o.set = [](ServerConfig& c, const std::string& v) {
            parseSize("--size", v, c.session.width, c.session.height);
        };
        o.show = [](const ServerConfig& c) {
            return std::to_string(c.session.width) + "x" + std::to_string(c.session.height);
        };
        t.push_back(o);
    }
    {
        ServerOption o{
            "--max-size", "GI_MAX_SIZE", "WxH",
            "largest frame a client may ask for; larger viewports are scaled down (default 2048x2048)"};
        o.set = [](ServerConfig& c, const std::string& v) {
            parseSize("--max-size", v, c.session.limits.maxWidth, c.session.limits.maxHeight);
        };
        o.show = [](const ServerConfig& c) {
            return std::to_string(c.session.limits.maxWidth) + "x" +
                   std::to_string(c.session.limits.maxHeight);
        };
        t.push_back(o);
    }
    {
        ServerOption o{"--max-vpls", "GI_MAX_VPLS", "N",
                       "most VPLs a parameter set may ask for, 1..16777216 (default 65536)"};
        o.set = [](ServerConfig& c, const std::string& v) {
            c.session.limits.maxVpls = parseInteger("--max-vpls", v, 1, 16777216);
        };
        o.show = [](const ServerConfig& c) { return std::to_string(c.session.limits.maxVpls); };
        t.push_back(o);
    }
    t.push_back(intOption("--jpeg-quality", "GI_JPEG_QUALITY",
                          "default JPEG/WebP stream quality, 1..100 (default 85)", 1, 100,
                          &ServerConfig::jpegQuality));
    {
        ServerOption o{"--interactive-scale", "GI_INTERACTIVE_SCALE", "F",
                       "largest size factor of interactive frames while input arrives (the frame budget "
                       "picks one up to it; with --frame-target-ms 0, the factor), 0.1..1 (default 1)"};
        o.set = [](ServerConfig& c, const std::string& v) {
            c.session.limits.interactiveScale = parseNumber("--interactive-scale", v, 0.1, 1.0);
        };
        o.show = [](const ServerConfig& c) { return numberText(c.session.limits.interactiveScale); };
        t.push_back(o);
    }
    {
        ServerOption o{"--frame-target-ms", "GI_FRAME_TARGET_MS", "MS",
                       "render + encode time an interactive frame should take: each session sizes its "
                       "interactive frames and caps their VPLs from what its frames measured; a client may "
                       "ask for its own; 0 = no budget, 0..2000 (default 80)"};
        o.set = [](ServerConfig& c, const std::string& v) {
            c.session.limits.frameTargetMs = static_cast<int>(parseInteger("--frame-target-ms", v, 0, 2000));
        };
        o.show = [](const ServerConfig& c) { return std::to_string(c.session.limits.frameTargetMs); };
        t.push_back(o);
    }
    {
        ServerOption o{"--slice-ms", "GI_SLICE_MS", "MS",
                       "time one tile of a refinement step should take: input waits at most about this long "
                       "for the tile in progress, 5..1000 (default 20)"};
        o.set = [](ServerConfig& c, const std::string& v) {
            c.session.limits.sliceMs = static_cast<int>(parseInteger("--slice-ms", v, 5, 1000));
        };
        o.show = [](const ServerConfig& c) { return std::to_string(c.session.limits.sliceMs); };
        t.push_back(o);
    }
    {
        ServerOption o{
            "--settle-ms", "GI_SETTLE_MS", "MS",
            "quiet time before refinement to the balanced and final presets, 0..10000 (default 250)"};
        o.set = [](ServerConfig& c, const std::string& v) {
            c.session.limits.settleMs = static_cast<int>(parseInteger("--settle-ms", v, 0, 10000));
        };
        o.show = [](const ServerConfig& c) { return std::to_string(c.session.limits.settleMs); };
        t.push_back(o);
    }
    {
        ServerOption o{
            "--refine-budget-ms", "GI_REFINE_BUDGET_MS", "MS",
            "skip a refinement step predicted to take longer in all (steps render in tiles input "
            "interrupts: this bounds the work, not the wait); 0 = no limit, 0..600000 (default 30000)"};
        o.set = [](ServerConfig& c, const std::string& v) {
            c.session.limits.refineBudgetMs =
                static_cast<int>(parseInteger("--refine-budget-ms", v, 0, 600000));
        };
        o.show = [](const ServerConfig& c) { return std::to_string(c.session.limits.refineBudgetMs); };
        t.push_back(o);
    }
    t.push_back(intOption("--max-sessions", "GI_MAX_SESSIONS",
                          "concurrent sessions, 1..256 (default 8); more are refused as busy", 1, 256,
                          &ServerConfig::maxSessions));
    // The default is the machine's core count, not printed here: docs/operations.md embeds this text
    // and must not depend on the machine that generated it (the startup summary shows the value).
    t.push_back(intOption("--render-slots", "GI_RENDER_SLOTS",
                          "renders at once across all sessions and the HTTP API, 1..256 (default: the number "
                          "of cores)",
                          1, 256, &ServerConfig::renderSlots));
    t.push_back(intOption("--http-queue", "GI_HTTP_QUEUE",
                          "POST /api/render jobs waiting before 503, 0..1024 (default 8)", 0, 1024,
                          &ServerConfig::httpRenderQueue));
    {
        ServerOption o{"--max-message-bytes", "GI_MAX_MESSAGE_BYTES", "N",
                       "largest client message, 256..16777216 (default 65536)"};
        o.set = [](ServerConfig& c, const std::string& v) {
            c.maxMessageBytes =
                static_cast<std::size_t>(parseInteger("--max-message-bytes", v, 256, 16777216));
        };
        o.show = [](const ServerConfig& c) { return std::to_string(c.maxMessageBytes); };
        t.push_back(o);
    }
    {
        ServerOption o{"--rate-limit", "GI_RATE_LIMIT", "N",
                       "messages per second per connection (bursts of twice that), 0 = unlimited, 0..100000 "
                       "(default 200)"};
        o.set = [](ServerConfig& c, const std::string& v) {
            c.messagesPerSecond = parseNumber("--rate-limit", v, 0, 100000);
        };
        o.show = [](const ServerConfig& c) { return numberText(c.messagesPerSecond); };
        t.push_back(o);
    }
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
    t.push_back(intOption("--resume-grace", "GI_RESUME_GRACE",
                          "a dropped controller's session waits this many seconds "
                          "for a resume, 0..3600 (default 30)",
                          0, 3600, &ServerConfig::resumeGraceS));
    t.push_back(
        intOption("--idle-timeout", "GI_IDLE_TIMEOUT",
                  "end sessions without steering input for this many seconds, 10..604800 (default 900)", 10,
                  604800, &ServerConfig::idleTimeoutS));
    t.push_back(
        intOption("--hello-timeout", "GI_HELLO_TIMEOUT",
                  "close connections that send no hello within this many seconds, 1..300 (default 10)", 1,
                  300, &ServerConfig::helloTimeoutS));
    t.push_back(intOption("--drain-seconds", "GI_DRAIN_SECONDS",
                          "on SIGTERM or SIGINT refuse new sessions, tell clients and let running sessions "
                          "finish for up to this many seconds, then close them and exit 0; a second signal "
                          "stops at once; 0 = no wait, 0..3600 (default 20)",
                          0, 3600, &ServerConfig::drainSeconds));
    t.push_back(listOption("--scene-dir", "GI_SCENE_DIR", "DIR",
                           "offer the .gltf/.glb files below DIR as file:NAME scenes (repeatable)",
                           &ServerConfig::sceneDirs));
    t.push_back(
        stringOption("--upload-dir", "GI_UPLOAD_DIR", "DIR",
                     "where per-session upload sandboxes live (default: a private directory under $TMPDIR)",
                     &ServerConfig::uploadDir));
    t.push_back(intOption("--max-upload-mb", "GI_MAX_UPLOAD_MB",
                          "largest uploaded .glb in MiB, 0..1024 (0 disables "
                          "uploads; default 32)",
                          0, 1024, &ServerConfig::maxUploadMb));
    t.push_back(
        intOption("--max-decoded-mb", "GI_MAX_DECODED_MB",
                  "most memory one uploaded or file: scene may take once decoded (buffers, images, "
                  "geometry), checked from image headers before decoding, 16..65536 MiB (default 512)",
                  16, 65536, &ServerConfig::maxDecodedMb));
    t.push_back(intOption("--max-session-uploads-mb", "GI_MAX_SESSION_UPLOADS_MB",
                          "all uploads of one session together, 1..65536 MiB (default 128)", 1, 65536,
                          &ServerConfig::maxSessionUploadsMb));
    t.push_back(intOption("--max-connections", "GI_MAX_CONNECTIONS",
                          "open HTTP and WebSocket connections; more are closed at accept; 0 = the open-file "
                          "limit less a reserve for sessions and files, 0..1000000 (default 0)",
                          0, 1000000, &ServerConfig::maxConnections));
    t.push_back(intOption("--max-pending-per-ip", "GI_MAX_PENDING_PER_IP",
                          "connections from one address that have not finished their HTTP request or hello, "
                          "1..100000 (default 32)",
                          1, 100000, &ServerConfig::maxPendingPerIp));
    t.push_back(intOption("--request-timeout", "GI_REQUEST_TIMEOUT",
                          "seconds an HTTP request may take from its first byte to the end of its body, "
                          "1..3600 (default 30)",
                          1, 3600, &ServerConfig::requestTimeoutS));
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
