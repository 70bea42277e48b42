// Digest S.4's 21 hard cases as scene-level tests, each instantiated for every registered technique
// (GetParam()); cases that do not apply to a technique skip and show "n/a" in docs/stability.md.
// Every frame goes through stability::render(), which asserts the shared S.4 conditions (finite
// buffers, no negative radiance, energy bound, frame time, black background); the bodies add the
// case's own assertions and note the measured values for the table.
#include <cmath>
#include <cstdio>
#include <limits>

#include <glm/gtc/constants.hpp>

#include "StabilityLab.h"
#include "StabilityScenes.h"
#include "frame/LightModel.h"
#include "gi/Technique.h"
#include "gi/common/EyeHierarchy.h"
#include "gi/second_order/Halton.h"
#include "gi/second_order/SecondOrder.h"
#include "gl/ShaderShared.h"
#include "frame/FrameState.h"

using namespace gis;
using namespace gis::stability;
namespace sc = gis::stability::scenes;

namespace {

/// Indirect radiance as one top-to-bottom RGBA array (zeros for `none`).
std::vector<float> indirectImage(const Frame& f) {
    std::vector<float> out(static_cast<size_t>(f.spec.width) * f.spec.height * 4, 0.0f);
    for (int y = 0; y < f.spec.height; ++y)
        for (int x = 0; x < f.spec.width; ++x)
            for (int c = 0; c < 3; ++c)
                out[(static_cast<size_t>(y) * f.spec.width + x) * 4 + c] = f.indirectAt(x, y, c);
    return out;
}

double indirectSum(const Frame& f) {
    return sumRgb(indirectImage(f));
}

double maxAbs(const std::vector<float>& v) {
    double m = 0;
    for (size_t i = 0; i < v.size(); ++i)
        if (i % 4 != 3) m = std::max(m, double(std::abs(v[i])));
    return m;
}

/// Parameters that only some techniques declare are dropped by the harness for the others, so one
/// object can describe "min_distance 0 wherever there is one".
nlohmann::json merge(nlohmann::json a, const nlohmann::json& b) {
    for (const auto& [k, v] : b.items()) a[k] = v;
    return a;
}

/// Eye-hierarchy thresholds that refine every varying patch down to pixels.
const nlohmann::json kZeroEyeThresholds = {{"depth_threshold", 0.0},
                                           {"normal_threshold", 0.0},
                                           {"depth_derivative_threshold", 0.0},
                                           {"curvature_threshold", 0.0}};

/// Window mean of the indirect radiance's channel mean around (x, y).
double indirectWindow(const Frame& f, int x, int y, int r) {
    double s = 0;
    int n = 0;
    for (int j = y - r; j <= y + r; ++j)
        for (int i = x - r; i <= x + r; ++i) {
            if (i < 0 || j < 0 || i >= f.spec.width || j >= f.spec.height || !f.coveredAt(i, j)) continue;
            s += (f.indirectAt(i, j, 0) + f.indirectAt(i, j, 1) + f.indirectAt(i, j, 2)) / 3.0;
            ++n;
        }
    return n ? s / n : 0.0;
}

glm::ivec2 project(const Camera& cam, glm::vec3 p, int w, int h) {
    const glm::vec4 clip = cameraViewProj(cam, w, h) * glm::vec4(p, 1.0f);
    const glm::vec2 ndc = glm::vec2(clip) / clip.w;
    return {int((ndc.x * 0.5f + 0.5f) * w), int((0.5f - ndc.y * 0.5f) * h)};
}

} // namespace

class S4 : public CaseTest {
protected:
    RenderSpec spec(const sc::ScenePtr& scene, const nlohmann::json& params = nlohmann::json::object(),
                    int w = 64, int h = 64) const {
        RenderSpec s;
        s.scene = scene;
        s.technique = technique();
        s.width = w;
        s.height = h;
        s.params = params;
        return s;
    }
    RenderSpec specFor(const std::string& tech, const sc::ScenePtr& scene,
                       const nlohmann::json& params = nlohmann::json::object(), int w = 64,
                       int h = 64) const {
        RenderSpec s = spec(scene, params, w, h);
        s.technique = tech;
        return s;
    }
};

// ---- 1. VPL coincident with the receiver ---------------------------------------------------------
// The crease puts the floor's VPLs against the wall's receivers at distances down to 0 (the contact
// line) and 1e-7-scale; min_distance 0 removes the point kernel's clamp, clamp_b 1e4 leaves K3 with
// a huge bound. The kernels' own bounds are checked exactly by KernelProbeTest.
TEST_P(S4, C01_CoincidentVpl) {
    if (!appliesTo(vplTechniques())) {
        GTEST_SKIP();
    }
    const auto crease = sc::builtin("crease");
    const nlohmann::json all = {{"rsm_size", 64}, {"vpl_grid", 64}, {"min_distance", 0.0}};
    // Without a distance clamp the 1/d^2 peak at the contact line is sampled by pixels; the screen
    // estimate of the received power may then exceed the flux (the bound is on the true integral).
    Frame unclamped = render(spec(crease, all), {.energy = 3.0});
    note("P/Phi unclamped", unclamped.energyRatio);
    Frame k3 =
        render(spec(crease, merge(all, {{"clamp_b", 40000.0}, {"ssbc_iterations", 0}})), {.energy = 3.0});
    Frame clamped = render(spec(crease, merge(all, {{"min_distance", 0.05}})));
    note("P/Phi clamp 0.1 m", clamped.energyRatio);
    if (findTechnique(technique()).info.params.find("kernel")) {
        Frame disk = render(spec(crease, merge(all, {{"kernel", "disk"}})));
        note("P/Phi disk", disk.energyRatio);
    }
    EXPECT_GT(unclamped.indirectMax, 0.0);
}

// ---- 2. Grazing and back-facing geometry -----------------------------------------------------------
TEST_P(S4, C02_GrazingBackFacing) {
    if (!appliesTo(vplTechniques())) {
        GTEST_SKIP();
    }
    // (a) Only a floor: every VPL lies in every receiver's tangent plane (cos = 0 up to rounding), so
    // the indirect light must vanish; rounding may leave ~1e-7 relative residue, never negative.
    Frame flat = render(spec(sc::floorOnly(2.0f, 1.0f), {{"min_distance", 0.0}}));
    const double directMax = maxAbs(flat.out.linear);
    EXPECT_LE(flat.indirectMax, 1e-4 * directMax) << "coplanar VPLs must give (almost exactly) 0";
    note("coplanar indirect/direct", directMax > 0 ? flat.indirectMax / directMax : 0.0);

    // (b) SSBC's grazing fade: above ssbc_grazing_angle a pixel's footprint Omega d^2 / cos is
    // replaced by Omega d^2 cos / cos_g^2, equal at the threshold. With a camera 10 degrees above the
    // crease floor (view angles around 80 degrees), moving the threshold across 79.9 / 80 / 80.1 must
    // change the compensation continuously, and the fade must bound it against no fade (90) where
    // A ~ 1/cos grows without bound.
    const auto crease = sc::builtin("crease");
    const nlohmann::json ssbc = {{"clamp_b", 40.0}, {"ssbc_iterations", 1}, {"ssbc_input", "direct"}};
    auto grazingCamera = [&](double deg) {
        const double a = glm::radians(deg);
        Camera cam = crease->cameras.front();
        cam.target = {0.2f, 0.0f, 0.0f};
        cam.position = cam.target + 2.5f * glm::vec3(float(std::sin(a)), float(std::cos(a)), 0.05f);
        return cam;
    };
    std::vector<double> added;
    for (double threshold : {79.9, 80.0, 80.1, 90.0}) {
        RenderSpec s = spec(crease, merge(ssbc, {{"ssbc_grazing_angle", threshold}}));
        s.camera = grazingCamera(80.0);
        added.push_back(render(s).counter("ssbc_energy_added", 0.0));
    }
    const double ref = std::max(added[1], 1e-12);
    EXPECT_LE(std::abs(added[0] - added[1]), 0.05 * ref + 1e-9) << "compensation jumps below 80 degrees";
    EXPECT_LE(std::abs(added[2] - added[1]), 0.05 * ref + 1e-9) << "compensation jumps above 80 degrees";
    EXPECT_LE(added[1], added[3] * (1 + 1e-6)) << "the fade must not add energy";
    RenderSpec edgeOn = spec(crease, ssbc);
    edgeOn.camera = grazingCamera(89.99);
    const double addedEdgeOn = render(edgeOn).counter("ssbc_energy_added", 0.0);
    EXPECT_TRUE(std::isfinite(addedEdgeOn));
    char buf[96];
    std::snprintf(buf, sizeof buf, "%.4g/%.4g/%.4g/%.4g", added[0], added[1], added[2], added[3]);
    note("ssbc added, fade at 79.9/80/80.1/none", buf);
    // Measured, not asserted: at 64 px the crease seen at grazing is resolved by a pixel row or two,
    // so the compensation swings with sub-degree camera motion (docs/stability.md, findings).
    std::vector<double> swing;
    for (double deg : {79.5, 80.5}) {
        RenderSpec s = spec(crease, ssbc);
        s.camera = grazingCamera(deg);
        swing.push_back(render(s).counter("ssbc_energy_added", 0.0));
    }
    std::snprintf(buf, sizeof buf, "%.3g/%.3g", swing[0], swing[1]);
    note("ssbc added, camera 79.5/80.5 deg", buf);
}

// ---- 3. Zero-energy inputs ---------------------------------------------------------------------------
TEST_P(S4, C03_ZeroEnergy) {
    if (!appliesTo(vplTechniques())) {
        GTEST_SKIP();
    }
    const auto cornell = sc::builtin("cornell");
    // Light intensity 0.
    RenderSpec dark = spec(cornell);
    Light l = cornell->lights.front();
    l.intensity = 0.0f;
    dark.light = l;
    Frame f0 = render(dark);
    EXPECT_EQ(f0.indirectMax, 0.0);
    EXPECT_EQ(maxAbs(f0.out.linear), 0.0);
    // Albedo 0 everywhere: an all-black RSM (and 003's weighted mean direction with sum w = 0).
    Frame fb = render(spec(sc::withAlbedo(cornell, 0.0f, "stability:cornell-albedo0")));
    EXPECT_EQ(fb.indirectMax, 0.0);
    EXPECT_EQ(fb.rsmFluxSum[0] + fb.rsmFluxSum[1] + fb.rsmFluxSum[2], 0.0);
    // 001's lightcut: tau >= I (T <= 0) refines nothing, tau = 0 (T = +inf) traverses everything.
    if (technique() == "hier_isr") {
        Frame t1 = render(spec(cornell, {{"tau", 1.0}}));
        Frame t0 = render(spec(cornell, {{"tau", 0.0}, {"max_depth", 64}}));
        note("cut mean tau=1", t1.counter("cut_size_mean"));
        note("cut mean tau=0", t0.counter("cut_size_mean"));
        EXPECT_GT(t0.counter("cut_size_mean"), t1.counter("cut_size_mean"));
    }
    if (technique() == "isr") {
        render(spec(cornell, {{"light_depth_threshold", 0.0}, {"light_normal_threshold", 0.0}}));
        render(spec(cornell, {{"light_depth_threshold", 1.0}, {"light_normal_threshold", 2.0}}));
    }
}

// ---- 4. Empty / background texels -----------------------------------------------------------------
TEST_P(S4, C04_EmptyTexels) {
    if (!appliesTo(vplTechniques())) {
        GTEST_SKIP();
    }
    Frame f = render(spec(sc::floorAndSky()));
    int empty = 0, emptyWithFlux = 0;
    for (size_t i = 0; i + 3 < f.rsmFlux.rgba.size(); i += 4)
        if (f.rsmPosition.rgba[i + 3] <= 0.5f) {
            ++empty;
            if (f.rsmFlux.rgba[i] != 0 || f.rsmFlux.rgba[i + 1] != 0 || f.rsmFlux.rgba[i + 2] != 0)
                ++emptyWithFlux;
        }
    EXPECT_GT(empty, 0) << "the spot must partly miss the geometry";
    EXPECT_EQ(emptyWithFlux, 0) << "empty RSM texels carry flux";
    note("empty RSM texels %", 100.0 * empty / double(f.rsmFlux.rgba.size() / 4));
    if (technique() == "second_order") {
        EXPECT_LT(f.counter("positive_valid"), f.counter("positive_count"))
            << "Halton points on empty texels";
        note("valid/placed lights", std::to_string(int(f.counter("positive_valid"))) + "/" +
                                        std::to_string(int(f.counter("positive_count"))));
    }
    if (technique() == "isr") note("VPLs", f.counter("vpl_count"));
    EXPECT_GT(f.indirectMax, 0.0);
}

// ---- 5. Degenerate triangles and NaN injection ---------------------------------------------------
// The NaN-carrying meshes are uploaded as built (no finalizeScene, no validateScene); the deep check
// reads every float texture of the context, mip chains included. SanitizeTest injects NaN texels
// straight into the G-buffer and RSM; RobustnessTest checks that the loader rejects NaN positions.
TEST_P(S4, C05_DegenerateAndNan) {
    RenderSpec a = spec(sc::degenerate(false));
    a.deep = true;
    Frame fa = render(a);
    RenderSpec b = spec(sc::degenerate(true));
    b.deep = true;
    Frame fb = render(b);
    note("float textures read", double(fa.deepTextures + fb.deepTextures));
}

// ---- 6. Camera inside geometry, on a surface, clipped by the near plane --------------------------
TEST_P(S4, C06_CameraInsideGeometry) {
    const auto cornell = sc::builtin("cornell");
    const Camera base = cornell->cameras.front();
    std::vector<std::pair<std::string, Camera>> cams;
    Camera c = base; // inside the tall box (closed), facing its back faces
    c.position = {-0.35f, 0.6f, -0.35f};
    c.target = {-0.35f, 0.6f, -1.0f};
    cams.emplace_back("inside box", c);
    c = base; // 1e-5 m from the back wall, looking at it
    c.position = {0.0f, 1.0f, -1.0f + 1e-5f};
    c.target = {0.0f, 1.0f, -2.0f};
    c.znear = 1e-6f;
    cams.emplace_back("1e-5 from wall", c);
    c.znear = 1e-5f; // the wall on the near plane
    cams.emplace_back("wall on near plane", c);
    c = base; // 1e-5 m from the back wall, looking into the room
    c.position = {0.0f, 1.0f, -1.0f + 1e-5f};
    c.target = {0.0f, 1.0f, 1.0f};
    c.znear = 1e-6f;
    cams.emplace_back("back to wall", c);
    double maxMs = 0;
    for (const auto& [name, cam] : cams) {
        SCOPED_TRACE(name);
        RenderSpec s = spec(cornell, {{"ssbc_iterations", technique() == "ssbc" ? 1 : 0}});
        s.camera = cam;
        Frame f = render(s);
        maxMs = std::max(maxMs, f.wallMs);
        if (usesEyeHierarchy(technique())) {
            EXPECT_LE(f.counter("receivers_total", 0), 4.0 / 3.0 * s.width * s.height + 64);
        }
    }
    note("max frame ms", maxMs);
}

// ---- 7. Analytic sphere -----------------------------------------------------------------------------
// Between two points of a sphere G = 1/(4R^2), so the one-bounce irradiance is uniform:
// E1 = Phi_R / (4 pi R^2) with Phi_R the reflected flux (the RSM's sum), L1 = rho / pi * E1.
TEST_P(S4, C07_AnalyticSphere) {
    if (!appliesTo(vplTechniques())) {
        GTEST_SKIP();
    }
    const float radius = 1.0f, rho = 0.5f, outer = 60.0f, inner = 45.0f;
    const auto sphere = sc::sphere(radius, rho, outer, inner);
    const double pi = glm::pi<double>();
    // Flux check: Phi_R = rho I Omega_eff, Omega_eff = 2 pi int spot(theta) sin(theta) dtheta.
    double omega = 0;
    const int steps = 200000;
    const double cosO = std::cos(glm::radians(double(outer))), cosI = std::cos(glm::radians(double(inner)));
    for (int i = 0; i < steps; ++i) {
        const double th = (i + 0.5) / steps * glm::radians(double(outer));
        const double t = std::clamp((std::cos(th) - cosO) / (cosI - cosO), 0.0, 1.0);
        omega += 2 * pi * t * t * std::sin(th) * glm::radians(double(outer)) / steps;
    }
    const double phiAnalytic = rho * 1.0 * omega;

    // No distance clamp (G is bounded by 1/(4R^2) here), no compensation, no negative lights.
    const nlohmann::json base = {{"rsm_size", 128},  {"min_distance", 0.0}, {"ssbc_iterations", 0},
                                 {"clamp_b", 0.0},   {"negative_count", 0}, {"tau", 0.0},
                                 {"max_depth", 128}, {"isr_finest", 128},   {"positive_count", 1024}};
    nlohmann::json params = base;
    if (technique() == "rsm_gather" || technique() == "ssbc") params["vpl_grid"] = 128; // R0: all texels
    if (technique() == "multires_splat" || technique() == "multires_gather") params["vpl_grid"] = 32;
    Frame f = render(spec(sphere, params, 48, 48));
    const double phi = f.rsmFluxSum[0];
    EXPECT_NEAR(phi / phiAnalytic, 1.0, 2e-3) << "RSM flux vs rho I Omega";
    note("Phi_RSM/analytic", phi / phiAnalytic);
    // The receivers' albedo as the gather reads it: the RGBA8 G-buffer (0.5 is stored as 128/255).
    const double rhoG = std::round(rho * 255.0) / 255.0;
    const double expected = rhoG / pi * phi / (4 * pi * radius * radius);
    // Uniformity and level over every covered pixel (lit and unlit parts of the sphere alike).
    double sum = 0, sum2 = 0, lo = 1e30, hi = 0;
    int n = 0;
    for (int y = 0; y < f.spec.height; ++y)
        for (int x = 0; x < f.spec.width; ++x) {
            if (!f.coveredAt(x, y)) continue;
            const double v = f.indirectAt(x, y, 0);
            sum += v;
            sum2 += v * v;
            lo = std::min(lo, v);
            hi = std::max(hi, v);
            ++n;
        }
    ASSERT_GT(n, 0);
    const double mean = sum / n, cv = std::sqrt(std::max(sum2 / n - mean * mean, 0.0)) / mean;
    note("mean/analytic", mean / expected);
    note("coeff. of variation", cv);
    // R0 (every RSM texel a VPL, exact solid angles) matches to the tessellation's error; the
    // clustered and eye-space techniques to the documented patch/disk-kernel error.
    const bool exact = technique() == "rsm_gather" || technique() == "ssbc";
    EXPECT_NEAR(mean / expected, 1.0, exact ? 2e-3 : 1e-2);
    EXPECT_LT(cv, exact ? 2e-3 : 1e-2);

    // K3 with b < 1/(4R^2) clamps every pair: the indirect becomes exactly rho/pi * b/pi * Phi_R,
    // whatever the VPL set, as long as it carries the whole flux (grid, Halton, ISR, HISR).
    // clamp_b is relative to the scene's size (its bounds' longest side, 2R here): b = clamp_b / size^2.
    const double b = 0.1, size = sphere->bounds.longestSide();
    Frame fc = render(spec(sphere, merge(params, {{"clamp_b", b * size * size}}), 48, 48));
    double csum = 0;
    int cn = 0;
    for (int y = 0; y < fc.spec.height; ++y)
        for (int x = 0; x < fc.spec.width; ++x)
            if (fc.coveredAt(x, y)) {
                csum += fc.indirectAt(x, y, 0);
                ++cn;
            }
    const double clampedExpected = rhoG / pi * b / pi * fc.rsmFluxSum[0];
    note("clamped mean/(rho b Phi/pi^2)", csum / cn / clampedExpected);
    EXPECT_NEAR(csum / cn / clampedExpected, 1.0, 1e-3) << "VPL set does not conserve the RSM flux";

    if (technique() == "rsm_gather") {
        // 000 Fig. 13: the equal-solid-angle split mis-weights texels radially (dimmer on-axis,
        // brighter off-axis than the exact cos^3 law).
        Frame eq = renderRaw(spec(sphere, merge(params, {{"rsm_solid_angle", "equal"}}), 48, 48));
        const int r = 128, mid = r / 2;
        auto texel = [&](const Frame& g, int x, int y) { return g.rsmFlux.at(x, y, 0); };
        const double centre = texel(eq, mid, mid) / texel(f, mid, mid);
        const double edge = texel(eq, mid, 6) / texel(f, mid, 6);
        note("equal/exact centre, edge texel",
             std::to_string(centre).substr(0, 6) + ", " + std::to_string(edge).substr(0, 6));
        EXPECT_LT(centre, edge);
    }
}

// ---- 8. On-axis disk ----------------------------------------------------------------------------------
// The exact K2 identity is checked in KernelProbeTest; here the whole pipeline: the receiver above
// the disk centre gets E = int_0^R B(r) h^2 / (pi (h^2 + r^2)^2) 2 pi r dr with the disk's exitance
// B(r) = rho I H / (H^2 + r^2)^1.5 under the spot at height H.
TEST_P(S4, C08_OnAxisDisk) {
    if (!appliesTo(vplTechniques())) {
        GTEST_SKIP();
    }
    const float radius = 0.5f, lightH = 0.3f, recvH = 0.6f, rho = 0.8f;
    const auto d = sc::disk(radius, lightH, recvH, rho);
    const double pi = glm::pi<double>();
    double e = 0;
    const int steps = 100000;
    for (int i = 0; i < steps; ++i) {
        const double r = (i + 0.5) / steps * radius;
        const double b = rho * 1.0 * lightH / std::pow(lightH * lightH + r * r, 1.5);
        e += b * recvH * recvH / (pi * std::pow(recvH * recvH + r * r, 2.0)) * 2 * pi * r * radius / steps;
    }
    const double expected = 0.8 / pi * e; // receiver albedo 0.8
    const nlohmann::json params = {
        {"rsm_size", 128},      {"vpl_grid", 64},    {"min_distance", 0.0},    {"tau", 0.0},
        {"max_depth", 128},     {"isr_finest", 128}, {"positive_count", 1024}, {"negative_count", 0},
        {"ssbc_iterations", 0}, {"clamp_b", 0.0}};
    Frame f = render(spec(d, params));
    const glm::ivec2 p = project(d->cameras.front(), {0, recvH, 0}, 64, 64);
    const double measured = indirectWindow(f, p.x, p.y, 1);
    note("L(centre)/analytic", measured / expected);
    EXPECT_NEAR(measured / expected, 1.0, 0.15);
}

// ---- 9. Crease bias and SSBC convergence --------------------------------------------------------
TEST_P(S4, C09_CreaseCompensation) {
    if (!appliesTo(vplTechniques())) {
        GTEST_SKIP();
    }
    const auto crease = sc::builtin("crease");
    const nlohmann::json vpls = {{"rsm_size", 64}, {"vpl_grid", 32}, {"negative_count", 0}};
    // Reference: the unclamped one-bounce gather over every RSM texel.
    Frame ref =
        renderRaw(specFor("rsm_gather", crease, {{"rsm_size", 64}, {"vpl_grid", 64}, {"min_distance", 0.0}}));
    const double eRef = indirectSum(ref);
    std::vector<double> e;
    for (int n = 0; n <= 3; ++n) {
        Frame f = render(
            spec(crease, merge(vpls, {{"clamp_b", 40.0}, {"ssbc_iterations", n}, {"ssbc_input", "direct"}})));
        e.push_back(indirectSum(f));
    }
    EXPECT_LT(e[0], eRef) << "the clamp must darken (near the crease)";
    for (int n = 1; n <= 3; ++n) EXPECT_GE(e[n], e[n - 1] * (1 - 1e-6)) << "N=" << n << " lost energy";
    EXPECT_LE(e[3] - e[2], (e[2] - e[1]) * 1.05 + 1e-9 * eRef) << "increments must shrink";
    EXPECT_LE(e[2] - e[1], (e[1] - e[0]) * 1.05 + 1e-9 * eRef) << "increments must shrink";
    EXPECT_LE(e[3], eRef * 1.15) << "overshoots the unclamped reference";
    note("E/E_ref N=0..3",
         std::to_string(e[0] / eRef).substr(0, 5) + "/" + std::to_string(e[1] / eRef).substr(0, 5) + "/" +
             std::to_string(e[2] / eRef).substr(0, 5) + "/" + std::to_string(e[3] / eRef).substr(0, 5));
    // b -> infinity: nothing is clamped, nothing to compensate.
    Frame big0 = renderRaw(spec(crease, merge(vpls, {{"clamp_b", 40000.0}, {"ssbc_iterations", 0}})));
    Frame big1 = render(
        spec(crease, merge(vpls, {{"clamp_b", 40000.0}, {"ssbc_iterations", 1}, {"ssbc_input", "direct"}})));
    const double extra = (indirectSum(big1) - indirectSum(big0)) / std::max(indirectSum(big0), 1e-30);
    note("compensation at b=1e4", extra);
    EXPECT_LT(std::abs(extra), 0.02);
}

// ---- 10. Discontinuity on a mip-cell boundary and on a diagonal -----------------------------------
TEST_P(S4, C10_MipBoundaryEdges) {
    const auto edges = sc::depthEdges();
    if (!usesEyeHierarchy(technique())) {
        render(spec(edges)); // shared assertions only
        return;
    }
    for (bool diagonal : {true, false}) {
        SCOPED_TRACE(diagonal ? "diagonal rule on" : "adjacent cells");
        const nlohmann::json p = {{"diagonal_refine", diagonal}, {"vpl_grid", 16}};
        Frame f = render(spec(edges, p));
        Frame full = render(spec(edges, merge(p, kZeroEyeThresholds)));
        // No covered pixel is left without a receiver: wherever the fully refined frame has light,
        // the hierarchical one has some too.
        int holes = 0, lit = 0;
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                if (!f.coveredAt(x, y)) continue;
                const double a =
                    full.indirectAt(x, y, 0) + full.indirectAt(x, y, 1) + full.indirectAt(x, y, 2);
                const double b = f.indirectAt(x, y, 0) + f.indirectAt(x, y, 1) + f.indirectAt(x, y, 2);
                lit += a > 0;
                holes += a > 0 && b <= 0;
            }
        EXPECT_GT(lit, 0);
        EXPECT_EQ(holes, 0) << "covered pixels without a receiver";
        // No leak across the edge at x = 32: the columns beside it match the full refinement.
        double num = 0, den = 0;
        for (int y = 0; y < 64; ++y)
            for (int x : {31, 32})
                for (int c = 0; c < 3; ++c) {
                    const double dv = f.indirectAt(x, y, c) - full.indirectAt(x, y, c);
                    num += dv * dv;
                    den += double(full.indirectAt(x, y, c)) * full.indirectAt(x, y, c);
                }
        const double edgeErr = den > 0 ? std::sqrt(num / den) : 0.0;
        const double allErr = relativeRmse(indirectImage(full), indirectImage(f));
        note(diagonal ? "rel. RMSE edge/all (diagonal)" : "rel. RMSE edge/all (adjacent)",
             std::to_string(edgeErr).substr(0, 6) + "/" + std::to_string(allErr).substr(0, 6));
        EXPECT_LT(allErr, 0.2);
        // No patch straddles the edge, so both sides stay coarse receivers: eyeInterpolateCoarse's
        // geometric weights keep the upsampling from mixing them.
        EXPECT_LE(edgeErr, 2 * allErr + 0.02) << "light leaks across the depth edge on the cell boundary";
        EXPECT_LE(f.counter("receivers_total", 0), 4.0 / 3.0 * 64 * 64);
    }
}

// ---- 11. Coverage vs black in upsampling ----------------------------------------------------------
TEST_P(S4, C11_CoverageVsBlack) {
    const auto scene = sc::blackRegion();
    Frame f = render(spec(scene, {{"vpl_grid", 16}}));
    // Black covered pixels: albedo 0, so their radiance (indirect included) is exactly 0.
    int black = 0, blackLit = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            if (!f.coveredAt(x, y)) continue;
            const int gy = f.gAlbedo.height - 1 - y;
            if (f.gAlbedo.at(x, gy, 0) != 0 || f.gAlbedo.at(x, gy, 1) != 0 || f.gAlbedo.at(x, gy, 2) != 0)
                continue;
            ++black;
            for (int c = 0; c < 3; ++c)
                if (f.finalAt(x, y, c) != 0.0f) {
                    ++blackLit;
                    break;
                }
        }
    EXPECT_GT(black, 0);
    EXPECT_EQ(blackLit, 0) << "albedo-0 pixels with radiance";
    if (usesEyeHierarchy(technique())) {
        // Total energy after the coverage-aware upsampling vs the fully refined frame.
        Frame full = render(spec(scene, merge({{"vpl_grid", 16}}, kZeroEyeThresholds)));
        const double ratio = indirectSum(f) / std::max(indirectSum(full), 1e-30);
        note("energy vs full refinement", ratio);
        EXPECT_NEAR(ratio, 1.0, 0.1);
    }
}

// ---- 12. Threshold extremes reproduce the references --------------------------------------------
TEST_P(S4, C12_ThresholdExtremes) {
    const auto cornell = sc::builtin("cornell");
    const std::string t = technique();
    if (t == "multires_gather" || t == "multires_splat") {
        for (const char* kernel : {"point", "disk"}) {
            const nlohmann::json vpl = {{"vpl_grid", 8}, {"kernel", kernel}};
            Frame zero = render(spec(cornell, merge(vpl, kZeroEyeThresholds)));
            Frame full = renderRaw(specFor("rsm_gather", cornell, vpl));
            const double err = relativeRmse(full.out.linear, zero.out.linear);
            note(std::string("thresholds 0 vs full-res (") + kernel + ")", err);
            EXPECT_LT(err, 1e-3);
        }
        Frame maxed = render(spec(cornell, {{"depth_threshold", 1.0}, {"normal_threshold", 2.0}}));
        note("receivers at max thresholds", maxed.counter("receivers_total"));
        EXPECT_LT(maxed.counter("receivers_total"), 0.25 * maxed.coveredPixels);
    } else if (t == "hier_isr") {
        // tau = 0 and full depth: the per-texel gather (R0 with the disk kernel).
        const int rsm = 32;
        Frame hier = render(
            spec(cornell, merge(kZeroEyeThresholds, {{"rsm_size", rsm}, {"tau", 0.0}, {"max_depth", rsm}})));
        Frame flat = renderRaw(
            specFor("rsm_gather", cornell, {{"rsm_size", rsm}, {"vpl_grid", rsm}, {"kernel", "disk"}}));
        const double err = relativeRmse(indirectImage(flat), indirectImage(hier));
        note("tau=0 vs per-texel gather", err);
        EXPECT_LT(err, 1e-3);
    } else if (t == "isr") {
        Frame zero = render(spec(cornell, merge(kZeroEyeThresholds, {{"light_depth_threshold", 0.0},
                                                                     {"light_normal_threshold", 0.0}})));
        Frame maxed = render(spec(cornell, {{"light_depth_threshold", 1.0},
                                            {"light_normal_threshold", 2.0},
                                            {"depth_threshold", 1.0},
                                            {"normal_threshold", 2.0}}));
        note("VPLs at thresholds 0 / max", std::to_string(int(zero.counter("vpl_count"))) + " / " +
                                               std::to_string(int(maxed.counter("vpl_count"))));
        EXPECT_GE(zero.counter("vpl_count"), maxed.counter("vpl_count"));
    } else if (t == "second_order") {
        // Threshold 0: every pixel at full resolution, the unoptimised render (RMS 0%).
        Frame zero = render(spec(cornell, {{"discontinuity_threshold", 0.0}}));
        Frame full = render(spec(cornell, {{"discontinuity_threshold", 0.0}, {"lowres_factor", 1}}));
        const double err = relativeRmse(full.out.linear, zero.out.linear);
        note("threshold 0 vs lowres_factor 1", err);
        EXPECT_LT(err, 1e-5);
        render(spec(cornell, {{"discontinuity_threshold", 2.0}}));
    } else if (t == "ssbc" || t == "rsm_gather") {
        // SSBC thresholds -> 0: the hierarchical sum equals the flat screen-space sum.
        const nlohmann::json comp = {{"clamp_b", 40.0},
                                     {"ssbc_iterations", 1},
                                     {"ssbc_solid_angle", 0.0},
                                     {"ssbc_discontinuity_angle", 0.0}};
        Frame hier = render(spec(cornell, merge(comp, {{"ssbc_levels", 7}})));
        Frame flat = render(spec(cornell, merge(comp, {{"ssbc_levels", 1}})));
        // Compared on the compensation alone (the images minus the uncompensated one).
        Frame off = renderRaw(spec(cornell, merge(comp, {{"ssbc_iterations", 0}})));
        std::vector<float> ch = indirectImage(hier), cf = indirectImage(flat);
        const std::vector<float> co = indirectImage(off);
        for (size_t i = 0; i < ch.size(); ++i) {
            ch[i] -= co[i];
            cf[i] -= co[i];
        }
        const double err = relativeRmse(cf, ch);
        note("ssbc thresholds 0: hierarchical vs flat compensation", err);
        note("compensation sum hierarchical/flat", sumRgb(ch) / sumRgb(cf));
        EXPECT_LT(err, 1e-3) << "hierarchical != flat at thresholds 0";
    } else {
        GTEST_SKIP();
    }
}

// ---- 13. Scatter/gather and per-VPL/per-frame consistency -----------------------------------------
TEST_P(S4, C13_ScatterGather) {
    if (!appliesTo({"multires_splat", "multires_gather"})) {
        GTEST_SKIP();
    }
    const auto cornell = sc::builtin("cornell");
    const nlohmann::json p = {{"vpl_grid", 8}, {"kernel", "point"}, {"depth_threshold", 0.2}};
    Frame splat = render(specFor("multires_splat", cornell, p));
    Frame gather = render(specFor("multires_gather", cornell, p));
    const double err = relativeRmse(gather.out.linear, splat.out.linear);
    note("splat vs gather", err);
    EXPECT_LT(err, 1e-5);
    if (technique() == "multires_splat") {
        // Per-VPL illumination-driven refinement with T -> 0 vs per-frame refinement at full resolution.
        Frame perVpl = render(spec(
            cornell, merge(kZeroEyeThresholds,
                           {{"vpl_grid", 8}, {"refinement", "illumination"}, {"illum_threshold", 1e-7}})));
        Frame perFrame = render(spec(cornell, merge(kZeroEyeThresholds, {{"vpl_grid", 8}})));
        const double e2 = relativeRmse(perFrame.out.linear, perVpl.out.linear);
        note("per-VPL (T=1e-7) vs per-frame", e2);
        note("indirect sum per-VPL/per-frame", indirectSum(perVpl) / indirectSum(perFrame));
        EXPECT_LT(e2, 1e-3) << "per-VPL refinement at T=1e-7 differs from per-frame full refinement";
    }
}

// ---- 14. Scale, linearity and units --------------------------------------------------------------
TEST_P(S4, C14_ScaleAndLinearity) {
    const auto cornell = sc::builtin("cornell");
    const std::string t = technique();
    const bool hasKernel = findTechnique(t).info.params.find("kernel") != nullptr;
    // Every distance-like knob is relative to the scene's size (min_distance a fraction of it, clamp_b
    // in 1/size^2), so the same values give the same image at every scale: the point kernel with its
    // clamp, K3's clamp (ssbc's default, or set here for the rest), and the scale-free disk kernel.
    std::vector<nlohmann::json> variants = {{{"vpl_grid", 8}}};
    if (hasKernel) {
        variants = {{{"vpl_grid", 8}, {"kernel", "point"}, {"min_distance", 0.05}},
                    {{"vpl_grid", 8}, {"kernel", "disk"}}};
    }
    if (findTechnique(t).info.params.find("clamp_b") != nullptr && t != "ssbc") {
        variants.push_back({{"vpl_grid", 8}, {"clamp_b", 40.0}});
    }
    // The same through instance matrices: the placements scale, the own-space geometry does not.
    const auto placed = sc::instanced(cornell, "stability:cornell-instanced");
    for (float s : {1e-3f, 1e4f}) {
        SCOPED_TRACE(s);
        const nlohmann::json p = variants.front();
        const Frame ref = render(spec(placed, p));
        const Frame f =
            render(spec(sc::transformed(placed, s, glm::vec3(0.0f), "stability:cornell-instanced-x"), p));
        EXPECT_EQ(f.counter("instances"), static_cast<double>(cornell->meshes.size()));
        const double err = relativeRmse(ref.out.linear, f.out.linear);
        note((s < 1 ? "rel. RMSE instanced, scale 1e-3 " : "rel. RMSE instanced, scale 1e4 ") + p.dump(),
             err);
        EXPECT_LT(err, 2e-2);
    }
    for (const nlohmann::json& p : variants) {
        SCOPED_TRACE(p.dump());
        Frame ref = render(spec(cornell, p));
        for (float s : {1e-3f, 1e4f}) {
            SCOPED_TRACE(s);
            const auto scaled =
                sc::transformed(cornell, s, glm::vec3(0.0f), "stability:cornell-x" + std::to_string(s));
            Frame f = render(spec(scaled, p));
            const double err = relativeRmse(ref.out.linear, f.out.linear);
            note((s < 1 ? "rel. RMSE scale 1e-3 " : "rel. RMSE scale 1e4 ") + p.dump(), err);
            EXPECT_LT(err, 2e-2);
        }
    }
    const nlohmann::json p = {{"vpl_grid", 8}};
    Frame ref = render(spec(cornell, p));
    // Light intensity x4 scales the indirect (and the direct) light by exactly 4.
    RenderSpec k = spec(cornell, p);
    Light l = cornell->lights.front();
    l.intensity *= 4.0f;
    k.light = l;
    Frame f4 = render(k);
    if (t != "none") {
        const double ratio = indirectSum(f4) / indirectSum(ref);
        note("indirect ratio at I x4", ratio);
        EXPECT_NEAR(ratio, 4.0, 4e-4);
    }
}

// ---- 15. Determinism (the 100-frame and motion parts are in TemporalTest) -------------------------
TEST_P(S4, C15_Determinism) {
    const auto cornell = sc::builtin("cornell");
    Frame a = render(spec(cornell));
    Frame b = render(spec(cornell));
    EXPECT_TRUE(a.out.linear == b.out.linear) << "two renders of the same frame differ";
    EXPECT_TRUE(a.out.rgba8 == b.out.rgba8);
}

// ---- 16. Halton and cone sampling --------------------------------------------------------------------
TEST_P(S4, C16_HaltonAndCone) {
    if (!appliesTo({"second_order"})) {
        GTEST_SKIP();
    }
    EXPECT_DOUBLE_EQ(halton::radicalInverse(1, 2), 0.5);
    EXPECT_DOUBLE_EQ(halton::radicalInverse(2, 2), 0.25);
    EXPECT_NEAR(halton::radicalInverse(1, 3), 1.0 / 3, 1e-15);
    EXPECT_NEAR(halton::radicalInverse(2, 3), 2.0 / 3, 1e-15);
    EXPECT_NEAR(halton::radicalInverse(3, 3), 1.0 / 9, 1e-15);
    const auto cornell = sc::builtin("cornell");
    // A 0.5 degree cone: the sampler hits its cap and returns fewer lights; the frame stays valid.
    RenderSpec narrow = spec(cornell);
    Light l = cornell->lights.front();
    l.innerConeAngle = glm::radians(0.25f);
    l.outerConeAngle = glm::radians(0.5f);
    narrow.light = l;
    Frame f = render(narrow);
    EXPECT_EQ(f.counter("cone_capped"), 1.0);
    EXPECT_LT(f.counter("positive_count"), 256.0);
    note("lights in a 0.5 deg cone", f.counter("positive_count"));
    // The widest spot the scene model allows (90 degrees); 180 degrees and more accept every draw.
    l.innerConeAngle = glm::radians(80.0f);
    l.outerConeAngle = glm::radians(90.0f);
    narrow.light = l;
    Frame w = render(narrow);
    EXPECT_EQ(w.counter("cone_capped"), 0.0);
    EXPECT_EQ(halton::sampleCone(-1.0, 100).draws, 100u);
}

// ---- 17. Precision far from the origin -------------------------------------------------------------
TEST_P(S4, C17_FarFromOrigin) {
    const std::string t = technique();
    const auto cornell = sc::builtin("cornell");
    const auto far = sc::transformed(cornell, 1.0f, glm::vec3(1e4f, 0.0f, 1e4f), "stability:cornell+1e4");
    Frame ref = render(spec(cornell));
    Frame f = render(spec(far));
    const auto t_hasIndirect = [](const Frame& g) { return !g.indirect.empty(); };
    const double err = relativeRmse(ref.out.linear, f.out.linear);
    note("rel. RMSE at +1e4 m", err);
    // Sub-pixel silhouette shifts (positions carry a 1 mm ulp at 1e4 m) move a few edge pixels by a
    // lot, which dominates an RMSE; the assertion is on the level and on the share of pixels moved.
    int moved = 0, covered = 0;
    for (size_t i = 0; i < ref.out.linear.size(); i += 4) {
        const double a = (ref.out.linear[i] + ref.out.linear[i + 1] + ref.out.linear[i + 2]) / 3;
        const double b = (f.out.linear[i] + f.out.linear[i + 1] + f.out.linear[i + 2]) / 3;
        covered += a > 0 || b > 0;
        moved += std::abs(a - b) > 0.1 * std::max(a, 1e-3);
    }
    const double level = sumRgb(f.out.linear) / sumRgb(ref.out.linear);
    note("total radiance ratio", level);
    note("pixels changed > 10% (%)", 100.0 * moved / std::max(covered, 1));
    EXPECT_NEAR(level, 1.0, 0.02);
    EXPECT_LE(moved, 0.03 * covered);
    if (t_hasIndirect(f)) {
        const double ind = indirectSum(f) / indirectSum(ref);
        note("indirect ratio", ind);
        EXPECT_NEAR(ind, 1.0, 0.02);
    }
}

// ---- 18. Non-power-of-two and odd resolutions ------------------------------------------------------
TEST_P(S4, C18_OddResolutions) {
    const auto cornell = sc::builtin("cornell");
    const std::pair<int, int> sizes[] = {{64, 48}, {61, 47}, {33, 17}, {1, 1}, {2, 3}, {127, 95}};
    for (auto [w, h] : sizes) {
        SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
        RenderSpec s = spec(cornell, {{"ssbc_iterations", technique() == "ssbc" ? 1 : 0}}, w, h);
        s.deep = w == 61; // every mip level of every chain at one odd size
        // Below 4x4 pixels one pixel's footprint stands for a whole wall: the screen estimate of the
        // received power is too coarse for the 5% bound, so those frames get a loose one.
        render(s, {.energy = w * h < 16 ? 2.0 : kOneBounceEnergyBound});
        if (usesEyeHierarchy(technique())) {
            // The flattened atlas: levels cover ceil(W / 2^l) x ceil(H / 2^l) and never overlap.
            int aw = 0, ah = 0;
            const auto levels = eyeLevelLayout(w, h, 16, &aw, &ah);
            for (size_t i = 0; i < levels.size(); ++i) {
                EXPECT_EQ(levels[i].width, (w + (1 << i) - 1) >> i);
                EXPECT_EQ(levels[i].height, (h + (1 << i) - 1) >> i);
                EXPECT_LE(levels[i].x + levels[i].width, aw);
                EXPECT_LE(levels[i].y + levels[i].height, ah);
                for (size_t j = 0; j < i; ++j) {
                    const bool apart = levels[i].x >= levels[j].x + levels[j].width ||
                                       levels[j].x >= levels[i].x + levels[i].width ||
                                       levels[i].y >= levels[j].y + levels[j].height ||
                                       levels[j].y >= levels[i].y + levels[i].height;
                    EXPECT_TRUE(apart) << "levels " << j << " and " << i << " overlap";
                }
            }
        }
    }
}

// ---- 19. Negative lights --------------------------------------------------------------------------
TEST_P(S4, C19_NegativeLights) {
    if (!appliesTo({"second_order"})) {
        GTEST_SKIP();
    }
    // (a) The empty box: nothing blocks, negative lights change (almost) nothing.
    const auto empty = sc::builtin("cornell-empty");
    Frame with = render(spec(empty));
    Frame without = render(spec(empty, {{"negative_count", 0}}));
    const double e = relativeRmse(without.out.linear, with.out.linear);
    note("empty box: with vs without negative", e);
    EXPECT_LT(e, 0.02);
    // (b) A thin occluder 5 cm from the back wall: negative may exceed positive; the clamp keeps the
    // composite >= 0 (shared assertions) and says where it acted.
    Frame occ = render(spec(sc::cornellOccluder(false)));
    note("clamped fraction", occ.counter("negative_clamped_fraction"));
    // (c) An occluder out of view: 003's negative lights only sit on camera-visible surfaces, so its
    // indirect shadow is missing (view dependence, documented). All negative lights project into view.
    RenderSpec off = spec(sc::cornellOccluder(true));
    Camera cam = off.scene->cameras.front();
    cam.position = {-0.3f, 1.0f, 2.0f};
    cam.target = {-0.9f, 0.8f, -0.5f};
    off.camera = cam;
    Frame fo = render(off);
    auto* so = dynamic_cast<SecondOrder*>(rendererFor("second_order").technique());
    ASSERT_NE(so, nullptr);
    int positive = 0, outside = 0;
    const auto lights = so->readVpls(&positive);
    const glm::mat4 vp = cameraViewProj(cam, 64, 64);
    for (size_t i = size_t(positive); i < lights.size(); ++i) {
        if (lights[i].position.w <= 0) continue;
        const glm::vec4 clip = vp * glm::vec4(glm::vec3(lights[i].position), 1.0f);
        const glm::vec3 ndc = glm::vec3(clip) / clip.w;
        outside += clip.w <= 0 || std::abs(ndc.x) > 1.01f || std::abs(ndc.y) > 1.01f;
    }
    note("negative lights (off-screen occluder)", double(lights.size() - size_t(positive)));
    EXPECT_EQ(outside, 0) << "negative lights outside the view";
    (void)fo;
}

// ---- 20. Worst-case refinement and capacity --------------------------------------------------------
TEST_P(S4, C20_WorstCaseRefinement) {
    const auto bumpy = sc::highFrequencyNormals(64);
    const std::string t = technique();
    nlohmann::json p = {{"rsm_size", 128},
                        {"vpl_grid", 128},
                        {"isr_finest", 128},
                        {"light_normal_threshold", 0.0},
                        {"tau", 0.0},
                        {"max_depth", 128},
                        {"positive_count", 1024},
                        {"negative_count", 1024},
                        {"discontinuity_threshold", 0.0}};
    if (t == "multires_splat") p.update({{"refinement", "illumination"}, {"illum_threshold", 1e-7}});
    // multires_splat seeds 256 coarsest texels x 16384 VPLs = 4M items, 65536 work groups of 64: a
    // 2D dispatch (65535 is GL's guaranteed limit per dimension; one dimension failed with
    // GL_INVALID_VALUE and no light before).
    // The splat frame draws 4M points: bounded (no runaway), but by a minute rather than 20 s (three
    // in the sanitizer build, where it took 54-65 s: FrameBounds::maxFrameMs).
    Frame f = render(spec(bumpy, p), {.maxFrameMs = t == "multires_splat" ? 60000.0 : kMaxFrameMs});
    note("frame ms", f.wallMs);
    if (usesEyeHierarchy(t)) {
        const double cap = 4.0 / 3.0 * 64 * 64;
        if (t != "multires_splat") {
            EXPECT_LE(f.counter("receivers_total", 0), cap);
        }
        note("receivers", f.counter("receivers_total", 0));
    }
    if (t == "multires_splat") {
        note("subsplats", f.counter("subsplats_total"));
        EXPECT_GT(f.indirectMax, 0.0);
        // The seed alone fills the default 4M-item list, so refinement is cut short: reported.
        EXPECT_GT(f.counter("subsplat_capped"), 0.0) << "truncation at 128^2 VPLs must be reported";
        EXPECT_LE(f.counter("subsplats_total"), 4.0 * (1 << 20));
        note("items capped at 128^2 VPLs", f.counter("subsplat_capped"));
        // A list buffer too small for the frame: capped with a flag, never a silent overrun.
        nlohmann::json small = merge(p, {{"rsm_size", 64}, {"vpl_grid", 64}, {"max_subsplats", 1024}});
        Frame capped = render(spec(bumpy, small), {.energy = -1});
        EXPECT_GT(capped.counter("subsplat_capped"), 0.0) << "truncation must be reported";
        note("items capped at max_subsplats 1024", capped.counter("subsplat_capped"));
        EXPECT_LE(capped.counter("subsplats_total"), 1024.0);
    }
}

// ---- 21. Degenerate VPL counts --------------------------------------------------------------------
TEST_P(S4, C21_DegenerateVplCounts) {
    const auto cornell = sc::builtin("cornell");
    // Screen with no geometry: every pixel is background.
    RenderSpec away = spec(cornell);
    Camera cam = cornell->cameras.front();
    cam.target = cam.position + glm::vec3(0, 0, 1);
    away.camera = cam;
    Frame fa = render(away);
    EXPECT_EQ(maxAbs(fa.out.linear), 0.0);
    EXPECT_EQ(fa.coveredPixels + (fa.gPosition.empty() ? 1 : 0), 0);
    // All VPLs rejected: the spot points at the sky, the RSM is empty.
    RenderSpec sky = spec(sc::floorOnly(2.0f, 1.0f));
    Light l = sky.scene->lights.front();
    l.direction = {0, 1, 0};
    sky.light = l;
    Frame fs = render(sky);
    EXPECT_EQ(fs.indirectMax, 0.0);
    RenderSpec skyNone = sky;
    skyNone.technique = "none";
    Frame fn = renderRaw(skyNone);
    EXPECT_TRUE(fs.out.linear == fn.out.linear) << "output must be the direct light only";
    // N = 0 lights (second_order's positive_count; grids have at least one VPL).
    if (technique() == "second_order") {
        Frame z = render(spec(cornell, {{"positive_count", 0}, {"negative_count", 0}}));
        Frame none = renderRaw(specFor("none", cornell));
        EXPECT_EQ(z.indirectMax, 0.0);
        EXPECT_TRUE(z.out.linear == none.out.linear) << "output must be the direct light only";
    }
}

INSTANTIATE_TEST_SUITE_P(Techniques, S4, ::testing::ValuesIn(allTechniques()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });
