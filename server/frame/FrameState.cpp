#include "frame/FrameState.h"

#include <algorithm>

#include "core/Error.h"
#include "core/Log.h"
#include "gi/Catalog.h"
#include "frame/DefaultLighting.h"
#include "frame/Exposure.h"
#include "frame/FrameParams.h"

namespace gis {

FrameState makeFrameState(const Scene& scene, const std::string& technique) {
    FrameState s;
    if (!scene.cameras.empty()) s.camera = scene.cameras.front();
    if (!scene.lights.empty()) {
        setLights(s, scene.lights);
        s.lightSource = "scene";
        s.lightNote = scene.lights.size() == 1
                          ? "the scene's light '" + scene.lights.front().name + "'"
                          : "the scene's " + std::to_string(scene.lights.size()) + " lights";
    } else {
        const DefaultLighting fallback = defaultLighting(scene, s.camera);
        setLights(s, {fallback.key, fallback.fill});
        s.lightSource = "default";
        s.lightNote = fallback.reason;
    }
    s.baseExposure = baseExposure(scene);
    s.frameParams = ParamSet(frameParamTable());
    setTechnique(s, technique);
    return s;
}

std::string nextLightId(const FrameState& state) {
    long next = 0;
    for (const FrameLight& l : state.lights) {
        if (l.id.rfind("light", 0) != 0 || l.id.size() == 5) continue;
        const std::string digits = l.id.substr(5);
        if (digits.size() > 6 ||
            !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
            continue;
        next = std::max(next, std::stol(digits) + 1);
    }
    return "light" + std::to_string(next);
}

FrameLight* findLight(FrameState& state, const std::string& id) {
    for (FrameLight& l : state.lights)
        if (l.id == id) return &l;
    return nullptr;
}

void setLights(FrameState& state, const std::vector<Light>& lights) {
    state.lights.clear();
    for (const Light& l : lights)
        state.lights.push_back({"light" + std::to_string(state.lights.size()), l, true});
}

void setTechnique(FrameState& state, const std::string& technique, const std::string& where) {
    const TechniqueInfo& info = findTechniqueInfo(technique, where);
    state.technique = info.name;
    state.techniqueParams = ParamSet(info.params);
}

void setParam(FrameState& state, const std::string& name, const nlohmann::json& value,
              const std::string& where) {
    if (state.frameParams.has(name)) return state.frameParams.set(name, value, where);
    if (state.techniqueParams.has(name)) return state.techniqueParams.set(name, value, where);
    std::string known;
    for (const auto& s : state.frameParams.table().specs()) known += (known.empty() ? "" : ", ") + s.name;
    for (const auto& s : state.techniqueParams.table().specs()) known += ", " + s.name;
    throw InputError(where, "unknown parameter '" + name + "' for technique '" + state.technique +
                                "' (known: " + known + ")");
}

void setParamFromString(FrameState& state, const std::string& name, const std::string& text,
                        const std::string& where) {
    if (state.frameParams.has(name)) return state.frameParams.setFromString(name, text, where);
    if (state.techniqueParams.has(name)) return state.techniqueParams.setFromString(name, text, where);
    setParam(state, name, nullptr, where); // throws the unknown-parameter error
}

std::vector<std::string> applyParams(FrameState& state, const nlohmann::json& values,
                                     const std::string& where) {
    if (!values.is_object()) throw InputError(where, "expected an object of parameter values");
    FrameState copy = state;
    for (const auto& [k, v] : values.items()) setParam(copy, k, v, where + "/" + k);
    std::vector<std::string> changed;
    nlohmann::json before = paramsJson(state), after = paramsJson(copy);
    for (const auto& [k, v] : after.items())
        if (before[k] != v) changed.push_back(k);
    state = std::move(copy);
    return changed;
}

nlohmann::json paramsJson(const FrameState& state) {
    nlohmann::json out = state.frameParams.toJson();
    const nlohmann::json technique = state.techniqueParams.toJson(); // items() must not outlive it
    for (const auto& [k, v] : technique.items()) out[k] = v;
    return out;
}

namespace {
double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
} // namespace

nlohmann::json medianStats(const std::vector<nlohmann::json>& frames) {
    GIS_ASSERT(!frames.empty());
    nlohmann::json out = frames.back();
    auto collect = [&](const char* key) {
        std::vector<double> v;
        for (const auto& f : frames) v.push_back(f.value(key, 0.0));
        return median(v);
    };
    out["frame_ms"] = collect("frame_ms");
    out["readback_ms"] = collect("readback_ms");
    nlohmann::json& passes = out["passes"];
    for (size_t i = 0; i < passes.size(); ++i) {
        std::vector<double> gpu, cpu;
        for (const auto& f : frames) {
            const auto& p = f["passes"];
            if (i < p.size() && p[i]["name"] == passes[i]["name"]) {
                gpu.push_back(p[i]["gpu_ms"].get<double>());
                cpu.push_back(p[i]["cpu_ms"].get<double>());
            }
        }
        passes[i]["gpu_ms"] = median(gpu);
        passes[i]["cpu_ms"] = median(cpu);
    }
    out["frames"] = frames.size();
    return out;
}

} // namespace gis
