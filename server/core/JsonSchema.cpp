#include "core/JsonSchema.h"

#include <cmath>

namespace gis {
namespace {

bool matchesType(const nlohmann::json& v, const std::string& type) {
    if (type == "object") return v.is_object();
    if (type == "array") return v.is_array();
    if (type == "string") return v.is_string();
    if (type == "boolean") return v.is_boolean();
    if (type == "null") return v.is_null();
    if (type == "number") return v.is_number();
    if (type == "integer") {
        if (v.is_number_integer()) return true;
        if (!v.is_number_float()) return false;
        double d = v.get<double>();
        return std::isfinite(d) && d == std::floor(d);
    }
    return false;
}

std::string describe(const nlohmann::json& v) {
    return jsonExcerpt(v, 60);
}

/// Appends a rendering of `v` to `out`, stopping once `out` holds more than `budget` bytes.
void appendExcerpt(const nlohmann::json& v, std::string& out, std::size_t budget, int depth) {
    if (out.size() > budget) return;
    if (v.is_object() || v.is_array()) {
        const bool object = v.is_object();
        out += object ? '{' : '[';
        if (depth >= 3 && !v.empty()) {
            out += "...";
        } else {
            bool first = true;
            for (auto it = v.begin(); it != v.end() && out.size() <= budget; ++it) {
                if (!first) out += ',';
                first = false;
                if (object) {
                    // Keys can be long too: bounded like string values.
                    appendExcerpt(nlohmann::json(it.key().substr(0, budget)), out, budget, depth + 1);
                    out += ':';
                }
                appendExcerpt(*it, out, budget, depth + 1);
            }
        }
        out += object ? '}' : ']';
        return;
    }
    if (v.is_string()) {
        // Only the part that can be shown is serialised: a 1 MB string costs what its excerpt costs.
        const auto& s = v.get_ref<const std::string&>();
        out += nlohmann::json(s.substr(0, budget + 1))
                   .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
        return;
    }
    out += v.dump();
}

std::string escapePointerToken(const std::string& key) {
    std::string out;
    for (char c : key) {
        if (c == '~')
            out += "~0";
        else if (c == '/')
            out += "~1";
        else
            out += c;
    }
    return out;
}

std::optional<SchemaViolation> check(const nlohmann::json& v, const nlohmann::json& schema,
                                     const std::string& at) {
    if (schema.is_boolean()) {
        if (schema.get<bool>()) return std::nullopt;
        return SchemaViolation{at, "is not allowed here"};
    }
    if (!schema.is_object()) return std::nullopt;

    if (auto t = schema.find("type"); t != schema.end()) {
        bool ok = false;
        std::string expected;
        if (t->is_string()) {
            ok = matchesType(v, *t);
            expected = *t;
        } else if (t->is_array()) {
            for (const auto& one : *t) {
                ok = ok || matchesType(v, one);
                expected += (expected.empty() ? "" : " or ") + one.get<std::string>();
            }
        }
        if (!ok) return SchemaViolation{at, "expected " + expected + ", got " + describe(v)};
    }
    if (auto c = schema.find("const"); c != schema.end() && v != *c)
        return SchemaViolation{at, "must be " + c->dump() + ", got " + describe(v)};
    if (auto e = schema.find("enum"); e != schema.end()) {
        bool found = false;
        for (const auto& option : *e) found = found || option == v;
        if (!found) return SchemaViolation{at, "must be one of " + e->dump() + ", got " + describe(v)};
    }
    if (v.is_number()) {
        double d = v.get<double>();
        if (!std::isfinite(d)) return SchemaViolation{at, "must be a finite number"};
        if (auto m = schema.find("minimum"); m != schema.end() && d < m->get<double>())
            return SchemaViolation{at, "must be >= " + m->dump() + ", got " + describe(v)};
        if (auto m = schema.find("maximum"); m != schema.end() && d > m->get<double>())
            return SchemaViolation{at, "must be <= " + m->dump() + ", got " + describe(v)};
        if (auto m = schema.find("exclusiveMinimum"); m != schema.end() && d <= m->get<double>())
            return SchemaViolation{at, "must be > " + m->dump() + ", got " + describe(v)};
        if (auto m = schema.find("exclusiveMaximum"); m != schema.end() && d >= m->get<double>())
            return SchemaViolation{at, "must be < " + m->dump() + ", got " + describe(v)};
    }
    if (v.is_string()) {
        auto len = v.get_ref<const std::string&>().size();
        if (auto m = schema.find("minLength"); m != schema.end() && len < m->get<size_t>())
            return SchemaViolation{at, "must have at least " + m->dump() + " characters"};
        if (auto m = schema.find("maxLength"); m != schema.end() && len > m->get<size_t>())
            return SchemaViolation{at, "must have at most " + m->dump() + " characters"};
    }
    if (v.is_array()) {
        if (auto m = schema.find("minItems"); m != schema.end() && v.size() < m->get<size_t>())
            return SchemaViolation{at, "must have at least " + m->dump() + " items, got " +
                                           std::to_string(v.size())};
        if (auto m = schema.find("maxItems"); m != schema.end() && v.size() > m->get<size_t>())
            return SchemaViolation{at, "must have at most " + m->dump() + " items, got " +
                                           std::to_string(v.size())};
        if (auto items = schema.find("items"); items != schema.end()) {
            for (size_t i = 0; i < v.size(); ++i)
                if (auto r = check(v[i], *items, at + "/" + std::to_string(i))) return r;
        }
    }
    if (v.is_object()) {
        if (auto req = schema.find("required"); req != schema.end()) {
            for (const auto& key : *req)
                if (!v.contains(key.get<std::string>()))
                    return SchemaViolation{at, "missing required field '" + key.get<std::string>() + "'"};
        }
        const nlohmann::json* props = nullptr;
        if (auto p = schema.find("properties"); p != schema.end()) props = &*p;
        auto additional = schema.find("additionalProperties");
        for (const auto& [key, value] : v.items()) {
            std::string child = at + "/" + escapePointerToken(key);
            if (props && props->contains(key)) {
                if (auto r = check(value, (*props)[key], child)) return r;
            } else if (additional != schema.end()) {
                if (additional->is_boolean() && !additional->get<bool>())
                    return SchemaViolation{child, "unknown field '" + key + "'"};
                if (auto r = check(value, *additional, child)) return r;
            }
        }
    }
    return std::nullopt;
}

} // namespace

std::optional<SchemaViolation> validateJson(const nlohmann::json& instance, const nlohmann::json& schema) {
    return check(instance, schema, "");
}

std::string validUtf8(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    size_t i = 0;
    while (i < text.size()) {
        const auto c = static_cast<unsigned char>(text[i]);
        // Length of the sequence this lead byte starts (0: not a lead byte), and the smallest code
        // point it may encode (overlong forms are invalid).
        size_t len = 0;
        unsigned long cp = 0, min = 0;
        if (c < 0x80) {
            out += static_cast<char>(c);
            ++i;
            continue;
        } else if ((c & 0xE0) == 0xC0) {
            len = 2, cp = c & 0x1Fu, min = 0x80;
        } else if ((c & 0xF0) == 0xE0) {
            len = 3, cp = c & 0x0Fu, min = 0x800;
        } else if ((c & 0xF8) == 0xF0) {
            len = 4, cp = c & 0x07u, min = 0x10000;
        }
        bool ok = len > 0 && i + len <= text.size();
        for (size_t k = 1; ok && k < len; ++k) {
            const auto b = static_cast<unsigned char>(text[i + k]);
            if ((b & 0xC0) != 0x80) ok = false;
            cp = (cp << 6) | (b & 0x3Fu);
        }
        if (ok && (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))) ok = false;
        if (ok) {
            out.append(text.substr(i, len));
            i += len;
        } else {
            static const char* kHex = "0123456789ABCDEF";
            out += "\\x";
            out += kHex[c >> 4];
            out += kHex[c & 0xF];
            ++i;
        }
    }
    return out;
}

std::optional<std::size_t> findExcessNesting(std::string_view text, int maxDepth) {
    int depth = 0;
    bool inString = false, escaped = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (escaped)
                escaped = false;
            else if (c == '\\')
                escaped = true;
            else if (c == '"')
                inString = false;
            continue;
        }
        if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > maxDepth) return i;
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return std::nullopt;
}

std::string jsonExcerpt(const nlohmann::json& value, std::size_t maxChars) {
    std::string out;
    appendExcerpt(value, out, maxChars, 0);
    if (out.size() <= maxChars) return out;
    std::size_t cut = maxChars >= 3 ? maxChars - 3 : 0;
    // Never split a UTF-8 sequence: back up over continuation bytes.
    while (cut > 0 && (static_cast<unsigned char>(out[cut]) & 0xC0) == 0x80) --cut;
    out.resize(cut);
    return out + "...";
}

nlohmann::json parseJsonExplained(std::string_view text, std::string& error, int maxDepth) {
    error.clear();
    if (auto at = findExcessNesting(text, maxDepth)) {
        error = "arrays and objects nested deeper than " + std::to_string(maxDepth) + " levels at byte " +
                std::to_string(*at) + "; flatten the document";
        return nlohmann::json(nlohmann::json::value_t::discarded);
    }
    try {
        return nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
        std::string what = e.what();
        if (what.rfind("[json.exception.", 0) == 0) {
            const size_t close = what.find("] ");
            if (close != std::string::npos) what = what.substr(close + 2);
        }
        // The parser quotes the bytes it stopped at, which may not be UTF-8.
        error = what.empty() ? "not valid JSON" : validUtf8(what);
        return nlohmann::json(nlohmann::json::value_t::discarded);
    }
}

} // namespace gis
