#include "effects/EffectPlan.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include <glm/gtc/matrix_inverse.hpp>

#include "frame/LightModel.h"
#include "frame/VplBudget.h"
#include "gi/Catalog.h"
#include "gi/common/ParamSpecs.h"
#include "reference/RayScene.h"
#include "reference/Sampling.h"
#include "scene/SurfaceAnalysis.h"
#include "scene/Brdf.h"

namespace gis {
namespace {

using reference::kInvPi;
using reference::kPi;
using reference::RayScene;
using reference::Rng;
using reference::SurfaceHit;

// Frame-time model on llvmpipe (2 shared cores), fitted to glFinish pass timings of `ssbc` with
// vpl_shadows at 256x256 (docs/effects.md): the gather per VPL-receiver pair (docs/ssbc.md, 512^2),
// the visibility lookups per pair plus each VPL's cube shadow map per thousand triangles
// (`vpl_shadows` pass), compensation per pixel (`ssbc_mips` + `ssbc_integrate_1`), and the light's
// shadow map, RSM and direct passes per pixel. Only the size matters: decisions never read it.
constexpr double kGatherNsPerPair = 1.6;
constexpr double kShadowNsPerPair = 4.2;
constexpr double kShadowMsPerVplPerKTri = 0.3;
constexpr double kCompensationNsPerPixel = 1250.0;
constexpr double kDirectNsPerPixel = 120.0;

glm::vec3 facing(const glm::vec3& n, const glm::vec3& towards) {
    return glm::dot(n, towards) < 0.0f ? -n : n;
}

double sumSq(const glm::dvec3& v) {
    return glm::dot(v, v);
}

/// A point the transport reads: position, normal on the shaded side, geometric normal on that side.
struct Point {
    glm::vec3 p{0.0f}, n{0.0f}, ng{0.0f}, albedo{0.0f};
};

std::string fmt(const char* format, double a, double b = 0.0, double c = 0.0, double d = 0.0) {
    char buf[256];
    std::snprintf(buf, sizeof buf, format, a, b, c, d);
    return buf;
}

/// Traces the eye ray through normalised device coordinates (nx, ny) of the pipeline's own projection
/// (as the reference renderer does), so samples see exactly the GL frustum. False on a miss or a
/// degenerate ray; `dir` is the unit ray direction.
bool traceEyeRay(const RayScene& rays, const glm::dmat4& invViewProj, double nx, double ny, SurfaceHit& hit,
                 glm::vec3& dir, long long& rayCount) {
    const glm::dvec4 nearP = invViewProj * glm::dvec4(nx, ny, -1.0, 1.0);
    const glm::dvec4 farP = invViewProj * glm::dvec4(nx, ny, 1.0, 1.0);
    if (!(std::abs(nearP.w) > 1e-300) || !(std::abs(farP.w) > 1e-300)) return false;
    const glm::vec3 o(glm::dvec3(nearP) / nearP.w), f(glm::dvec3(farP) / farP.w);
    const float len = glm::length(f - o);
    if (!(len > 0.0f)) return false;
    dir = (f - o) / len;
    ++rayCount;
    return rays.intersectFromCamera(o, dir, 0.0f, len, hit);
}

/// The forced state of one effect from its frame parameter; "auto" when the table lacks it.
Material materialOf(const Scene& scene, int mesh) {
    if (mesh < 0 || mesh >= static_cast<int>(scene.meshes.size())) return Material{};
    const int m = scene.meshes[static_cast<size_t>(mesh)].material;
    return m >= 0 && m < static_cast<int>(scene.materials.size()) ? scene.materials[static_cast<size_t>(m)]
                                                                  : Material{};
}

bool hasLobe(const Material& m) {
    return brdf::surfaceFrom(m, glm::vec3(m.baseColor)).hasSpecular();
}

std::string forcedMode(const FrameState& state, const std::string& effect) {
    const std::string name = "effect_" + effect;
    return state.frameParams.has(name) ? state.frameParams.getEnum(name) : "auto";
}

// The coarsest eye-space level worth starting the multiresolution refinement at (000 §3, 001 §3.2):
// levels on which nearly every patch holds a depth or normal discontinuity split completely, so they
// add a pass and save nothing, while starting finer than needed splits patches that could have stayed
// whole. Measured on a regular grid of eye rays with the pipeline's own min-max tests and thresholds:
// the start is the coarsest candidate level on which at least kMinWholeFraction of the patches need
// no refinement. Candidates are powers of two from 4 to 64 patches along the longer side (the
// parameter's unit), each patch at least 2x2 samples.
constexpr double kMinWholeFraction = 0.10;
// A non-diffuse effect runs when more than this fraction of the samples (0.2%: two of 1024 view
// samples) reach it.
constexpr double kNonDiffuseMinFraction = 0.002;
constexpr int kLevelGrid = 128; // samples along the longer side

EffectDecision planCoarsestLevel(const RayScene& rays, const FrameState& state, long long& rayCount) {
    EffectDecision d{.effect = "levels"};
    d.measurement = "coarsest eye level (patches along the longer side) with >= 10% of covered patches whole";
    d.threshold = kMinWholeFraction;
    const int w = std::max(state.width, 1), h = std::max(state.height, 1);
    const int gx = w >= h ? kLevelGrid : std::max(2, kLevelGrid * w / h);
    const int gy = w >= h ? std::max(2, kLevelGrid * h / w) : kLevelGrid;
    const glm::dmat4 invViewProj = glm::inverse(glm::dmat4(cameraViewProj(state.camera, w, h)));
    struct Sample {
        bool hit = false;
        float distance = 0.0f;
        glm::vec3 normal{0.0f};
    };
    std::vector<Sample> grid(static_cast<size_t>(gx) * gy);
    for (int j = 0; j < gy; ++j)
        for (int i = 0; i < gx; ++i) {
            SurfaceHit hit;
            glm::vec3 dir;
            if (!traceEyeRay(rays, invViewProj, 2.0 * (i + 0.5) / gx - 1.0, 1.0 - 2.0 * (j + 0.5) / gy, hit,
                             dir, rayCount))
                continue;
            Sample& s = grid[static_cast<size_t>(j) * gx + i];
            s.hit = true;
            s.distance = glm::length(hit.position - state.camera.position);
            s.normal = facing(hit.shadingNormal, -dir);
        }
    // Only techniques with the eye hierarchy (TechniqueInfo::eyeHierarchy) come here; its own
    // thresholds decide.
    const double depthThreshold = state.techniqueParams.getFloat("depth_threshold");
    const double normalThreshold = state.techniqueParams.getFloat("normal_threshold");
    const bool diagonal = state.techniqueParams.getBool("diagonal_refine");
    // Whole fraction per candidate level, among the patches with geometry (empty ones are never lit).
    std::string densities;
    int chosen = 0;
    const int longSide = std::max(gx, gy);
    for (int level = 4; level <= 64 && level * 2 <= longSide; level *= 2) {
        const int cell = std::max(1, longSide / level);
        const int px = (gx + cell - 1) / cell, py = (gy + cell - 1) / cell;
        std::vector<std::uint8_t> covered(static_cast<size_t>(px) * py, 0), disc(covered.size(), 0);
        for (int cy = 0; cy < py; ++cy)
            for (int cx = 0; cx < px; ++cx) {
                bool anyHit = false, anyMiss = false;
                float dMin = std::numeric_limits<float>::max(), dMax = 0.0f;
                glm::vec3 nMin(2.0f), nMax(-2.0f);
                for (int y = cy * cell; y < std::min((cy + 1) * cell, gy); ++y)
                    for (int x = cx * cell; x < std::min((cx + 1) * cell, gx); ++x) {
                        const Sample& s = grid[static_cast<size_t>(y) * gx + x];
                        if (!s.hit) {
                            anyMiss = true;
                            continue;
                        }
                        anyHit = true;
                        dMin = std::min(dMin, s.distance);
                        dMax = std::max(dMax, s.distance);
                        nMin = glm::min(nMin, s.normal);
                        nMax = glm::max(nMax, s.normal);
                    }
                const glm::vec3 nRange = nMax - nMin;
                const size_t k = static_cast<size_t>(cy) * px + cx;
                covered[k] = anyHit;
                // shaders/gi/common/eye_hierarchy.glsl eyePatchDiscontinuous: partial coverage, depth
                // range beyond a fraction of the nearest, or a normal component's range.
                disc[k] = anyHit && (anyMiss || dMax - dMin > depthThreshold * std::max(dMin, 1e-6f) ||
                                     std::max({nRange.x, nRange.y, nRange.z}) > normalThreshold);
            }
        int patches = 0, whole = 0;
        for (int cy = 0; cy < py; ++cy)
            for (int cx = 0; cx < px; ++cx) {
                const size_t k = static_cast<size_t>(cy) * px + cx;
                if (!covered[k]) continue;
                bool refine = disc[k];
                // eye_flags.frag: a discontinuous diagonal neighbour refines too (000 §5.2).
                for (int dy = -1; dy <= 1 && diagonal && !refine; dy += 2)
                    for (int dx = -1; dx <= 1; dx += 2) {
                        const int x = cx + dx, y = cy + dy;
                        if (x >= 0 && y >= 0 && x < px && y < py && disc[static_cast<size_t>(y) * px + x])
                            refine = true;
                    }
                ++patches;
                if (!refine) ++whole;
            }
        const double wholeFraction = patches > 0 ? static_cast<double>(whole) / patches : 1.0;
        densities += (densities.empty() ? "" : ", ") + fmt("%.0f%%", 100.0 * wholeFraction) + " at " +
                     std::to_string(level);
        if (chosen == 0 && wholeFraction >= kMinWholeFraction) {
            chosen = level;
            d.value = level;
        }
    }
    const int current = state.techniqueParams.getInt("coarsest_size");
    if (chosen == 0) {
        // Discontinuities everywhere down to the finest candidate: keep the configured start.
        d.value = current;
        d.reason = "patches left whole: " + densities + "; none reaches 10%, keeping coarsest_size " +
                   std::to_string(current);
    } else {
        d.reason = "patches left whole: " + densities +
                   "; coarser levels would split nearly all, so start at " + std::to_string(chosen) +
                   " (configured " + std::to_string(current) + ")";
    }
    return d;
}

} // namespace

const EffectDecision* EffectPlan::find(std::string_view effect) const {
    for (const auto& d : decisions)
        if (d.effect == effect) return &d;
    return nullptr;
}

bool EffectPlan::enabled(std::string_view effect) const {
    const EffectDecision* d = find(effect);
    return d == nullptr || d->enabled;
}

EffectPlan planEffects(const Scene& scene, const FrameState& state, const EffectPlanOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    const RayScene rays(scene, {.fastBuild = true}); // a few thousand rays: the build is what costs
    EffectPlan plan = planEffects(scene, rays, state, options);
    // The structure's build is part of what this call cost.
    plan.analysisMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return plan;
}

EffectPlan planEffects(const Scene& scene, const reference::RayScene& rays, const FrameState& state,
                       const EffectPlanOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    EffectPlan plan;
    plan.mode = state.frameParams.has("effects") ? state.frameParams.getEnum("effects") : "manual";

    const float eps = rays.epsilon();
    // The lights exactly as the renderer shows them (frame/LightModel.h): the enabled ones that reach
    // the scene, at most max_lights.
    const LightSetModel lightSet = makeLightSet(state, scene.bounds);
    const bool lightOn = lightSet.any();
    for (const LightModel& l : lightSet.lights) plan.lightsRendered.push_back(l.id);
    plan.lightsSkipped = lightSet.skipped;
    // Point-kernel singularity: receivers next to a VPL would dominate a few-hundred-sample estimate,
    // so distances are floored at 2% of the scene radius (a G bound far above any clamp_b in use).
    const float minDist = std::max(0.02f * scene.bounds.radius(), 1e-4f);

    // 1. Receivers: one jittered sample per cell of a grid over the image, through the pipeline's own
    //    projection (as the reference renderer), so they see exactly the GL frustum.
    const int w = std::max(state.width, 1), h = std::max(state.height, 1);
    const double aspect = static_cast<double>(w) / h;
    const int gx = std::max(1, static_cast<int>(std::lround(std::sqrt(options.viewSamples * aspect))));
    const int gy = std::max(1, options.viewSamples / gx);
    const glm::dmat4 invViewProj = glm::inverse(glm::dmat4(cameraViewProj(state.camera, w, h)));
    std::vector<Point> receivers;
    receivers.reserve(static_cast<size_t>(gx) * gy);
    std::vector<glm::vec3> emission;
    std::vector<Material> receiverMaterial; // what the non-diffuse decisions read
    std::vector<int> receiverMesh;
    for (int j = 0; j < gy; ++j)
        for (int i = 0; i < gx; ++i) {
            Rng rng(options.seed, static_cast<std::uint64_t>(j * gx + i), 0);
            const double nx = 2.0 * (i + rng.uniform()) / gx - 1.0;
            const double ny = 1.0 - 2.0 * (j + rng.uniform()) / gy;
            SurfaceHit hit;
            glm::vec3 dir;
            if (!traceEyeRay(rays, invViewProj, nx, ny, hit, dir, plan.rays)) continue;
            receivers.push_back({hit.position, facing(hit.shadingNormal, -dir),
                                 facing(hit.geometricNormal, -dir), hit.albedo});
            emission.push_back(hit.emission);
            receiverMesh.push_back(hit.mesh);
            receiverMaterial.push_back(materialOf(scene, hit.mesh));
        }
    plan.receivers = static_cast<int>(receivers.size());

    // 2. Light paths, the samples split across lights by the flux each sends into the scene: per light,
    //    stratified directions over a spot's cone or a point light's sphere (uniform in solid angle),
    //    or stratified origins over a directional light's orthographic square (uniform in area). Each
    //    hit is a VPL carrying flux rho x (irradiance on a surface facing the light) x (the sample's
    //    share of the measure: solid angle x d^2, or area), oriented towards the light (the RSM's rule).
    struct Vpl {
        Point at;
        glm::vec3 flux{0.0f};
    };
    std::vector<Vpl> vpls;
    std::vector<Material> vplMaterial;
    if (lightOn) {
        const float radius = std::max(scene.bounds.radius(), 1e-6f);
        double totalFlux = 0.0;
        for (const LightModel& l : lightSet.lights) totalFlux += std::max(l.sceneFlux(radius), 0.0);
        const int n = std::max(options.vplSamples, 1);
        for (size_t li = 0; li < lightSet.lights.size(); ++li) {
            const LightModel& light = lightSet.lights[li];
            const double share = totalFlux > 0.0 ? std::max(light.sceneFlux(radius), 0.0) / totalFlux
                                                 : 1.0 / static_cast<double>(lightSet.lights.size());
            const int samples = static_cast<int>(std::lround(n * share));
            if (samples <= 0) continue;
            const int side = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(samples))));
            const bool directional = light.type == LightType::Directional;
            const float cosOuter = light.type == LightType::Spot ? light.cosOuter : -1.0f;
            const LightViewModel& view = lightSet.views[static_cast<size_t>(light.firstView)];
            const float perSample =
                directional
                    ? (2.0f * view.halfWidth) * (2.0f * view.halfWidth) / static_cast<float>(side * side)
                    : 2.0f * kPi * (1.0f - cosOuter) / static_cast<float>(side * side);
            glm::vec3 t, b;
            reference::basisAround(light.axis, t, b);
            const glm::mat4 invView = glm::inverse(view.viewProj); // orthographic: NDC to world
            for (int j = 0; j < side; ++j)
                for (int i = 0; i < side; ++i) {
                    Rng rng(options.seed + 1 + li, static_cast<std::uint64_t>(j * side + i), 1);
                    glm::vec3 origin = light.position, dir = light.axis;
                    if (directional) {
                        const float u = 2.0f * (static_cast<float>(i) + rng.uniform()) / side - 1.0f;
                        const float v = 2.0f * (static_cast<float>(j) + rng.uniform()) / side - 1.0f;
                        origin = glm::vec3(invView * glm::vec4(u, v, -1.0f, 1.0f)); // on the near plane
                    } else {
                        const float cosTheta =
                            1.0f - (1.0f - cosOuter) * (static_cast<float>(j) + rng.uniform()) / side;
                        const float phi = 2.0f * kPi * (static_cast<float>(i) + rng.uniform()) / side;
                        const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
                        dir = cosTheta * light.axis + sinTheta * (std::cos(phi) * t + std::sin(phi) * b);
                    }
                    SurfaceHit hit;
                    ++plan.rays;
                    if (!rays.intersect(origin, dir, 0.0f, std::numeric_limits<float>::infinity(), hit))
                        continue;
                    glm::vec3 toLight, irradiance;
                    float dist = 0.0f;
                    if (!light.incidence(hit.position, toLight, dist, irradiance)) continue;
                    const float measure = directional ? perSample : perSample * dist * dist;
                    const glm::vec3 flux = hit.albedo * irradiance * measure;
                    Vpl vpl{{hit.position, facing(hit.shadingNormal, -dir), facing(hit.geometricNormal, -dir),
                             hit.albedo},
                            flux};
                    vpls.push_back(vpl);
                    vplMaterial.push_back(materialOf(scene, hit.mesh));
                }
        }
    }
    plan.vpls = static_cast<int>(vpls.size());

    // 3. Per receiver: direct (hard shadow), one bounce without and with x-y visibility, and the part of
    //    the unoccluded bounce the clamp min(G, b) removes.
    const TechniqueInfo& technique = findTechniqueInfo(state.technique);
    const bool hasClamp = technique.biasCompensation;
    const double clampB =
        hasClamp ? vplClampB(state.techniqueParams, scene.bounds.longestSide()) : 0.0; // 1/m^2
    double truthSq = 0.0, indirectSq = 0.0, occlusionSq = 0.0, compensationSq = 0.0;
    double pairsWeighted = 0.0, pairsOccludedWeighted = 0.0;
    int lit = 0, reached = 0;
    for (size_t r = 0; r < receivers.size(); ++r) {
        if (options.stop && r > 0 && r % kPlanStopEvery == 0 && options.stop()) {
            plan.stopped = true;
            plan.decisions.clear();
            return plan;
        }
        const Point& x = receivers[r];
        glm::dvec3 direct(emission[r]);
        bool litHere = false;
        for (const LightModel& light : lightSet.lights) {
            glm::vec3 l, irradiance;
            float dist = 0.0f;
            if (!light.incidence(x.p, l, dist, irradiance)) continue;
            const float cosX = glm::dot(x.n, l);
            if (!(cosX > 0.0f) || !(glm::dot(irradiance, irradiance) > 0.0f)) continue;
            const glm::vec3 origin = x.p + facing(x.ng, l) * eps;
            ++plan.rays;
            const float tfar = std::isfinite(dist) ? glm::length(light.position - origin) - eps
                                                   : std::numeric_limits<float>::infinity();
            if (!rays.occluded(origin, l, 0.0f, tfar)) {
                direct += glm::dvec3(x.albedo * kInvPi * irradiance * cosX);
                litHere = true;
            }
        }
        if (litHere) ++lit;
        glm::dvec3 unoccluded(0.0), occluded(0.0), removed(0.0);
        for (const Vpl& v : vpls) {
            const glm::vec3 d = v.at.p - x.p;
            const float dist = glm::length(d);
            if (!(dist > 1e-6f)) continue;
            const glm::vec3 l = d / dist;
            const float cosX = glm::dot(x.n, l), cosY = -glm::dot(v.at.n, l);
            if (!(cosX > 0.0f) || !(cosY > 0.0f)) continue;
            const float dd = std::max(dist, minDist);
            const double g = static_cast<double>(cosX) * cosY / (static_cast<double>(dd) * dd);
            const glm::dvec3 e = glm::dvec3(x.albedo * kInvPi * v.flux * kInvPi) * g;
            unoccluded += e;
            if (clampB > 0.0 && g > clampB) removed += e * ((g - clampB) / g);
            const glm::vec3 origin = x.p + facing(x.ng, l) * eps;
            const float tfar = glm::length(v.at.p - origin) - 2.0f * eps;
            ++plan.rays;
            const bool blocked = tfar > eps && rays.occluded(origin, l, 0.0f, tfar);
            if (!blocked) occluded += e;
            const double weight = e.x + e.y + e.z;
            pairsWeighted += weight;
            if (blocked) pairsOccludedWeighted += weight;
        }
        if (glm::dot(glm::dvec3(unoccluded), glm::dvec3(1.0)) > 0.0 ||
            glm::dot(direct, glm::dvec3(1.0)) > 0.0)
            ++reached;
        truthSq += sumSq(direct + occluded);
        indirectSq += sumSq(occluded);
        occlusionSq += sumSq(unoccluded - occluded);
        compensationSq += sumSq(removed);
    }
    const double truthNorm = std::sqrt(truthSq);
    auto relative = [&](double sq) { return truthNorm > 0.0 ? std::sqrt(sq) / truthNorm : 0.0; };

    // Cost model inputs.
    const double pixels = static_cast<double>(w) * h;
    // The technique's own VPL count (TechniqueInfo::vplEstimate); 256 for one without VPLs.
    const long estimated = vplEstimate(state);
    const double vplCount = estimated > 0 ? static_cast<double>(estimated) : 256.0;
    const double gatherMs = vplCount * pixels * kGatherNsPerPair * 1e-6;
    const double triangles = static_cast<double>(scene.triangleCount());

    auto decide = [&](EffectDecision d, bool measuredOn) {
        const std::string mode = forcedMode(state, d.effect);
        d.forced = mode != "auto";
        d.enabled = d.forced ? mode == "on" : measuredOn;
        d.applied = d.forced || plan.mode == "auto";
        if (d.forced) d.reason = "forced " + mode + " (measured: " + d.reason + ")";
        plan.decisions.push_back(std::move(d));
    };

    // Direct: off only when the light reaches no receiver, directly or after one bounce.
    {
        EffectDecision d{.effect = "direct"};
        d.measurement = "fraction of view samples the light reaches (directly or by one bounce)";
        d.value =
            receivers.empty() ? 0.0 : static_cast<double>(reached) / static_cast<double>(receivers.size());
        d.threshold = 0.0;
        d.costMs = pixels * kDirectNsPerPixel * 1e-6;
        if (!lightOn)
            d.reason = lightSet.skipped.empty() ? "there is no light"
                                                : "no light is rendered: " + lightSet.skipped.front();
        else if (receivers.empty())
            d.reason = "no surface is in view";
        else
            d.reason = fmt("the light reaches %.1f%% of the view (%.1f%% directly)", 100.0 * d.value,
                           100.0 * lit / static_cast<double>(receivers.size()));
        const bool on = lightOn && d.value > d.threshold;
        decide(std::move(d), on);
    }
    const bool directOn = plan.decisions.back().enabled;

    // Diffuse bounce: dropping it removes the whole occluded one-bounce term from the image.
    {
        EffectDecision d{.effect = "indirect"};
        d.measurement = "estimated relative RMSE of dropping the bounce";
        d.value = relative(indirectSq);
        d.threshold = options.indirectThreshold;
        d.available = state.technique != "none";
        d.costMs = d.available ? gatherMs : 0.0;
        if (!directOn)
            d.reason = "the light is off";
        else if (vpls.empty())
            d.reason = "the light hits no surface";
        else
            d.reason = fmt("the bounce is %.2f%% of the image (relative RMSE; threshold %.2f%%)",
                           100.0 * d.value, 100.0 * d.threshold);
        const bool on = directOn && d.value > d.threshold;
        decide(std::move(d), on);
    }
    const bool indirectOn = plan.decisions.back().enabled;

    // Indirect occlusion: what x-y visibility changes in the bounce.
    {
        EffectDecision d{.effect = "occlusion"};
        d.measurement = "estimated relative RMSE of ignoring indirect visibility";
        d.value = relative(occlusionSq);
        d.threshold = options.occlusionThreshold;
        d.available = technique.vplVisibility;
        d.costMs = d.available ? vplCount * pixels * kShadowNsPerPair * 1e-6 +
                                     vplCount * triangles * 1e-3 * kShadowMsPerVplPerKTri
                               : 0.0;
        const double pairFraction = pairsWeighted > 0.0 ? pairsOccludedWeighted / pairsWeighted : 0.0;
        d.reason = fmt("%.1f%% of the bounce's VPL-receiver transfer is occluded; ignoring it costs %.2f%% "
                       "(threshold %.2f%%)",
                       100.0 * pairFraction, 100.0 * d.value, 100.0 * d.threshold);
        if (!indirectOn) d.reason = "the bounce is off";
        if (!d.available) d.reason += "; the technique has no vpl_shadows";
        const bool on = indirectOn && d.available && d.value > d.threshold;
        decide(std::move(d), on);
    }

    // Bias compensation: the energy min(G, b) removes from the unoccluded bounce.
    {
        EffectDecision d{.effect = "compensation"};
        d.measurement = "estimated relative RMSE of the energy clamp_b removes";
        d.value = relative(compensationSq);
        d.threshold = options.compensationThreshold;
        d.available = technique.biasCompensation && clampB > 0.0;
        d.costMs = d.available ? pixels * kCompensationNsPerPixel * 1e-6 : 0.0;
        if (!indirectOn)
            d.reason = "the bounce is off";
        else if (!hasClamp)
            d.reason = "the technique has no clamp_b";
        else if (!(clampB > 0.0))
            d.reason = "clamp_b is 0: the kernel removes nothing";
        else
            d.reason =
                fmt("clamp_b %.3g (%.3g/m^2) removes %.2f%% (relative RMSE; threshold %.2f%%)",
                    state.techniqueParams.getFloat("clamp_b"), clampB, 100.0 * d.value, 100.0 * d.threshold);
        const bool on = indirectOn && d.available && d.value > d.threshold;
        decide(std::move(d), on);
    }

    // Non-diffuse effects (docs/nondiffuse.md): which specular paths the view and the light reach.
    // Each value is a fraction of samples (view samples on geometry, or light samples); an effect
    // runs when that fraction exceeds kNonDiffuseMinFraction.
    {
        const float split =
            state.frameParams.has("glossy_split") ? state.frameParams.getFloat("glossy_split") : 0.35f;
        const int mirrorDepth =
            state.frameParams.has("mirror_depth") ? state.frameParams.getInt("mirror_depth") : 1;
        const float mirrorRoughness =
            state.frameParams.has("mirror_roughness") ? state.frameParams.getFloat("mirror_roughness") : 0.1f;
        const TechniqueInfo& info = findTechniqueInfo(state.technique);
        const bool glossyAvailable = info.glossyTransport && info.glossyTransport(state.techniqueParams);
        std::vector<bool> mirrorMesh(scene.meshes.size(), false);
        if (mirrorDepth > 0)
            for (const MirrorPlane& m : findPlanarMirrors(scene, mirrorRoughness))
                mirrorMesh[static_cast<size_t>(m.mesh)] = true;
        int specularView = 0, roughView = 0, smoothView = 0, mirrorView = 0, roughLight = 0;
        for (size_t i = 0; i < receiverMaterial.size(); ++i) {
            const Material& m = receiverMaterial[i];
            if (!hasLobe(m)) continue;
            ++specularView;
            const int mesh = receiverMesh[i];
            if (mesh >= 0 && mirrorMesh[static_cast<size_t>(mesh)])
                ++mirrorView;
            else if (!specularWorthAPass(m, split))
                continue; // a rough dielectric: direct highlights only
            else if (m.roughness >= split && glossyAvailable)
                ++roughView;
            else
                ++smoothView;
        }
        for (const Material& m : vplMaterial)
            if (specularWorthAPass(m, split) && m.roughness >= split) ++roughLight;
        const double view = std::max<double>(receivers.size(), 1.0);
        const double lightSamples = std::max<double>(vpls.size(), 1.0);
        auto fraction = [&](EffectDecision& d, double v, const char* what) {
            d.value = v;
            d.threshold = kNonDiffuseMinFraction;
            d.reason = fmt("%.1f%% of the ", 100.0 * v) + what;
        };
        {
            EffectDecision d{.effect = "specular"};
            d.measurement = "fraction of view samples on surfaces with a specular lobe";
            fraction(d, specularView / view, "view has a specular lobe");
            d.costMs = pixels * kDirectNsPerPixel * 1e-6 * 0.3;
            if (!directOn) d.reason = "the light is off";
            decide(std::move(d), directOn && specularView / view > kNonDiffuseMinFraction);
        }
        {
            EffectDecision d{.effect = "glossy"};
            d.measurement = "larger of the view and light fractions on lobes at least glossy_split rough";
            const double v = std::max(roughView / view, glossyAvailable ? roughLight / lightSamples : 0.0);
            fraction(d, v, "view or light samples are on rough specular surfaces");
            d.available = glossyAvailable;
            d.costMs = d.available ? 2.0 * gatherMs * std::min(1.0, v * 4.0) : 0.0;
            if (!indirectOn) d.reason = "the bounce is off";
            if (!glossyAvailable) d.reason += "; the technique has no glossy VPL transport";
            decide(std::move(d), indirectOn && glossyAvailable && v > kNonDiffuseMinFraction);
        }
        {
            EffectDecision d{.effect = "env"};
            d.measurement = "fraction of view samples on smooth specular surfaces outside planar mirrors";
            fraction(d, smoothView / view, "view is smooth specular (environment probe)");
            if (!directOn) d.reason = "the light is off";
            decide(std::move(d), directOn && smoothView / view > kNonDiffuseMinFraction);
        }
        {
            EffectDecision d{.effect = "mirrors"};
            d.measurement = "fraction of view samples on planar mirrors";
            fraction(d, mirrorView / view, "view is a planar mirror");
            if (mirrorDepth == 0) d.reason = "mirror_depth is 0";
            decide(std::move(d), mirrorDepth > 0 && mirrorView / view > kNonDiffuseMinFraction);
        }
    }

    // Multiresolution level limit: where the eye-space hierarchy should start refining.
    if (technique.eyeHierarchy) decide(planCoarsestLevel(rays, state, plan.rays), true);

    plan.analysisMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return plan;
}

void applyEffectPlan(FrameState& state, const EffectPlan& plan) {
    const TechniqueInfo* technique = &findTechniqueInfo(state.technique);
    for (const EffectDecision& d : plan.decisions) {
        if (!d.applied) continue;
        if (d.effect == "direct") {
            // Forcing it on cannot light a scene without lights; it only keeps the lights as they are.
            if (!d.enabled)
                for (FrameLight& l : state.lights) l.enabled = false;
        } else if (d.effect == "indirect") {
            if (!d.enabled && state.technique != "none") {
                setTechnique(state, "none", "effect_indirect");
                technique = &findTechniqueInfo(state.technique);
            }
        } else if (d.effect == "occlusion") {
            if (technique->vplVisibility)
                state.techniqueParams.set("vpl_shadows", d.enabled, "effect_occlusion");
        } else if (d.effect == "specular" || d.effect == "glossy" || d.effect == "env" ||
                   d.effect == "mirrors") {
            // The renderer resolves these itself (render/Reflections); the plan narrows `auto` to
            // what the view shows.
            const std::string name = "effect_" + d.effect;
            if (state.frameParams.has(name)) state.frameParams.set(name, d.enabled ? "on" : "off", "effects");
        } else if (d.effect == "levels") {
            if (technique->eyeHierarchy && d.value >= 1.0)
                state.techniqueParams.set("coarsest_size", static_cast<int>(d.value), "effects");
        } else if (d.effect == "compensation") {
            if (technique->biasCompensation && state.techniqueParams.getFloat("clamp_b") > 0.0) {
                const int now = state.techniqueParams.getInt("ssbc_iterations");
                state.techniqueParams.set("ssbc_iterations", d.enabled ? std::max(now, 1) : 0,
                                          "effect_compensation");
            }
        }
    }
    state.plan = toJson(plan);
}

nlohmann::json toJson(const EffectPlan& plan) {
    nlohmann::json decisions = nlohmann::json::array();
    for (const auto& d : plan.decisions)
        decisions.push_back({{"effect", d.effect},
                             {"enabled", d.enabled},
                             {"forced", d.forced},
                             {"applied", d.applied},
                             {"available", d.available},
                             {"reason", d.reason},
                             {"measurement", d.measurement},
                             {"value", d.value},
                             {"threshold", d.threshold},
                             {"cost_ms", d.costMs}});
    return {{"mode", plan.mode},
            {"decisions", std::move(decisions)},
            {"receivers", plan.receivers},
            {"vpls", plan.vpls},
            {"rays", plan.rays},
            {"analysis_ms", plan.analysisMs},
            {"lights", {{"rendered", plan.lightsRendered}, {"skipped", plan.lightsSkipped}}}};
}

std::string describe(const EffectPlan& plan) {
    std::string out = "effect plan (effects=" + plan.mode + "; " + std::to_string(plan.receivers) +
                      " receivers, " + std::to_string(plan.vpls) + " VPLs, " + std::to_string(plan.rays) +
                      " rays, " + fmt("%.1f ms", plan.analysisMs) + ")\n";
    char line[160];
    std::snprintf(line, sizeof line, "  %-13s %-4s %-7s %-9s %10s %10s %9s  %s\n", "effect", "on", "forced",
                  "applied", "value", "threshold", "cost ms", "reason");
    out += line;
    for (const auto& d : plan.decisions) {
        std::snprintf(line, sizeof line, "  %-13s %-4s %-7s %-9s %10.5f %10.5f %9.1f  ", d.effect.c_str(),
                      d.enabled ? "on" : "off", d.forced ? "yes" : "no", d.applied ? "yes" : "no", d.value,
                      d.threshold, d.costMs);
        out += line + d.reason + "\n";
    }
    out += "  lights rendered: " + std::to_string(plan.lightsRendered.size());
    for (const std::string& id : plan.lightsRendered) out += " " + id;
    out += "\n";
    for (const std::string& s : plan.lightsSkipped) out += "  skipped " + s + "\n";
    return out;
}

} // namespace gis
