#include "session/ProtocolMessages.h"

#include <algorithm>
#include <map>
#include <mutex>

#include "core/EmbeddedFiles.h"
#include "core/JsonSchema.h"

namespace gis {
namespace {

const nlohmann::json* schemaFor(const std::string& type) {
    static std::once_flag once;
    static std::map<std::string, nlohmann::json> schemas;
    std::call_once(once, [] {
        for (const auto& f : embedded::protocol()) {
            // "schema/camera.json" -> "camera"
            std::string_view p = f.path;
            auto slash = p.rfind('/');
            auto dot = p.rfind('.');
            if (slash == std::string_view::npos || dot == std::string_view::npos || dot < slash) continue;
            schemas[std::string(p.substr(slash + 1, dot - slash - 1))] = nlohmann::json::parse(f.content);
        }
    });
    auto it = schemas.find(type);
    return it == schemas.end() ? nullptr : &it->second;
}

} // namespace

const std::vector<std::string>& clientMessageTypes() {
    static const std::vector<std::string> types = {
        "hello",  "camera", "light",   "light_add", "light_remove", "technique", "params",
        "resize", "scene",  "quality", "snapshot",  "ack",          "ping"};
    return types;
}

nlohmann::json parseClientMessage(std::string_view text) {
    std::string parseError;
    nlohmann::json msg = parseJsonExplained(text, parseError);
    if (msg.is_discarded())
        throw ProtocolError{"invalid_json", "the message is not valid JSON: " + parseError, "", ""};
    if (!msg.is_object())
        throw ProtocolError{"invalid_message", "a message must be a JSON object with a 'type' field", "", ""};
    auto type = msg.find("type");
    if (type == msg.end() || !type->is_string())
        throw ProtocolError{"invalid_message", "missing string field 'type'", "/type", ""};
    const std::string t = *type;
    const auto& types = clientMessageTypes();
    const nlohmann::json* schema =
        std::find(types.begin(), types.end(), t) == types.end() ? nullptr : schemaFor(t);
    if (!schema) {
        std::string known;
        for (const auto& k : types) known += (known.empty() ? "" : ", ") + k;
        throw ProtocolError{"unknown_type", "unknown message type '" + t + "' (known: " + known + ")",
                            "/type", t};
    }
    if (auto v = validateJson(msg, *schema)) {
        // A params value of the wrong type (null, an array) is left to the parameter tables, whose
        // invalid_param error names the parameter's type and range, when nothing else is wrong.
        bool tablesJudge = false;
        if (t == "params" && v->pointer.rfind("/values/", 0) == 0) {
            nlohmann::json rest = msg;
            rest["values"] = nlohmann::json::object();
            tablesJudge = !validateJson(rest, *schema).has_value();
        }
        if (!tablesJudge)
            throw ProtocolError{"invalid_message", (v->pointer.empty() ? "" : v->pointer + ": ") + v->message,
                                v->pointer, t};
    }
    return msg;
}

nlohmann::json errorMessage(const ProtocolError& e) {
    // Messages may quote the client's bytes: only valid UTF-8 may reach dump().
    nlohmann::json m = {{"type", "error"}, {"code", e.code}, {"message", validUtf8(e.message)}};
    if (!e.where.empty()) m["where"] = validUtf8(e.where);
    if (!e.request.empty()) m["request"] = validUtf8(e.request);
    return m;
}

std::vector<std::uint8_t> makeFrameMessage(std::uint32_t frameId, int width, int height, ImageCodec codec,
                                           const std::vector<std::uint8_t>& payload) {
    std::vector<std::uint8_t> out(kFrameHeaderSize + payload.size(), 0);
    out[0] = 'G';
    out[1] = 'I';
    out[2] = 'F';
    out[3] = 'R';
    for (int i = 0; i < 4; ++i) out[4 + i] = static_cast<std::uint8_t>(frameId >> (8 * i));
    out[8] = static_cast<std::uint8_t>(width & 0xff);
    out[9] = static_cast<std::uint8_t>((width >> 8) & 0xff);
    out[10] = static_cast<std::uint8_t>(height & 0xff);
    out[11] = static_cast<std::uint8_t>((height >> 8) & 0xff);
    out[12] = static_cast<std::uint8_t>(codec);
    std::copy(payload.begin(), payload.end(), out.begin() + kFrameHeaderSize);
    return out;
}

} // namespace gis
