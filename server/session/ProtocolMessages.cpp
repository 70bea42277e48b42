#include "session/ProtocolMessages.h"

#include <algorithm>
#include <map>
#include <mutex>

#include "core/EmbeddedFiles.h"
#include "core/Error.h"
#include "core/JsonSchema.h"

namespace gis {
namespace {

/// The embedded schemas by path below protocol/schema, without ".json": "camera", "server/stats".
const nlohmann::json* schemaFor(const std::string& name) {
    static std::once_flag once;
    static std::map<std::string, nlohmann::json> schemas;
    std::call_once(once, [] {
        constexpr std::string_view kDir = "schema/", kExt = ".json";
        for (const auto& f : embedded::protocol()) {
            const std::string_view p = f.path;
            if (!p.starts_with(kDir) || !p.ends_with(kExt)) continue;
            schemas[std::string(p.substr(kDir.size(), p.size() - kDir.size() - kExt.size()))] =
                nlohmann::json::parse(f.content);
        }
    });
    auto it = schemas.find(name);
    return it == schemas.end() ? nullptr : &it->second;
}

/// "/pointer: message", or the message alone at the root.
std::string violationText(const SchemaViolation& v) {
    return (v.pointer.empty() ? "" : v.pointer + ": ") + v.message;
}

const nlohmann::json& messageTable() {
    static const nlohmann::json table = [] {
        const auto text = findEmbedded(embedded::protocol(), "messages.json");
        GIS_ASSERT_MSG(text.has_value(), "protocol/messages.json is not embedded");
        return nlohmann::json::parse(*text);
    }();
    return table;
}

} // namespace

const std::vector<ClientMessageSpec>& clientMessages() {
    static const std::vector<ClientMessageSpec> rows = [] {
        std::vector<ClientMessageSpec> out;
        for (const auto& [type, row] : messageTable().at("client").items()) {
            GIS_ASSERT_MSG(schemaFor(type) != nullptr, "protocol/schema/" + type + ".json is missing");
            out.push_back(
                {type, row.value("viewers", false), row.value("handler", "session") == "connection"});
        }
        return out;
    }();
    return rows;
}

const ClientMessageSpec* findClientMessage(std::string_view type) {
    for (const auto& m : clientMessages())
        if (m.type == type) return &m;
    return nullptr;
}

const std::vector<std::string>& clientMessageTypes() {
    static const std::vector<std::string> types = [] {
        std::vector<std::string> out;
        for (const auto& m : clientMessages()) out.push_back(m.type);
        return out;
    }();
    return types;
}

const std::vector<std::string>& serverMessageTypes() {
    static const std::vector<std::string> types = [] {
        std::vector<std::string> out;
        for (const auto& [type, row] : messageTable().at("server").items()) out.push_back(type);
        return out;
    }();
    return types;
}

std::string checkServerMessage(const nlohmann::json& message) {
    if (!message.is_object() || !message.contains("type") || !message["type"].is_string())
        return "a server message is an object with a string type";
    const std::string type = message["type"];
    const auto& types = serverMessageTypes();
    if (std::find(types.begin(), types.end(), type) == types.end())
        return "'" + type + "' is not a server message in protocol/messages.json";
    const nlohmann::json* schema = schemaFor("server/" + type);
    if (!schema) return "protocol/schema/server/" + type + ".json is missing";
    if (auto v = validateJson(message, *schema)) return violationText(*v);
    return {};
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
    const nlohmann::json* schema = findClientMessage(t) ? schemaFor(t) : nullptr;
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
        if (!tablesJudge) throw ProtocolError{"invalid_message", violationText(*v), v->pointer, t};
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
