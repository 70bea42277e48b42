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

namespace {

const char* typeName(LightType t) {
    return t == LightType::Spot ? "spot" : t == LightType::Point ? "point" : "directional";
}

// Applies the fields of `light` to `l` and `enabled`: everything is read before either changes.
void readLightFields(const nlohmann::json& light, const std::string& where, Light& out, bool& enabledOut,
                     bool readType = true) {
    requireObject(light, where, "a light");
    Light l = out;
    bool enabled = enabledOut;
    if (auto t = light.find("type"); readType && t != light.end()) {
        const std::string name = t->is_string() ? t->get<std::string>() : "";
        if (name == "spot")
            l.type = LightType::Spot;
        else if (name == "point")
            l.type = LightType::Point;
        else if (name == "directional")
            l.type = LightType::Directional;
        else
            throw InputError(where + "/type",
                             "expected \"spot\", \"point\" or \"directional\", got " + shortDump(*t));
    }
    if (auto n = light.find("name"); n != light.end()) {
        if (!n->is_string() || n->get<std::string>().size() > 200)
            throw InputError(where + "/name",
                             "expected a name of at most 200 characters, got " + shortDump(*n));
        l.name = n->get<std::string>();
    }
    if (auto p = light.find("position"); p != light.end())
        l.position = readVec3(*p, where + "/position", -kMaxCoordinate, kMaxCoordinate,
                              "a position [x, y, z] in metres");
    if (auto d = light.find("direction"); d != light.end()) {
        const glm::vec3 dir = readVec3(*d, where + "/direction", -1, 1, "a direction [x, y, z]");
        const float len = glm::length(dir);
        if (!(len > 1e-6f))
            throw InputError(where + "/direction",
                             "light direction must not be zero: give the unit vector the light "
                             "points along, e.g. [0, -1, 0] for straight down");
        l.direction = dir / len;
    }
    if (auto i = light.find("intensity"); i != light.end())
        l.intensity = static_cast<float>(readNumber(*i, where + "/intensity", 0, 1e6,
                                                    "the intensity (candela; lux for a directional light)"));
    if (auto c = light.find("color"); c != light.end())
        l.color = readVec3(*c, where + "/color", 0, 1, "a linear colour [r, g, b]");
    if (auto r = light.find("range"); r != light.end())
        l.range = static_cast<float>(
            readNumber(*r, where + "/range", 0, kMaxCoordinate, "the range in metres (0 = infinite)"));
    // Cones: the outer half-angle, and the inner one either given or keeping its proportion of the
    // outer one as the scene defined it.
    const float ratio = l.outerConeAngle > 0 ? l.innerConeAngle / l.outerConeAngle : 0.8f;
    if (auto cone = light.find("cone_deg"); cone != light.end()) {
        const float outer = static_cast<float>(readNumber(*cone, where + "/cone_deg", 1, 85,
                                                          "the cone half-angle in degrees")) *
                            kDegToRad;
        l.outerConeAngle = outer;
        l.innerConeAngle = std::clamp(ratio, 0.0f, 0.99f) * outer;
    }
    if (auto inner = light.find("inner_cone_deg"); inner != light.end()) {
        const float in = static_cast<float>(readNumber(*inner, where + "/inner_cone_deg", 0, 85,
                                                       "the inner cone half-angle in degrees")) *
                         kDegToRad;
        if (!(in < l.outerConeAngle))
            throw InputError(where + "/inner_cone_deg",
                             "the inner cone must be narrower than the outer one (" +
                                 number(l.outerConeAngle / kDegToRad) + " degrees)");
        l.innerConeAngle = in;
    }
    if (auto e = light.find("enabled"); e != light.end()) {
        if (!e->is_boolean())
            throw InputError(where + "/enabled", "expected true or false, got " + shortDump(*e));
        enabled = e->get<bool>();
    }
    out = l;
    enabledOut = enabled;
}

std::string knownIds(const FrameState& state) {
    std::string ids;
    for (const FrameLight& l : state.lights) ids += (ids.empty() ? "" : ", ") + l.id;
    return ids.empty() ? "none" : ids;
}

std::string readId(const nlohmann::json& v, const std::string& where) {
    if (!v.is_string() || v.get<std::string>().empty() || v.get<std::string>().size() > 64)
        throw InputError(where, "expected a light id such as \"light0\", got " + shortDump(v));
    return v.get<std::string>();
}

} // namespace

void editLightJson(FrameState& state, const std::string& id, const nlohmann::json& fields,
                   const std::string& where, bool allowType, const std::string& idWhere) {
    FrameLight* target = nullptr;
    if (!id.empty()) {
        target = findLight(state, id);
        if (!target)
            throw InputError(idWhere.empty() ? where + "/id" : idWhere,
                             "no light '" + id + "' (lights: " + knownIds(state) + ")");
    } else if (!state.lights.empty()) {
        target = &state.lights.front(); // protocol 1's single light
    }
    if (!target) {
        FrameLight fresh{nextLightId(state), Light{.name = "light"}, true};
        readLightFields(fields, where, fresh.light, fresh.enabled, allowType);
        state.lights.push_back(fresh);
        return;
    }
    readLightFields(fields, where, target->light, target->enabled, allowType);
}

void applyLightJson(FrameState& state, const nlohmann::json& message, const std::string& where) {
    requireObject(message, where, "a light");
    // Protocol 2 nests the fields in "light" (which may then carry the light's own "type"); protocol 1
    // sent them flat, beside the message's "type".
    const auto nested = message.find("light");
    const bool isNested = nested != message.end();
    const nlohmann::json& fields = isNested ? *nested : message;
    const std::string fieldsAt = isNested ? where + "/light" : where;
    std::string id, idWhere = where + "/id";
    if (auto i = message.find("id"); i != message.end()) {
        id = readId(*i, idWhere);
    } else if (isNested && fields.is_object() && fields.contains("id")) {
        idWhere = fieldsAt + "/id";
        id = readId(fields["id"], idWhere);
    }
    editLightJson(state, id, fields, fieldsAt, isNested, idWhere);
}

std::string addLightJson(FrameState& state, const nlohmann::json& light, const std::string& where) {
    requireObject(light, where, "a light");
    if (state.lights.size() >= kMaxFrameLights)
        throw InputError(where, "a frame holds at most " + std::to_string(kMaxFrameLights) +
                                    " lights: remove one first");
    FrameLight fresh{nextLightId(state), Light{}, true};
    fresh.light.name = "added " + fresh.id;
    if (auto id = light.find("id"); id != light.end()) {
        fresh.id = readId(*id, where + "/id");
        if (findLight(state, fresh.id))
            throw InputError(where + "/id", "light '" + fresh.id + "' exists already");
    }
    readLightFields(light, where, fresh.light, fresh.enabled);
    state.lights.push_back(fresh);
    return fresh.id;
}

void removeLight(FrameState& state, const std::string& id, const std::string& where) {
    const auto before = state.lights.size();
    std::erase_if(state.lights, [&](const FrameLight& l) { return l.id == id; });
    if (state.lights.size() == before)
        throw InputError(where, "no light '" + id + "' (lights: " + knownIds(state) + ")");
}

void setLightsJson(FrameState& state, const nlohmann::json& lights, const std::string& where) {
    if (!lights.is_array()) throw InputError(where, "expected an array of lights, got " + shortDump(lights));
    if (lights.size() > kMaxFrameLights)
        throw InputError(where, "at most " + std::to_string(kMaxFrameLights) + " lights, got " +
                                    std::to_string(lights.size()));
    FrameState scratch;
    for (size_t i = 0; i < lights.size(); ++i) {
        const std::string at = where + "/" + std::to_string(i);
        requireObject(lights[i], at, "a light");
        if (!lights[i].contains("type"))
            throw InputError(at, "missing 'type': \"spot\", \"point\" or \"directional\"");
        FrameLight l{nextLightId(scratch), Light{}, true};
        l.light.name = "light " + std::to_string(i);
        if (auto id = lights[i].find("id"); id != lights[i].end()) {
            l.id = readId(*id, at + "/id");
            if (findLight(scratch, l.id)) throw InputError(at + "/id", "light '" + l.id + "' appears twice");
        }
        readLightFields(lights[i], at, l.light, l.enabled);
        scratch.lights.push_back(l);
    }
    state.lights = std::move(scratch.lights);
}

nlohmann::json cameraJson(const Camera& c) {
    return {{"position", toJson(c.position)},
            {"target", toJson(c.target)},
            {"up", toJson(c.up)},
            {"fov_deg", c.yfovRadians / kDegToRad}};
}

nlohmann::json lightJson(const FrameLight& fl) {
    const Light& l = fl.light;
    return {{"id", fl.id},
            {"name", l.name},
            {"type", typeName(l.type)},
            {"position", toJson(l.position)},
            {"direction", toJson(l.direction)},
            {"intensity", l.intensity},
            {"color", toJson(l.color)},
            {"range", l.range},
            {"cone_deg", l.outerConeAngle / kDegToRad},
            {"inner_cone_deg", l.innerConeAngle / kDegToRad},
            {"enabled", fl.enabled}};
}

nlohmann::json lightsJson(const FrameState& state) {
    nlohmann::json out = nlohmann::json::array();
    for (const FrameLight& l : state.lights) out.push_back(lightJson(l));
    return out;
}

nlohmann::json lightJson(const FrameState& state) {
    if (state.lights.empty()) return nullptr;
    return lightJson(state.lights.front());
}

} // namespace gis
