// Glossy VPL transport (docs/nondiffuse.md): Lambertian scenes are untouched by it, the gallery's
// rough copper block gains its specular bounce, multires_splat's illumination-driven refinement
// agrees with the full-resolution gather and refines more where the glossy lobe varies, and grazing
// views of glossy surfaces stay finite.
#include <cmath>

#include "GlTestSupport.h"
#include "render/Reflections.h"
#include "scene/SceneLoader.h"

using namespace gis;

namespace {

constexpr int kW = 64, kH = 64;

struct Stats {
    bool finite = true, nonNegative = true;
};

Stats check(const FrameOutput& f) {
    Stats s;
    for (float v : f.linear) {
        if (!std::isfinite(v)) s.finite = false;
        if (v < 0.0f) s.nonNegative = false;
    }
    return s;
}

/// Pixels whose centre ray hits mesh `name` first (masks from a frame where only that mesh is lit
/// differently would be fragile; the scene's geometry is known, so project its vertices' bounding box
/// and keep the pixels whose G-buffer-free test is: inside the projected box and not background).
std::vector<int> meshPixels(const Scene& scene, const std::string& name, int w, int h) {
    std::vector<int> out;
    for (const Mesh& m : scene.meshes) {
        if (m.name != name) continue;
        glm::ivec2 lo(w, h), hi(-1, -1);
        for (const glm::vec3& p : m.positions) {
            const glm::ivec2 px = test::projectToPixel(scene, p, w, h);
            lo = glm::min(lo, px);
            hi = glm::max(hi, px);
        }
        // Shrink by one pixel so silhouettes (mixed pixels) stay out.
        for (int y = std::max(lo.y + 1, 0); y <= std::min(hi.y - 1, h - 1); ++y)
            for (int x = std::max(lo.x + 1, 0); x <= std::min(hi.x - 1, w - 1); ++x) out.push_back(y * w + x);
    }
    return out;
}

double meanLuminance(const FrameOutput& f, const std::vector<int>& pixels) {
    double sum = 0.0;
    for (int i : pixels) {
        const float* p = &f.linear[static_cast<size_t>(i) * 4];
        sum += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    }
    return pixels.empty() ? 0.0 : sum / static_cast<double>(pixels.size());
}

double relativeDifference(const FrameOutput& a, const FrameOutput& b, const std::vector<int>& pixels) {
    double num = 0.0, den = 0.0;
    for (int i : pixels)
        for (int c = 0; c < 3; ++c) {
            const double x = a.linear[static_cast<size_t>(i) * 4 + c],
                         y = b.linear[static_cast<size_t>(i) * 4 + c];
            num += (x - y) * (x - y);
            den += y * y;
        }
    return den > 0.0 ? std::sqrt(num / den) : 0.0;
}

} // namespace

TEST(Glossy, LambertianScenesAreBitIdentical) {
    for (const char* technique : {"rsm_gather", "multires_splat"}) {
        nlohmann::json base = {{"vpl_grid", 8}};
        if (std::string(technique) == "multires_splat") base["refinement"] = "illumination";
        nlohmann::json on = base, off = base;
        on["effect_glossy"] = "on";
        off["effect_glossy"] = "off";
        const FrameOutput a = test::renderScene("builtin:cornell", technique, kW, kH, on);
        const FrameOutput b = test::renderScene("builtin:cornell", technique, kW, kH, off);
        ASSERT_EQ(a.linear.size(), b.linear.size());
        if (std::string(technique) == "rsm_gather") {
            EXPECT_TRUE(a.linear == b.linear) << technique << ": glossy transport changed a Lambertian frame";
        } else {
            // Per-VPL splatting evaluates the materials' model instead of the phong_* lobe: the same
            // value (phong_ks 0 is Lambertian) in another order of operations.
            double worst = 0.0;
            for (size_t i = 0; i < a.linear.size(); ++i)
                worst = std::max(worst, std::abs(double(a.linear[i]) - b.linear[i]) /
                                            std::max(1e-6, std::abs(double(b.linear[i]))));
            EXPECT_LT(worst, 1e-4) << technique;
        }
        EXPECT_EQ(a.stats["nondiffuse"]["specular"], "off: every material is Lambertian");
    }
}

TEST(Glossy, GalleryCopperGainsItsSpecularBounce) {
    const Scene scene = loadScene("builtin:gallery");
    const std::vector<int> copper = meshPixels(scene, "copper_block", kW, kH);
    ASSERT_GT(copper.size(), 10u);
    for (const char* technique : {"rsm_gather", "multires_splat"}) {
        // The environment probe would shade the copper when glossy transport is off: keep it out.
        nlohmann::json base = {{"vpl_grid", 8}, {"effect_env", "off"}, {"effect_mirrors", "off"}};
        if (std::string(technique) == "multires_splat") base["refinement"] = "illumination";
        nlohmann::json on = base, off = base;
        on["effect_glossy"] = "on";
        off["effect_glossy"] = "off";
        const FrameOutput a = test::renderScene("builtin:gallery", technique, kW, kH, on);
        const FrameOutput b = test::renderScene("builtin:gallery", technique, kW, kH, off);
        const Stats sa = check(a);
        EXPECT_TRUE(sa.finite && sa.nonNegative) << technique;
        EXPECT_EQ(a.stats["nondiffuse"]["glossy"], "on: effect_glossy=on");
        // The copper block is metal (rho_d = 0): without glossy transport it has no indirect light.
        const double gain = meanLuminance(a, copper) - meanLuminance(b, copper);
        EXPECT_GT(gain, 0.05 * meanLuminance(a, copper)) << technique;
    }
    // auto: the gallery has a rough specular material and rsm_gather carries glossy transport.
    const FrameOutput autoFrame =
        test::renderScene("builtin:gallery", "rsm_gather", kW, kH, {{"vpl_grid", 8}});
    EXPECT_EQ(autoFrame.stats["nondiffuse"]["glossy"], "on: 1 materials at least glossy_split rough");
    // Geometry refinement splats irradiance: no glossy transport, said so.
    const FrameOutput geometry =
        test::renderScene("builtin:gallery", "multires_splat", kW, kH, {{"vpl_grid", 8}});
    EXPECT_EQ(geometry.stats["nondiffuse"]["glossy"], "off: the technique has no glossy VPL transport");
}

TEST(Glossy, IlluminationRefinementFollowsTheGather) {
    // With every child refined (threshold at its 1e-7 floor) per-VPL splatting evaluates the same BRDF as the
    // gather at every pixel; a coarser threshold keeps fewer subsplats and stays close on the copper.
    const Scene scene = loadScene("builtin:gallery");
    const std::vector<int> copper = meshPixels(scene, "copper_block", kW, kH);
    const nlohmann::json common = {
        {"vpl_grid", 8}, {"effect_glossy", "on"}, {"effect_env", "off"}, {"effect_mirrors", "off"}};
    const FrameOutput gather = test::renderScene("builtin:gallery", "rsm_gather", kW, kH, common);
    nlohmann::json fine = common, coarse = common;
    fine["refinement"] = coarse["refinement"] = "illumination";
    fine["illum_threshold"] = 1e-7;
    coarse["illum_threshold"] = 0.05;
    const FrameOutput splatFine = test::renderScene("builtin:gallery", "multires_splat", kW, kH, fine);
    const FrameOutput splatCoarse = test::renderScene("builtin:gallery", "multires_splat", kW, kH, coarse);
    const double fineError = relativeDifference(splatFine, gather, copper);
    const double coarseError = relativeDifference(splatCoarse, gather, copper);
    std::printf("[glossy] copper rel. difference to the gather: threshold 0 %.4f, 0.05 %.4f\n", fineError,
                coarseError);
    EXPECT_LT(fineError, 0.02);
    EXPECT_LT(coarseError, 0.25);
    EXPECT_LE(splatCoarse.stats["counts"].value("subsplats_total", 0.0),
              splatFine.stats["counts"].value("subsplats_total", 0.0));
}

TEST(Glossy, GrazingViewsStayFinite) {
    // The camera 0.5 degrees above the glossy floor, and looking along the copper block's face.
    Scene scene = loadScene("builtin:gallery");
    for (const auto& [pos, target] :
         {std::pair{glm::vec3(0.0f, 0.02f, 0.99f), glm::vec3(0.0f, 0.0f, -1.3f)},
          std::pair{glm::vec3(-0.9f, 0.3f, 0.9f), glm::vec3(0.2f, 0.3f, -1.0f)}}) {
        scene.cameras[0].position = pos;
        scene.cameras[0].target = target;
        auto shared = std::make_shared<const Scene>(scene);
        FrameRenderer& renderer = test::sharedRenderer();
        renderer.setScene(shared);
        for (const char* technique : {"rsm_gather", "multires_splat"}) {
            FrameState state = makeFrameState(*shared, technique);
            state.width = kW;
            state.height = kH;
            applyParams(state, {{"vpl_grid", 8}, {"effect_glossy", "on"}, {"specular_lobe", "phong"}},
                        "test");
            if (std::string(technique) == "multires_splat")
                applyParams(state, {{"refinement", "illumination"}}, "test");
            const FrameOutput f = renderer.render(state, true);
            const Stats s = check(f);
            EXPECT_TRUE(s.finite) << technique << " at " << pos.x << "," << pos.y << "," << pos.z;
            EXPECT_TRUE(s.nonNegative) << technique;
        }
    }
}
