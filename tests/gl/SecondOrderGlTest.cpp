// Technique second_order (003): Halton light placement (pure functions), flux bookkeeping, negative
// lights against the one-bounce reference, and the numeric guards of digest S.4.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>

#include "GlTestSupport.h"
#include "gi/second_order/Halton.h"
#include "gi/second_order/SecondOrder.h"
#include "gl/ShaderShared.h"
#include "reference/ReferenceRenderer.h"

using namespace gis;
using test::badValues;
using test::counter;
using test::relativeRmseOf;

namespace {

const double kPi = 3.14159265358979323846;

// test::renderScene with second_order.
FrameOutput renderState(const std::string& sceneName, int w, int h, const nlohmann::json& params,
                        const std::function<void(FrameState&)>& edit = {}) {
    return test::renderScene(sceneName, "second_order", w, h, params, edit);
}

double count(const FrameOutput& f, const char* name) {
    return f.stats["counts"].value(name, -1.0);
}

// sqrt(mean((a - b)^2)) / sqrt(mean(b^2)) over RGB, pixels where either image is non-black.

SecondOrder* technique() {
    return dynamic_cast<SecondOrder*>(test::sharedRenderer().technique());
}

} // namespace

TEST(SecondOrderHalton, RadicalInversesHaveTheKnownValues) {
    const double base2[] = {0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875};
    for (std::uint32_t i = 1; i <= 7; ++i) EXPECT_DOUBLE_EQ(halton::radicalInverse(i, 2), base2[i - 1]) << i;
    const double base3[] = {1.0 / 3, 2.0 / 3, 1.0 / 9, 4.0 / 9, 7.0 / 9, 2.0 / 9, 5.0 / 9, 8.0 / 9, 1.0 / 27};
    for (std::uint32_t i = 1; i <= 9; ++i)
        EXPECT_NEAR(halton::radicalInverse(i, 3), base3[i - 1], 1e-15) << i;
    EXPECT_EQ(halton::radicalInverse(0, 2), 0.0);
    EXPECT_EQ(halton::radicalInverse(5, 1), 0.0); // no base-1 digits: defined, not a hang
    EXPECT_LT(halton::radicalInverse(0xFFFFFFFFu, 2), 1.0);
}

TEST(SecondOrderHalton, SpherePointsAreUnitAndUniformInZ) {
    // delta = asin(2 v - 1) makes z = sin(delta) uniform in [-1, 1] (digest S.4 case 16).
    const int n = 4096;
    double meanZ = 0;
    int above = 0;
    for (std::uint32_t i = 1; i <= n; ++i) {
        const glm::dvec3 s = halton::sphereDirection(i);
        EXPECT_NEAR(glm::length(s), 1.0, 1e-12);
        meanZ += s.z / n;
        if (s.z >= 0.5) ++above;
    }
    EXPECT_NEAR(meanZ, 0.0, 2e-3);
    EXPECT_NEAR(above / double(n), 0.25, 2e-3);
}

TEST(SecondOrderHalton, ConeSamplesLieInTheConeAndAreDeterministic) {
    for (double degrees : {10.0, 30.0, 60.0, 90.0}) {
        const double c = std::cos(degrees * kPi / 180.0);
        const halton::ConeSamples a = halton::sampleCone(c, 256);
        const halton::ConeSamples b = halton::sampleCone(c, 256);
        ASSERT_EQ(a.directions.size(), 256u) << degrees;
        EXPECT_FALSE(a.capped);
        EXPECT_EQ(a.draws, b.draws);
        EXPECT_TRUE(a.directions == b.directions) << "not deterministic at " << degrees << " degrees";
        for (const glm::vec3& d : a.directions) {
            EXPECT_GE(d.z, static_cast<float>(c) - 1e-6f) << degrees;
            EXPECT_NEAR(glm::length(d), 1.0f, 1e-5f);
        }
        // Acceptance is the cone's share of the sphere, (1 - cos) / 2 (digest 003.5 item 5).
        EXPECT_NEAR(256.0 / a.draws, (1.0 - c) / 2.0, 0.1 * (1.0 - c) / 2.0 + 2.0 / a.draws) << degrees;
    }
    // A cone of 180 degrees or more accepts every draw.
    const halton::ConeSamples all = halton::sampleCone(-1.0, 100);
    EXPECT_EQ(all.directions.size(), 100u);
    EXPECT_EQ(all.draws, 100u);
    EXPECT_EQ(halton::sampleCone(std::nan(""), 10, 1000).directions.size(), 0u);
    EXPECT_EQ(halton::sampleCone(0.5, 0).draws, 0u);
}

TEST(SecondOrderHalton, NarrowConeStopsAtTheCapWithFewerLights) {
    // 0.5 degrees: acceptance (1 - cos) / 2 = 1.9e-5, about 20 points in the 2^20 draws allowed.
    const auto start = std::chrono::steady_clock::now();
    const halton::ConeSamples s = halton::sampleCone(std::cos(0.5 * kPi / 180.0), 256);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_TRUE(s.capped);
    EXPECT_EQ(s.draws, halton::kMaxDraws);
    EXPECT_GT(s.directions.size(), 5u);
    EXPECT_LT(s.directions.size(), 60u);
    EXPECT_LT(seconds, 2.0);
    std::printf("0.5 degree cone: %zu lights from %u draws in %.1f ms\n", s.directions.size(), s.draws,
                seconds * 1e3);
}

TEST(SecondOrderHalton, FrustumSolidAngle) {
    // A 90 x 90 degree frustum is one face of a cube: 4 pi / 6.
    glm::dvec3 face[4] = {{-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}};
    for (auto& c : face) c = glm::normalize(c);
    EXPECT_NEAR(halton::frustumSolidAngle(face), 4.0 * kPi / 6.0, 1e-12);
    // Small frustums: the image-plane area.
    const double t = 1e-3;
    glm::dvec3 small[4] = {{-t, -t, 1}, {t, -t, 1}, {t, t, 1}, {-t, t, 1}};
    for (auto& c : small) c = glm::normalize(c);
    EXPECT_NEAR(halton::frustumSolidAngle(small), 4 * t * t, 1e-10);
    glm::dvec3 degenerate[4] = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    EXPECT_EQ(halton::frustumSolidAngle(degenerate), 0.0);
}

TEST(SecondOrder, PositiveLightsCarryTheRsmFluxWhateverTheirCount) {
    // Flux is normalised to the RSM total, so 64 and 256 lights carry the same total (digest S.4
    // case 7), and so does a narrow cone's handful.
    auto positiveFlux = [](int n, float coneDegrees) {
        FrameOutput f = renderState(
            "builtin:cornell", 64, 64, {{"positive_count", n}, {"negative_count", 0}}, [&](FrameState& s) {
                if (coneDegrees > 0) {
                    s.lights.at(0).light.outerConeAngle = glm::radians(coneDegrees);
                    s.lights.at(0).light.innerConeAngle = glm::radians(coneDegrees * 0.5f);
                }
            });
        int positives = 0;
        std::vector<shader::Vpl> vpls = technique()->readVpls(&positives);
        EXPECT_EQ(positives, static_cast<int>(count(f, "positive_count")));
        glm::dvec3 sum(0.0);
        int valid = 0;
        for (int i = 0; i < positives; ++i) {
            const auto& v = vpls[static_cast<size_t>(i)];
            if (v.position.w < 0.5f) {
                EXPECT_EQ(v.flux.r + v.flux.g + v.flux.b, 0.0f) << "an empty light carries flux";
                continue;
            }
            ++valid;
            EXPECT_NEAR(glm::length(glm::vec3(v.normal)), 1.0f, 2e-3f);
            EXPECT_GE(std::min({v.flux.r, v.flux.g, v.flux.b}), 0.0f);
            sum += glm::dvec3(v.flux);
        }
        EXPECT_EQ(valid, static_cast<int>(count(f, "positive_valid")));
        return sum;
    };
    const glm::dvec3 a = positiveFlux(64, 0), b = positiveFlux(256, 0);
    ASSERT_GT(a.g, 0.0);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c] / b[c], 1.0, 1e-4) << "channel " << c;
    // A narrower cone reflects less in total but its lights still sum to its RSM's flux: > 0.
    const glm::dvec3 narrow = positiveFlux(256, 5.0f);
    EXPECT_GT(narrow.g, 0.0);
    EXPECT_LT(narrow.g, b.g);
}

TEST(SecondOrder, NarrowConeRendersFewerLightsGracefully) {
    const auto start = std::chrono::steady_clock::now();
    FrameOutput f = renderState("builtin:cornell", 64, 48, {}, [](FrameState& s) {
        s.lights.at(0).light.outerConeAngle = glm::radians(0.5f);
        s.lights.at(0).light.innerConeAngle = glm::radians(0.25f);
    });
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(count(f, "cone_capped"), 1.0);
    EXPECT_GT(count(f, "positive_count"), 0.0);
    EXPECT_LT(count(f, "positive_count"), 256.0);
    EXPECT_EQ(count(f, "halton_draws"), double(halton::kMaxDraws));
    EXPECT_EQ(badValues(f), 0u);
    EXPECT_LT(seconds, 5.0);
}

TEST(SecondOrder, NegativeLightsMoveTowardsTheOneBounceReference) {
    const int w = 64, h = 64;
    const std::string sceneName = "builtin:cornell";
    const Scene scene = loadScene(sceneName);
    FrameState state = makeFrameState(scene, "second_order");
    state.width = w;
    state.height = h;
    ReferenceRenderer reference(scene);
    const ReferenceImage ref = reference.render(state, {.mode = "one-bounce", .spp = 512, .seed = 3});

    const FrameOutput without = renderState(sceneName, w, h, {{"negative_count", 0}});
    const FrameOutput with = renderState(sceneName, w, h, {});
    EXPECT_EQ(count(without, "negative_count"), 0.0);
    ASSERT_GT(count(with, "negative_count"), 0.0);

    // The negative lights subtract part of what the positive ones deliver: flux <= 0, unit emission
    // axes, and a total well below the positive total.
    int positives = 0;
    const std::vector<shader::Vpl> vpls = technique()->readVpls(&positives);
    double positive = 0, negative = 0;
    for (size_t i = 0; i < vpls.size(); ++i) {
        const float luma = 0.2126f * vpls[i].flux.r + 0.7152f * vpls[i].flux.g + 0.0722f * vpls[i].flux.b;
        if (static_cast<int>(i) < positives) {
            positive += luma;
        } else if (vpls[i].position.w > 0.5f) {
            EXPECT_LE(std::max({vpls[i].flux.r, vpls[i].flux.g, vpls[i].flux.b}), 0.0f);
            EXPECT_NEAR(glm::length(glm::vec3(vpls[i].normal)), 1.0f, 1e-4f);
            negative -= luma;
        }
    }
    EXPECT_GT(negative, 0.0);
    EXPECT_LT(negative, 0.5 * positive);
    const size_t pixels = static_cast<size_t>(w * h);
    const double errWithout = relativeRmseOf(without.linear, 4, ref.rgb, 3, pixels);
    const double errWith = relativeRmseOf(with.linear, 4, ref.rgb, 3, pixels);
    // Measured on llvmpipe: 0.1055 without, 0.0974 with 128 negative lights (reference noise at
    // 512 spp included in both).
    std::printf("cornell %dx%d vs one-bounce (%d spp): relative RMSE %.4f without, %.4f with %g negative "
                "lights; clamped %.4f\n",
                w, h, ref.spp, errWithout, errWith, count(with, "negative_count"),
                count(with, "negative_clamped_fraction"));
    EXPECT_LT(errWith, errWithout - 0.003);
}

TEST(SecondOrder, NegativeLightsLeaveTheEmptyBoxAlone) {
    // Inside an empty convex room every light is in front of every visible surface: S_neg is zero
    // (digest S.4 case 19a), so the negative lights must not change the image.
    const FrameOutput without = renderState("builtin:cornell-empty", 64, 64, {{"negative_count", 0}});
    const FrameOutput with = renderState("builtin:cornell-empty", 64, 64, {});
    const double change = relativeRmseOf(with.linear, 4, without.linear, 4, 64 * 64);
    EXPECT_LT(change, 0.005);
    EXPECT_EQ(count(with, "negative_clamped_fraction"), 0.0);
}

TEST(SecondOrder, NoNanInfOrNegativeRadiance) {
    const std::function<void(FrameState&)> narrow = [](FrameState& s) {
        s.lights.at(0).light.outerConeAngle = glm::radians(0.5f);
        s.lights.at(0).light.innerConeAngle = glm::radians(0.25f);
    };
    const std::function<void(FrameState&)> off = [](FrameState& s) { s.lights.at(0).enabled = false; };
    struct Config {
        const char* name;
        nlohmann::json params;
        std::function<void(FrameState&)> edit;
    };
    const Config configs[] = {
        {"default", nlohmann::json::object(), {}},
        {"no negative lights", {{"negative_count", 0}}, {}},
        {"unclamped, factor 3", {{"min_distance", 0.0}, {"lowres_factor", 3}}, {}},
        {"narrow cone", nlohmann::json::object(), narrow},
        {"light off", nlohmann::json::object(), off},
        {"no lights", {{"positive_count", 0}}, {}},
    };
    for (const char* scene :
         {"builtin:cornell", "builtin:cornell-empty", "builtin:crease", "builtin:cornell-dense"})
        for (glm::ivec2 size : {glm::ivec2(64, 64), glm::ivec2(63, 47)})
            for (const Config& c : configs) {
                const FrameOutput f = renderState(scene, size.x, size.y, c.params, c.edit);
                EXPECT_EQ(badValues(f), 0u) << scene << " " << size.x << "x" << size.y << " " << c.name;
                const double lowres = count(f, "lowres_fraction"),
                             clamped = count(f, "negative_clamped_fraction");
                EXPECT_TRUE(lowres >= 0.0 && lowres <= 1.0) << scene << " " << c.name;
                EXPECT_TRUE(clamped >= 0.0 && clamped <= 1.0) << scene << " " << c.name;
                if (std::string(c.name) == "light off" || std::string(c.name) == "no lights") {
                    EXPECT_EQ(count(f, "vpl_count"), 0.0) << scene;
                }
            }
}

TEST(SecondOrder, ThresholdExtremesAndDeterminism) {
    // Threshold 0: every covered pixel is fixed up, i.e. the unoptimised render (digest S.4 case 12);
    // threshold 2: none is.
    const FrameOutput full = renderState("builtin:cornell", 64, 48, {{"discontinuity_threshold", 0.0}});
    EXPECT_EQ(count(full, "lowres_fraction"), 0.0);
    EXPECT_EQ(count(full, "fixup_pixels"), count(full, "covered_pixels"));
    const FrameOutput factorOne =
        renderState("builtin:cornell", 64, 48, {{"lowres_factor", 1}, {"discontinuity_threshold", 2.0}});
    EXPECT_EQ(count(factorOne, "lowres_fraction"), 1.0);
    // The same lights at full resolution either way: equal up to summation order.
    EXPECT_LT(relativeRmseOf(factorOne.linear, 4, full.linear, 4, 64 * 48), 1e-5);

    const FrameOutput a = renderState("builtin:cornell", 64, 48, {});
    const FrameOutput b = renderState("builtin:cornell", 64, 48, {});
    EXPECT_TRUE(a.linear == b.linear) << "two renders of the same frame differ";
    const double lowres = count(a, "lowres_fraction");
    EXPECT_GT(lowres, 0.0);
    EXPECT_LT(lowres, 1.0);
}
