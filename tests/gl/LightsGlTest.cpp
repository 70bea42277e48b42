// Every light type and any number of lights through every technique: superposition on the linear
// output, each type against the CPU reference on the built-in light scenes, and the stability cases
// of issue [lights] (a light on or inside a surface, a directional light parallel to a wall, zero
// intensity, range 0, 64 lights).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>

#include "GlTestSupport.h"
#include "gi/Technique.h"
#include "gi/common/VplGrid.h"
#include "reference/ReferenceRenderer.h"

using namespace gis;

namespace {

// test::renderScene with the state edit first, as most tests here give it.
FrameOutput renderWith(const std::string& name, const std::string& technique, int w, int h,
                       const std::function<void(FrameState&)>& edit, const nlohmann::json& params = {}) {
    return test::renderScene(name, technique, w, h, params, edit);
}

Light pointAt(glm::vec3 p, float intensity, glm::vec3 colour) {
    Light l;
    l.name = "added point";
    l.type = LightType::Point;
    l.position = p;
    l.intensity = intensity;
    l.color = colour;
    return l;
}

double maxValue(const FrameOutput& f) {
    double m = 0;
    for (size_t i = 0; i < f.linear.size(); i += 4)
        m = std::max({m, double(f.linear[i]), double(f.linear[i + 1]), double(f.linear[i + 2])});
    return m;
}

} // namespace

// A frame with two lights equals the sum of the frames with each alone, on linear output, for every
// technique. Not exactly: with both lights the VPL budget is split between them by their RSM flux,
// while each alone gets all of it, so the sets are different samplings of the same bounce; and
// second_order's negative lights and its clamp are not linear. Measured on llvmpipe (48x48, cornell
// with its spot and an added blue point light, rsm_size 64, default VPL budgets; relative RMS
// difference of the two-light frame against the sum): none 0 (the direct pass is exactly linear),
// rsm_gather 0.068, ssbc 0.051, multires_splat 0.067, multires_gather 0.028, isr 0.036, hier_isr
// 0.021, second_order 0.039. Bounds below add headroom.
TEST(Lights, EveryTechniqueSuperposesTwoLights) {
    const int w = 48, h = 48;
    const Light blue = pointAt({-0.5f, 1.2f, 0.4f}, 1.5f, {0.3f, 0.5f, 1.0f});
    const std::map<std::string, double> bound = {
        {"none", 1e-5},           {"rsm_gather", 0.12},      {"ssbc", 0.09},
        {"multires_splat", 0.12}, {"multires_gather", 0.06}, {"isr", 0.06},
        {"hier_isr", 0.05},       {"second_order", 0.08}};
    for (const TechniqueEntry& entry : techniqueRegistry()) {
        const std::string& t = entry.info.name;
        SCOPED_TRACE(t);
        const nlohmann::json params = {{"rsm_size", 64}};
        const FrameOutput both = renderWith(
            "builtin:cornell", t, w, h,
            [&](FrameState& s) {
                s.lights.push_back({"blue", blue, true});
            },
            params);
        const FrameOutput spot = renderWith("builtin:cornell", t, w, h, nullptr, params);
        const FrameOutput point = renderWith(
            "builtin:cornell", t, w, h,
            [&](FrameState& s) {
                s.lights = {{"blue", blue, true}};
            },
            params);
        ASSERT_EQ(both.stats["lighting"]["rendered"].size(), 2u);
        EXPECT_EQ(test::badValues(both), 0u);
        std::vector<float> sum(both.linear.size());
        for (size_t i = 0; i < sum.size(); ++i) sum[i] = spot.linear[i] + point.linear[i];
        const double rel = test::relativeRmseOf(both.linear, 4, sum, 4, sum.size() / 4);
        std::printf("superposition %-16s relative RMS difference %.4f\n", t.c_str(), rel);
        ASSERT_TRUE(bound.count(t)) << "a new technique needs its bound here";
        EXPECT_LT(rel, bound.at(t));
    }
}

// Each light type against the reference's one-bounce-unoccluded mode, indirect only (each side's
// total minus its own direct term), for every technique at its defaults (rsm_size 64): a point light
// (cornell-point), a directional sun through a skylight (sun-room, lit mostly indirectly) and three
// coloured lights of all types (cornell-colored). rsm_gather also runs at one VPL per RSM texel with
// no distance clamp, the comparison ReferenceGl.RsmGatherApproachesOneBounceUnoccluded makes for the
// spot. The figures are printed; the bounds (kBounds) are the measured values on llvmpipe with
// headroom. What remains at the defaults is each technique's own approximation (the distance clamp,
// VPL count, hierarchy, negative lights' occlusion, which the unoccluded reference does not have)
// plus the reference's noise; the sun-room's reference is the noisiest (its light enters through 9%
// of the ceiling).
TEST(Lights, EachTypeApproachesTheReferenceWithEveryTechnique) {
    const int w = 40, h = 40;
    // technique -> {cornell-point, sun-room, cornell-colored}
    // Measured (cornell-point, sun-room, cornell-colored): rsm_gather 64^2 exact 0.114, 0.160, 0.166;
    // rsm_gather 0.192, 0.549, 0.241; ssbc 0.164, 0.356, 0.186; multires_splat 0.188, 0.548, 0.239;
    // multires_gather 0.165, 0.345, 0.218; isr 0.127, 0.167, 0.192; hier_isr 0.116, 0.294, 0.166;
    // second_order 0.194, 0.599, 0.247. Bounds: 1.3 x measured. In the sun-room most of the RSM is the
    // roof's sunlit outside, whose VPLs face away from the room: 256 VPLs leave few for the skylight's
    // patch (the exact row's 4096 do), hence its large default-budget errors.
    const std::map<std::string, std::array<double, 3>> kBounds = {
        {"rsm_gather (64^2, min_distance 0)", {0.15, 0.21, 0.22}},
        {"rsm_gather", {0.25, 0.72, 0.32}},
        {"ssbc", {0.22, 0.47, 0.25}},
        {"multires_splat", {0.25, 0.72, 0.32}},
        {"multires_gather", {0.22, 0.45, 0.29}},
        {"isr", {0.17, 0.22, 0.25}},
        {"hier_isr", {0.16, 0.39, 0.22}},
        {"second_order", {0.26, 0.78, 0.33}},
    };
    const char* scenes[] = {"builtin:cornell-point", "builtin:sun-room", "builtin:cornell-colored"};
    for (int k = 0; k < 3; ++k) {
        SCOPED_TRACE(scenes[k]);
        const Scene scene = loadScene(scenes[k]);
        FrameState state = makeFrameState(scene, "rsm_gather");
        state.width = w;
        state.height = h;
        ReferenceRenderer reference(scene);
        const ReferenceImage ref =
            reference.render(state, {.mode = "one-bounce-unoccluded", .spp = 1024, .seed = 5});
        const ReferenceImage refDirect = reference.render(state, {.mode = "direct", .spp = 1});
        const FrameOutput glDirect = test::renderScene(scenes[k], "none", w, h, {{"rsm_size", 64}});
        for (const auto& [label, bounds] : kBounds) {
            const bool exact = label.find("min_distance 0") != std::string::npos;
            const std::string technique = label.substr(0, label.find(' '));
            nlohmann::json params = {{"rsm_size", 64}};
            if (exact) params = {{"rsm_size", 64}, {"vpl_grid", 64}, {"min_distance", 0.0}};
            const FrameOutput gl = test::renderScene(scenes[k], technique, w, h, params);
            const test::IndirectPair ind = test::indirectOnly(gl, glDirect, ref.rgb, refDirect.rgb);
            const double glSum = ind.glSum, refSum = ind.refSum;
            const double indirect =
                test::relativeRmseOf(ind.gl, 3, ind.reference, 3, ind.reference.size() / 3);
            std::printf("%-24s %-36s indirect relative RMSE %.4f, mean indirect GL/reference %.3f (reference "
                        "%d spp)\n",
                        scenes[k], label.c_str(), indirect, refSum > 0 ? glSum / refSum : 0.0, ref.spp);
            EXPECT_GT(refSum, 0.0) << "the reference sees indirect light";
            EXPECT_EQ(test::badValues(gl), 0u) << label;
            EXPECT_LT(indirect, bounds[static_cast<size_t>(k)]) << label;
            if (exact) {
                EXPECT_NEAR(glSum / refSum, 1.0, 0.15) << "energy of the bounce";
            }
        }
    }
}

// Hard cases for every light type through every technique: finite, non-negative output, and no
// runaway energy (a bound far above the scene's brightest direct value).
TEST(Lights, HardCasesStayFiniteForEveryTechnique) {
    const int w = 32, h = 32;
    struct Hard {
        const char* name;
        std::function<void(FrameState&)> edit;
    };
    const std::vector<Hard> cases = {
        {"point light on the floor",
         [](FrameState& s) {
             s.lights = {{"p", pointAt({0.0f, 0.0f, 0.0f}, 2.0f, glm::vec3(1.0f)), true}};
         }},
        {"point light inside the tall box",
         [](FrameState& s) {
             s.lights = {{"p", pointAt({-0.35f, 0.6f, -0.35f}, 2.0f, glm::vec3(1.0f)), true}};
         }},
        {"point light in the wall plane",
         [](FrameState& s) {
             s.lights = {{"p", pointAt({-1.0f, 1.0f, 0.0f}, 2.0f, glm::vec3(1.0f)), true}};
         }},
        {"directional light parallel to the left wall",
         [](FrameState& s) {
             Light sun;
             sun.type = LightType::Directional;
             sun.direction = {0.0f, -1.0f, 0.0f}; // grazes the walls at exactly 90 degrees
             sun.intensity = 2.0f;
             s.lights = {{"sun", sun, true}};
         }},
        {"zero intensity", [](FrameState& s) { s.lights.at(0).light.intensity = 0.0f; }},
        {"range 0 on a point light (infinite)",
         [](FrameState& s) {
             Light p = pointAt({0.0f, 1.5f, 0.0f}, 2.0f, glm::vec3(1.0f));
             p.range = 0.0f;
             s.lights = {{"p", p, true}};
         }},
        {"tiny range",
         [](FrameState& s) {
             Light p = pointAt({0.0f, 1.5f, 0.0f}, 2.0f, glm::vec3(1.0f));
             p.range = 1e-6f;
             s.lights = {{"p", p, true}};
         }},
        {"64 lights of every type",
         [](FrameState& s) {
             s.frameParams.set("max_lights", 64);
             s.lights.clear();
             for (int i = 0; i < 64; ++i) {
                 Light l;
                 l.type = i % 3 == 0   ? LightType::Spot
                          : i % 3 == 1 ? LightType::Point
                                       : LightType::Directional;
                 const float a = 0.1f * static_cast<float>(i);
                 l.position = {0.8f * std::cos(a), 0.3f + 1.5f * static_cast<float>(i) / 64.0f,
                               0.8f * std::sin(a)};
                 l.direction = glm::normalize(glm::vec3(-std::cos(a), -1.0f, -std::sin(a)));
                 l.intensity = 0.05f;
                 l.color = {0.5f + 0.5f * std::cos(a), 0.6f, 0.5f + 0.5f * std::sin(a)};
                 std::string id = "l";
                 id += std::to_string(i);
                 s.lights.push_back({id, l, true});
             }
         }},
    };
    for (const TechniqueEntry& entry : techniqueRegistry()) {
        for (const Hard& c : cases) {
            SCOPED_TRACE(entry.info.name);
            SCOPED_TRACE(c.name);
            const FrameOutput f =
                renderWith("builtin:cornell", entry.info.name, w, h, c.edit, {{"rsm_size", 32}});
            EXPECT_EQ(test::badValues(f), 0u);
            EXPECT_LT(maxValue(f), 1e4) << "runaway energy";
            if (std::string(c.name) == "zero intensity") {
                EXPECT_EQ(maxValue(f), 0.0) << "no light, no emission: black";
                EXPECT_FALSE(f.stats["lighting"]["skipped"].empty()) << "the skipped light is listed";
                EXPECT_TRUE(f.stats["lighting"].contains("warning"));
            }
            if (std::string(c.name) == "64 lights of every type") {
                EXPECT_EQ(f.stats["lighting"]["rendered"].size(), 64u);
                EXPECT_GT(maxValue(f), 0.0);
            }
        }
    }
}

// The VPL budget is split by each view's measured flux: a light 100 times dimmer than another gets
// far fewer VPLs, and the VPL count stays at the budget.
TEST(Lights, VplBudgetFollowsEachLightsFlux) {
    const FrameOutput f = renderWith("builtin:cornell", "rsm_gather", 32, 32,
                                     [](FrameState& s) {
                                         Light dim = s.lights.at(0).light;
                                         dim.intensity *= 0.01f;
                                         dim.position.x += 0.3f;
                                         s.lights.push_back({"dim", dim, true});
                                     },
                                     {{"vpl_grid", 16}});
    const double count = test::counter(f, "vpl_count");
    EXPECT_GE(count, 16.0 * 16.0);
    EXPECT_LE(count, 16.0 * 16.0 + 2.0 * 16.0 + 2.0) << "the total stays near the budget";
}

TEST(Lights, SplitVplGridByFlux) {
    EXPECT_EQ(splitVplGrid(16, {}, 1, 256), std::vector<int>({16}));
    EXPECT_EQ(splitVplGrid(16, {}, 1, 8), std::vector<int>({8})) << "at most the RSM side";
    EXPECT_EQ(splitVplGrid(16, {3.0, 1.0}, 2, 256), std::vector<int>({14, 8})); // 192 and 64 VPLs
    EXPECT_EQ(splitVplGrid(16, {1.0, 0.0, 1.0}, 3, 256), std::vector<int>({11, 0, 11})) << "no flux, no VPLs";
    EXPECT_EQ(splitVplGrid(16, {0.0, 0.0}, 2, 256), std::vector<int>({11, 11})) << "all dark: an even split";
    EXPECT_EQ(splitVplGrid(16, {1.0, 1e-9}, 2, 256), std::vector<int>({16, 1})) << "a lit view keeps one VPL";
    EXPECT_EQ(splitVplGrid(16, {1.0, std::nan("")}, 2, 256), std::vector<int>({16, 0}));
}

// A rendered light that no surface reflects (here a spot above the room pointing up) is named in
// the stats' warning; the file's other light is not.
TEST(Lights, WarnsAboutALightThatReachesNoSurface) {
    const FrameOutput f = renderWith("builtin:cornell", "rsm_gather", 32, 32, [](FrameState& s) {
        Light away = s.lights.at(0).light;
        away.name = "skyward";
        away.position = {0.0f, 5.0f, 0.0f};
        away.direction = {0.0f, 1.0f, 0.0f};
        s.lights.push_back({"up", away, true});
    });
    const nlohmann::json& lighting = f.stats["lighting"];
    ASSERT_EQ(lighting["rendered"].size(), 2u);
    EXPECT_GT(lighting["rendered"][0]["reflected_flux"].get<double>(), 0.0);
    EXPECT_EQ(lighting["rendered"][1]["reflected_flux"].get<double>(), 0.0);
    ASSERT_TRUE(lighting.contains("warning")) << lighting.dump();
    const std::string warning = lighting["warning"];
    EXPECT_NE(warning.find("skyward"), std::string::npos) << warning;
    EXPECT_EQ(warning.find("ceiling_spot"), std::string::npos) << warning;
    // Alone (one view: its flux is read after the frame's read-back), the same light is warned about.
    const FrameOutput alone = renderWith("builtin:cornell", "rsm_gather", 32, 32, [](FrameState& s) {
        s.lights.at(0).light.name = "skyward";
        s.lights.at(0).light.position = {0.0f, 5.0f, 0.0f};
        s.lights.at(0).light.direction = {0.0f, 1.0f, 0.0f};
    });
    ASSERT_TRUE(alone.stats["lighting"].contains("warning")) << alone.stats["lighting"].dump();
    EXPECT_NE(alone.stats["lighting"]["warning"].get<std::string>().find("no surface reflects any light"),
              std::string::npos);
    // The file's own light, alone: measured, positive, no warning.
    const FrameOutput own = renderWith("builtin:cornell", "rsm_gather", 32, 32, nullptr);
    EXPECT_GT(own.stats["lighting"]["rendered"][0]["reflected_flux"].get<double>(), 0.0);
    EXPECT_FALSE(own.stats["lighting"].contains("warning"));
}
