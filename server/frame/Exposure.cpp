#include "frame/Exposure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "frame/LightModel.h"

namespace gis {

namespace {

bool meteringOff(const FrameState& state) {
    return state.frameParams.has("metering") && state.frameParams.getEnum("metering") == "off";
}

} // namespace

std::string evText(double ev) {
    char text[32];
    std::snprintf(text, sizeof text, "%+.1f EV", ev);
    return text;
}

MeteredLight meterLight(const Scene& scene, const std::vector<FrameLight>& lights) {
    std::vector<LightModel> models;
    for (const FrameLight& l : lights) {
        LightModel m = makeLightModel(l, scene.bounds);
        if (m.on) models.push_back(std::move(m));
    }
    std::size_t total = 0;
    for (const Mesh& mesh : scene.meshes) total += mesh.indices.size() / 3 * mesh.placements();
    const std::size_t stride = std::max<std::size_t>(1, (total + kMeterTriangles - 1) / kMeterTriangles);

    MeteredLight out;
    double area = 0.0, litArea = 0.0, logSum = 0.0;
    std::size_t index = 0; // triangle number over every placement, for the stride
    for (const Mesh& mesh : scene.meshes) {
        const std::size_t triangles = mesh.indices.size() / 3;
        if (triangles == 0) continue;
        for (std::size_t placement = 0; placement < mesh.placements(); ++placement) {
            // Skip whole placements the stride does not reach.
            const std::size_t first = (index + stride - 1) / stride * stride;
            if (first >= index + triangles) {
                index += triangles;
                continue;
            }
            const glm::mat4 toWorld = mesh.instanced() ? mesh.instances[placement] : glm::mat4(1.0f);
            for (std::size_t t = first - index; t < triangles; t += stride) {
                glm::dvec3 p[3];
                for (int k = 0; k < 3; ++k) {
                    const std::uint32_t v = mesh.indices[3 * t + static_cast<std::size_t>(k)];
                    p[k] = glm::dvec3(glm::vec3(toWorld * glm::vec4(mesh.positions[v], 1.0f)));
                }
                const glm::dvec3 cross = glm::cross(p[1] - p[0], p[2] - p[0]);
                const double twiceArea = glm::length(cross);
                ++out.samples;
                if (!(twiceArea > 0.0) || !std::isfinite(twiceArea)) continue;
                const double a = 0.5 * twiceArea;
                const glm::dvec3 n = cross / twiceArea;
                const glm::dvec3 centre = (p[0] + p[1] + p[2]) / 3.0;
                glm::dvec3 irradiance(0.0);
                for (const LightModel& m : models) {
                    glm::vec3 toLight, e;
                    float distance = 0.0f;
                    if (!m.incidence(glm::vec3(centre), toLight, distance, e)) continue;
                    // Either side: the meter does not know which one the camera will see.
                    irradiance += glm::dvec3(e) * std::abs(glm::dot(n, glm::dvec3(toLight)));
                }
                const double y = luminance(irradiance);
                area += a;
                if (!(y > 0.0) || !std::isfinite(y)) continue;
                litArea += a;
                logSum += a * std::log(y);
                ++out.lit;
            }
            index += triangles;
        }
    }
    if (litArea > 0.0) out.key = std::exp(logSum / litArea);
    out.litArea = area > 0.0 ? litArea / area : 0.0;
    return out;
}

BaseExposure baseExposure(const Scene& scene) {
    if (scene.authoredExposureEv)
        return {std::clamp(static_cast<double>(*scene.authoredExposureEv), -kMeterEvLimit, kMeterEvLimit),
                "authored", "the scene's own exposure, " + evText(*scene.authoredExposureEv)};
    if (scene.lights.empty()) return {0.0, "default", "the default lighting is made for " + evText(0.0)};
    std::vector<FrameLight> lights;
    for (const Light& l : scene.lights) lights.push_back({"", l, true});
    const MeteredLight m = meterLight(scene, lights);
    if (!(m.key > 0.0))
        return {0.0, "metered",
                "metering found no surface the scene's lights reach: " + evText(0.0) + " (set exposure)"};
    const double ev = std::clamp(std::log2(kMeterKeyIlluminance / m.key), -kMeterEvLimit, kMeterEvLimit);
    char text[160];
    std::snprintf(text, sizeof text,
                  "metered for the scene's lights: %s (key %.3g lux on %.0f%% of the area)",
                  evText(ev).c_str(), m.key, 100.0 * m.litArea);
    return {ev, "metered", text};
}

double frameExposureEv(const FrameState& state) {
    const double base = meteringOff(state) ? 0.0 : state.baseExposure.ev;
    const double compensation =
        state.frameParams.has("exposure") ? state.frameParams.getFloat("exposure") : 0.0;
    return base + compensation;
}

nlohmann::json baseExposureJson(const FrameState& state) {
    const bool off = meteringOff(state);
    return {{"base_ev", off ? 0.0 : state.baseExposure.ev},
            {"source", off ? "off" : state.baseExposure.source},
            {"note", off ? "metering is off: the exposure parameter is absolute" : state.baseExposure.note},
            {"ev", frameExposureEv(state)}};
}

} // namespace gis
