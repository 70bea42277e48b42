#include "core/Param.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

#include "core/Error.h"

namespace gis {

std::string paramTypeName(ParamType type) {
    switch (type) {
    case ParamType::Int:
        return "integer";
    case ParamType::Float:
        return "number";
    case ParamType::Bool:
        return "boolean";
    case ParamType::Enum:
        return "string";
    }
    return "?";
}

namespace {

// Exact, so that a range or a rejected value reads as it was written: 16777216, not 1.67772e+07.
std::string formatNumber(double v) {
    if (std::isnan(v)) return "NaN";
    if (std::isinf(v)) return v > 0 ? "Infinity" : "-Infinity";
    if (v == std::floor(v) && std::abs(v) < 1e15) return std::to_string(static_cast<long long>(v));
    char buf[32];
    auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v); // shortest text that reads back as v
    return ec == std::errc() ? std::string(buf, end) : std::to_string(v);
}

/// A rejected value as the error shows it: numbers exactly (NaN and infinities by name, where JSON
/// would print null), anything else as JSON.
std::string valueText(const nlohmann::json& v) {
    return v.is_number() ? formatNumber(v.get<double>()) : v.dump();
}

std::string rangeText(const ParamSpec& s) {
    switch (s.type) {
    case ParamType::Bool:
        return "true or false";
    case ParamType::Enum: {
        std::string out = "one of ";
        for (size_t i = 0; i < s.options.size(); ++i) out += (i ? ", '" : "'") + s.options[i] + "'";
        return out;
    }
    default: {
        std::string out = std::string(s.type == ParamType::Int ? "an integer" : "a number") + " in [" +
                          formatNumber(s.min) + ", " + formatNumber(s.max) + "]";
        if (!s.unit.empty()) out += " " + s.unit;
        return out;
    }
    }
}

nlohmann::json defaultJson(const ParamSpec& s) {
    switch (s.type) {
    case ParamType::Int:
        return static_cast<long long>(std::llround(s.defaultValue));
    case ParamType::Float:
        return s.defaultValue;
    case ParamType::Bool:
        return s.defaultValue != 0.0;
    case ParamType::Enum:
        return s.options.at(static_cast<size_t>(s.defaultValue));
    }
    return nullptr;
}

} // namespace

ParamTable::ParamTable(std::vector<ParamSpec> specs) : mSpecs(std::move(specs)) {
    for (size_t i = 0; i < mSpecs.size(); ++i) {
        const ParamSpec& s = mSpecs[i];
        GIS_ASSERT_MSG(!s.name.empty(), "parameter without a name");
        for (size_t j = 0; j < i; ++j)
            GIS_ASSERT_MSG(mSpecs[j].name != s.name, "duplicate parameter " + s.name);
        if (s.type == ParamType::Enum) {
            GIS_ASSERT_MSG(s.defaultValue >= 0 && s.defaultValue < static_cast<double>(s.options.size()),
                           "enum default out of range: " + s.name);
        } else if (s.type != ParamType::Bool) {
            GIS_ASSERT_MSG(s.min <= s.defaultValue && s.defaultValue <= s.max,
                           "default outside range: " + s.name);
            GIS_ASSERT_MSG(!s.logScale || s.min > 0, "log-scale parameter needs min > 0: " + s.name);
        }
    }
}

const ParamSpec* ParamTable::find(std::string_view name) const {
    for (const auto& s : mSpecs)
        if (s.name == name) return &s;
    return nullptr;
}

ParamTable ParamTable::merged(const ParamTable& other) const {
    std::vector<ParamSpec> all = mSpecs;
    all.insert(all.end(), other.mSpecs.begin(), other.mSpecs.end());
    return ParamTable(std::move(all));
}

nlohmann::json ParamTable::jsonSchema() const {
    nlohmann::json props = nlohmann::json::object();
    int order = 0;
    for (const auto& s : mSpecs) {
        nlohmann::json p;
        p["type"] = paramTypeName(s.type);
        // JSON objects do not keep their keys' order: the table's (most important first) goes along.
        p["x-order"] = order++;
        p["default"] = defaultJson(s);
        p["description"] = s.help;
        if (s.type == ParamType::Int || s.type == ParamType::Float) {
            p["minimum"] = s.min;
            p["maximum"] = s.max;
            if (s.logScale) p["x-log-scale"] = true;
        }
        if (s.type == ParamType::Enum) p["enum"] = s.options;
        if (!s.unit.empty()) p["x-unit"] = s.unit;
        if (!s.source.empty()) p["x-source"] = s.source;
        props[s.name] = std::move(p);
    }
    return {{"type", "object"}, {"additionalProperties", false}, {"properties", std::move(props)}};
}

std::vector<nlohmann::json> ParamTable::sweepValues(const ParamSpec& s, int count) {
    std::vector<nlohmann::json> out;
    count = std::max(count, 1);
    switch (s.type) {
    case ParamType::Bool:
        return {false, true};
    case ParamType::Enum:
        for (const auto& o : s.options) out.emplace_back(o);
        return out;
    default:
        break;
    }
    for (int i = 0; i < count; ++i) {
        double t = count == 1 ? 0.5 : static_cast<double>(i) / (count - 1);
        double v = s.logScale ? s.min * std::pow(s.max / s.min, t) : s.min + t * (s.max - s.min);
        if (s.type == ParamType::Int) {
            long long iv = std::llround(v);
            if (out.empty() || out.back().get<long long>() != iv) out.emplace_back(iv);
        } else {
            out.emplace_back(v);
        }
    }
    return out;
}

std::string ParamTable::describe() const {
    std::ostringstream o;
    for (const auto& s : mSpecs) {
        o << "  " << s.name << " (" << paramTypeName(s.type) << ", default " << defaultJson(s).dump() << ", "
          << rangeText(s) << ")\n      " << s.help;
        if (!s.source.empty()) o << " [" << s.source << "]";
        o << "\n";
    }
    return o.str();
}

ParamSet::ParamSet(ParamTable table) : mTable(std::move(table)) {
    resetToDefaults();
}

void ParamSet::resetToDefaults() {
    mValues = nlohmann::json::object();
    for (const auto& s : mTable.specs()) mValues[s.name] = defaultJson(s);
}

const ParamSpec& ParamSet::spec(std::string_view name) const {
    const ParamSpec* s = mTable.find(name);
    GIS_ASSERT_MSG(s != nullptr, "unknown parameter read: " + std::string(name));
    return *s;
}

nlohmann::json ParamSet::validated(const ParamSpec& s, const nlohmann::json& value,
                                   const std::string& where) const {
    const std::string loc = where.empty() ? s.name : where;
    auto fail = [&](const std::string& got) -> nlohmann::json {
        throw InputError(loc, "'" + s.name + "' must be " + rangeText(s) + ", got " + got);
    };
    switch (s.type) {
    case ParamType::Bool:
        if (!value.is_boolean()) return fail(valueText(value));
        return value;
    case ParamType::Enum: {
        if (!value.is_string()) return fail(valueText(value));
        const auto& str = value.get_ref<const std::string&>();
        if (std::find(s.options.begin(), s.options.end(), str) == s.options.end())
            return fail("'" + str + "'");
        return value;
    }
    case ParamType::Int: {
        if (!value.is_number()) return fail(valueText(value));
        double d = value.get<double>();
        if (!std::isfinite(d) || d != std::floor(d) || d < s.min || d > s.max) return fail(valueText(value));
        return static_cast<long long>(d);
    }
    case ParamType::Float: {
        if (!value.is_number()) return fail(valueText(value));
        double d = value.get<double>();
        if (!std::isfinite(d) || d < s.min || d > s.max) return fail(valueText(value));
        return d;
    }
    }
    return nullptr;
}

void ParamSet::set(std::string_view name, const nlohmann::json& value, const std::string& where) {
    const ParamSpec* s = mTable.find(name);
    if (!s) {
        std::string known;
        for (const auto& k : mTable.specs()) known += (known.empty() ? "" : ", ") + k.name;
        throw InputError(
            where.empty() ? std::string(name) : where,
            "unknown parameter '" + std::string(name) + "'" +
                (known.empty() ? " (this technique has no parameters)" : " (known: " + known + ")"));
    }
    mValues[s->name] = validated(*s, value, where);
}

void ParamSet::setFromString(std::string_view name, std::string_view text, const std::string& where) {
    const ParamSpec* s = mTable.find(name);
    if (!s) return set(name, nullptr, where); // throws the unknown-parameter error
    std::string t(text);
    nlohmann::json v;
    switch (s->type) {
    case ParamType::Enum:
        v = t;
        break;
    case ParamType::Bool:
        if (t == "true" || t == "1" || t == "on")
            v = true;
        else if (t == "false" || t == "0" || t == "off")
            v = false;
        else
            v = t;
        break;
    default: {
        double d = 0;
        auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), d);
        if (ec != std::errc() || ptr != t.data() + t.size())
            v = t;
        else
            v = d;
        break;
    }
    }
    set(name, v, where);
}

std::vector<std::string> ParamSet::apply(const nlohmann::json& object, const std::string& where) {
    if (!object.is_object())
        throw InputError(where, "parameters must be a JSON object, got " + object.dump());
    ParamSet copy = *this;
    std::vector<std::string> changed;
    for (const auto& [key, value] : object.items()) {
        copy.set(key, value, where.empty() ? key : where + "/" + key);
        if (mValues.contains(key) && mValues[key] != copy.mValues[key]) changed.push_back(key);
    }
    *this = std::move(copy);
    return changed;
}

double ParamSet::getFloat(std::string_view name) const {
    const auto& s = spec(name);
    GIS_ASSERT(s.type == ParamType::Float || s.type == ParamType::Int);
    return mValues.at(s.name).get<double>();
}
int ParamSet::getInt(std::string_view name) const {
    const auto& s = spec(name);
    GIS_ASSERT(s.type == ParamType::Int);
    return static_cast<int>(mValues.at(s.name).get<long long>());
}
bool ParamSet::getBool(std::string_view name) const {
    const auto& s = spec(name);
    GIS_ASSERT(s.type == ParamType::Bool);
    return mValues.at(s.name).get<bool>();
}
const std::string& ParamSet::getEnum(std::string_view name) const {
    const auto& s = spec(name);
    GIS_ASSERT(s.type == ParamType::Enum);
    return mValues.at(s.name).get_ref<const std::string&>();
}

nlohmann::json ParamSet::toJson() const {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& s : mTable.specs()) out[s.name] = mValues.at(s.name);
    return out;
}

} // namespace gis
