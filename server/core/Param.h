// Parameters are declared once, in a ParamTable (name, type, default, range, unit, help, source).
// Everything else is derived from that table: validation with clear errors (ParamSet), the JSON
// Schema the server publishes, CLI `--param k=v` parsing, the client's control panel and the sweep
// axes of gi-bench. No knob is hand-copied anywhere else.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace gis {

enum class ParamType { Int, Float, Bool, Enum };

struct ParamSpec {
    std::string name;        ///< snake_case key, unique within its table
    ParamType type = ParamType::Float;
    double defaultValue = 0; ///< for Enum: index into options
    double min = 0;          ///< inclusive; ignored for Bool and Enum
    double max = 0;          ///< inclusive
    std::string unit;        ///< "m", "px", "count", "EV", "" for unitless
    std::string help;        ///< one line, shown in --list-params, the schema and the client
    std::string source;      ///< where the knob comes from ("000 §3.5", "eng")
    std::vector<std::string> options; ///< Enum only
    bool logScale = false;   ///< sweeps and sliders step geometrically (ranges spanning decades)
};

class ParamTable {
public:
    ParamTable() = default;
    explicit ParamTable(std::vector<ParamSpec> specs);

    const std::vector<ParamSpec>& specs() const { return mSpecs; }
    const ParamSpec* find(std::string_view name) const;
    bool empty() const { return mSpecs.empty(); }

    /// Table with the specs of both (names must not collide).
    ParamTable merged(const ParamTable& other) const;
    /// JSON Schema (draft 2020-12 subset) of an object holding these parameters; every property
    /// carries default, range, "x-unit", "x-source" and a description.
    nlohmann::json jsonSchema() const;
    /// `count` evenly (or geometrically, for logScale) spaced valid values across the range.
    static std::vector<nlohmann::json> sweepValues(const ParamSpec& spec, int count);
    /// Human-readable listing for --list-params.
    std::string describe() const;

private:
    std::vector<ParamSpec> mSpecs;
};

/// Current values for one table. Every mutation validates and throws InputError naming the
/// parameter, the accepted range with its unit, and the rejected value.
class ParamSet {
public:
    ParamSet() = default;
    explicit ParamSet(ParamTable table);

    const ParamTable& table() const { return mTable; }

    void set(std::string_view name, const nlohmann::json& value, const std::string& where = {});
    /// Parses "1.5", "16", "true", "filmic" according to the parameter's type (CLI flags).
    void setFromString(std::string_view name, std::string_view text, const std::string& where = {});
    /// Applies every key of a JSON object, all or nothing: on any error nothing changes.
    /// Returns the names whose value changed.
    std::vector<std::string> apply(const nlohmann::json& object, const std::string& where = {});
    bool has(std::string_view name) const { return mTable.find(name) != nullptr; }

    double getFloat(std::string_view name) const;
    int getInt(std::string_view name) const;
    bool getBool(std::string_view name) const;
    const std::string& getEnum(std::string_view name) const;

    nlohmann::json toJson() const; ///< {name: value}
    void resetToDefaults();

private:
    nlohmann::json validated(const ParamSpec& spec, const nlohmann::json& value, const std::string& where) const;
    const ParamSpec& spec(std::string_view name) const;

    ParamTable mTable;
    nlohmann::json mValues = nlohmann::json::object();
};

std::string paramTypeName(ParamType type);

} // namespace gis
