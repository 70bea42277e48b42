// Camera and light JSON (StateJson.h): the semantics Session.cpp had inline, with the checks the
// protocol schemas make repeated here so that a caller without a schema gets the same answers.
#include "frame/StateJson.h"

#include <algorithm>
#include <cmath>

#include "core/Error.h"

namespace gis {
namespace {

constexpr float kDegToRad = 0.017453292519943295f;
constexpr double kMaxCoordinate = 1e6; // metres; the protocol schemas' bound

std::string shortDump(const nlohmann::json& v) {
    std::string s = v.dump();
    return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

std::string number(double v) {
    if (v == std::floor(v) && std::abs(v) < 1e15) return std::to_string(static_cast<long long>(v));
    return nlohmann::json(v).dump();
}

double readNumber(const nlohmann::json& v, const std::string& where, double lo, double hi,
                  const std::string& what) {
    if (!v.is_number() || !std::isfinite(v.get<double>()))
        throw InputError(where, "expected " + what + ", got " + shortDump(v));
    const double d = v.get<double>();
    if (d < lo || d > hi)
        throw InputError(where,
                         what + " must be in [" + number(lo) + ", " + number(hi) + "], got " + shortDump(v));
    return d;
}

glm::vec3 readVec3(const nlohmann::json& v, const std::string& where, double lo, double hi,
                   const std::string& what) {
    if (!v.is_array() || v.size() != 3)
        throw InputError(where, "expected " + what + " as an array of 3 numbers, got " + shortDump(v));
    glm::vec3 out;
    for (int i = 0; i < 3; ++i)
        out[i] = static_cast<float>(readNumber(v[static_cast<size_t>(i)], where + "/" + std::to_string(i), lo,
                                               hi, "a component of " + what));
    return out;
}

void requireObject(const nlohmann::json& v, const std::string& where, const std::string& what) {
    if (!v.is_object()) throw InputError(where, "expected " + what + " object, got " + shortDump(v));
}

nlohmann::json toJson(glm::vec3 v) {
    return {v.x, v.y, v.z};
}

} // namespace

void applyCameraJson(FrameState& state, const nlohmann::json& camera, const std::string& where) {
    requireObject(camera, where, "a camera {\"position\": [x, y, z], \"target\": [x, y, z]}");
    Camera c = state.camera;
    for (const char* key : {"position", "target"})
        if (!camera.contains(key))
            throw InputError(where,
                             std::string("missing '") + key +
                                 "': a camera needs \"position\" and \"target\" ([x, y, z] in metres)");
    c.position = readVec3(camera["position"], where + "/position", -kMaxCoordinate, kMaxCoordinate,
                          "a position [x, y, z] in metres");
    c.target = readVec3(camera["target"], where + "/target", -kMaxCoordinate, kMaxCoordinate,
                        "a target [x, y, z] in metres");
    if (auto up = camera.find("up"); up != camera.end())
        c.up = readVec3(*up, where + "/up", -kMaxCoordinate, kMaxCoordinate, "an up vector [x, y, z]");
    if (auto fov = camera.find("fov_deg"); fov != camera.end())
        c.yfovRadians = static_cast<float>(readNumber(*fov, where + "/fov_deg", 1, 170,
                                                      "the vertical field of view in degrees")) *
                        kDegToRad;
    if (glm::length(c.target - c.position) < 1e-6f)
        throw InputError(where + "/target", "camera position and target must differ");
    if (glm::length(c.up) < 1e-6f) throw InputError(where + "/up", "camera up must not be zero");
    state.camera = c;
}

void applyLightJson(FrameState& state, const nlohmann::json& light, const std::string& where) {
    requireObject(light, where, "a light");
    Light l = state.light;
    bool enabled = state.lightEnabled;
    if (auto p = light.find("position"); p != light.end())
        l.position = readVec3(*p, where + "/position", -kMaxCoordinate, kMaxCoordinate,
                              "a position [x, y, z] in metres");
    if (auto d = light.find("direction"); d != light.end()) {
        const glm::vec3 dir = readVec3(*d, where + "/direction", -1, 1, "a direction [x, y, z]");
        const float len = glm::length(dir);
        if (!(len > 1e-6f)) throw InputError(where + "/direction", "light direction must not be zero");
        l.direction = dir / len;
    }
    if (auto i = light.find("intensity"); i != light.end())
        l.intensity =
            static_cast<float>(readNumber(*i, where + "/intensity", 0, 1e6, "the intensity in candela"));
    if (auto c = light.find("color"); c != light.end())
        l.color = readVec3(*c, where + "/color", 0, 1, "a linear colour [r, g, b]");
    if (auto cone = light.find("cone_deg"); cone != light.end()) {
        const float outer = static_cast<float>(readNumber(*cone, where + "/cone_deg", 1, 85,
                                                          "the cone half-angle in degrees")) *
                            kDegToRad;
        // Keep the soft edge's proportion: inner/outer as the scene defined it.
        const float ratio = l.outerConeAngle > 0 ? l.innerConeAngle / l.outerConeAngle : 0.8f;
        l.outerConeAngle = outer;
        l.innerConeAngle = std::clamp(ratio, 0.0f, 0.99f) * outer;
    }
    if (auto e = light.find("enabled"); e != light.end()) {
        if (!e->is_boolean())
            throw InputError(where + "/enabled", "expected true or false, got " + shortDump(*e));
        enabled = e->get<bool>();
    }
    state.light = l;
    state.lightEnabled = enabled;
}

nlohmann::json cameraJson(const Camera& c) {
    return {{"position", toJson(c.position)},
            {"target", toJson(c.target)},
            {"up", toJson(c.up)},
            {"fov_deg", c.yfovRadians / kDegToRad}};
}

nlohmann::json lightJson(const FrameState& state) {
    const Light& l = state.light;
    return {{"position", toJson(l.position)},
            {"direction", toJson(l.direction)},
            {"intensity", l.intensity},
            {"color", toJson(l.color)},
            {"cone_deg", l.outerConeAngle / kDegToRad},
            {"enabled", state.lightEnabled}};
}

} // namespace gis
