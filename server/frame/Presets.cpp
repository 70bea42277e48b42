#include "frame/Presets.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <mutex>

#include "core/Error.h"
#include "core/JsonSchema.h"

#ifndef GIS_DEFAULT_PRESETS
#define GIS_DEFAULT_PRESETS "presets/presets.json"
#endif

namespace gis {

std::string defaultPresetsPath() {
    if (const char* p = std::getenv("GI_PRESETS"); p && *p) return p;
    return GIS_DEFAULT_PRESETS;
}

const std::vector<std::string>& knownPresets() {
    static const std::vector<std::string> names = {"interactive", "balanced", "final"};
    return names;
}

nlohmann::json loadPresets(const std::string& path) {
    std::ifstream f(path);
    if (!f) throw InputError(path, "cannot read the presets file");
    const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    std::string parseError;
    nlohmann::json j = parseJsonExplained(text, parseError);
    if (j.is_discarded()) throw InputError(path, "not valid JSON: " + parseError);
    if (!j.is_object() || !j.contains("techniques") || !j["techniques"].is_object())
        throw InputError(path, "expected an object with a \"techniques\" object");
    for (const auto& [tech, presets] : j["techniques"].items()) {
        if (!presets.is_object()) throw InputError(path + "/" + tech, "expected an object of presets");
        for (const auto& [name, params] : presets.items())
            if (!params.is_object())
                throw InputError(path + "/" + tech + "/" + name, "expected an object of parameter values");
    }
    return j;
}

namespace {

void checkName(const std::string& name) {
    const auto& names = knownPresets();
    if (std::find(names.begin(), names.end(), name) != names.end()) return;
    std::string known;
    for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
    throw InputError("preset '" + name + "'", "unknown preset (known: " + known + ")");
}

} // namespace

std::string presetDefaultTechnique(const nlohmann::json& presets) {
    if (!presets.is_object()) return {};
    const auto it = presets.find("default_technique");
    if (it == presets.end() || !it->is_object()) return {};
    const auto name = it->find("name");
    return name != it->end() && name->is_string() ? name->get<std::string>() : std::string();
}

nlohmann::json presetParams(const nlohmann::json& presets, const std::string& technique,
                            const std::string& name) {
    checkName(name);
    const std::string where = "preset '" + name + "'";
    const auto& techs = presets.at("techniques");
    if (!techs.contains(technique) || !techs[technique].contains(name))
        throw InputError(where,
                         "no preset for technique '" + technique + "' (run gi-bench sweep and report)");
    return techs[technique][name];
}

nlohmann::json presetParams(const std::string& technique, const std::string& name) {
    checkName(name); // a misspelt name is reported even when the file is missing
    static std::once_flag once;
    static nlohmann::json cached;
    static std::string error;
    std::call_once(once, [] {
        try {
            cached = loadPresets(defaultPresetsPath());
        } catch (const InputError& e) {
            error = e.what();
        }
    });
    if (!error.empty()) throw InputError("preset '" + name + "'", error);
    return presetParams(cached, technique, name);
}

void applyPreset(FrameState& state, const nlohmann::json& presets, const std::string& name) {
    applyParams(state, presetParams(presets, state.technique, name), "preset '" + name + "'");
}

} // namespace gis

namespace gis {

void applyPreset(FrameState& state, const std::string& name) {
    applyParams(state, presetParams(state.technique, name), "preset '" + name + "'");
}

} // namespace gis
