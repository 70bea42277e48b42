// The reference renderer with the reflection model of scene/Brdf.h (issue #11): the BRDF sampler's
// estimate against numerically integrated directional albedos, a white furnace around a GGX metal, a
// mirror reflecting an emitter, GGX and Phong renders, Lambertian scenes unchanged, the cache key.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "ReferenceTestScenes.h"
#include "core/Error.h"
#include "reference/ReferenceRenderer.h"
#include "reference/Sampling.h"
#include "frame/FrameParams.h"
#include "scene/Brdf.h"

using namespace gis;
using namespace gis::test;

namespace {

// Directional albedo E(wo) = Integral f(wi, wo) cos(theta_i) d(omega_i) by the midpoint rule in
// (mu = cos(theta_i), phi), where d(omega) = d(mu) d(phi). The lobes tested are at least ~4 degrees wide,
// far wider than the grid's 0.06 x 0.2 degree cells.
glm::dvec3 integratedAlbedo(const brdf::Surface& s, brdf::Lobe lobe, const glm::vec3& wo, int nMu = 512,
                            int nPhi = 1024) {
    const glm::vec3 n(0.0f, 0.0f, 1.0f);
    glm::dvec3 sum(0.0);
    for (int i = 0; i < nMu; ++i) {
        const double mu = (i + 0.5) / nMu;
        const double sinTheta = std::sqrt(std::max(0.0, 1.0 - mu * mu));
        for (int j = 0; j < nPhi; ++j) {
            const double phi = 2.0 * M_PI * (j + 0.5) / nPhi;
            const glm::vec3 wi(static_cast<float>(sinTheta * std::cos(phi)),
                               static_cast<float>(sinTheta * std::sin(phi)), static_cast<float>(mu));
            sum += glm::dvec3(brdf::evaluate(s, lobe, n, wi, wo)) * mu;
        }
    }
    return sum * (2.0 * M_PI / (static_cast<double>(nMu) * nPhi));
}

glm::vec3 viewAt(float thetaDegrees) {
    const float t = glm::radians(thetaDegrees);
    return {std::sin(t), 0.0f, std::cos(t)};
}

Material metal(const glm::vec3& base, float roughness) {
    Material m = diffuse(base, "metal");
    m.metallic = 1.0f;
    m.roughness = roughness;
    return m;
}

Material emitter(const glm::vec3& radiance) {
    Material m = diffuse(glm::vec3(0.0f), "emitter");
    m.emissive = radiance;
    return m;
}

FrameState stateWithParams(const Scene& scene, int w, int h, const char* lobe,
                           const char* specular = "auto") {
    FrameState s = makeFrameState(scene, "rsm_gather");
    s.width = w;
    s.height = h;
    s.frameParams.set("specular_lobe", lobe);
    s.frameParams.set("effect_specular", specular);
    return s;
}

glm::dvec3 meanRgb(const ReferenceImage& img) {
    glm::dvec3 m(0.0);
    for (size_t i = 0; i + 2 < img.rgb.size(); i += 3)
        m += glm::dvec3(img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]);
    return img.rgb.empty() ? m : m / static_cast<double>(img.rgb.size() / 3);
}

bool allFiniteNonNegative(const std::vector<float>& v) {
    return std::all_of(v.begin(), v.end(), [](float x) { return std::isfinite(x) && x >= 0.0f; });
}

} // namespace

// (e) The estimator of Sampling.h sampleBrdf(): the mean of f cos / pdf over its own samples is the
// directional albedo, for GGX and Phong, metals (specular lobe only) and dielectrics (lobe mixture).
TEST(ReferenceBrdf, SampledWeightMatchesIntegratedAlbedo) {
    struct Case {
        const char* name;
        brdf::Surface s;
        brdf::Lobe lobe;
        float theta;
    };
    const std::vector<Case> cases{
        {"ggx metal r0.3 30deg", brdf::surfaceFrom(glm::vec3(0.9f, 0.6f, 0.3f), 1.0f, 0.3f, 1.0f),
         brdf::Lobe::Ggx, 30.0f},
        {"ggx metal r0.5 60deg", brdf::surfaceFrom(glm::vec3(1.0f), 1.0f, 0.5f, 1.0f), brdf::Lobe::Ggx,
         60.0f},
        {"ggx metal r1.0 45deg", brdf::surfaceFrom(glm::vec3(1.0f), 1.0f, 1.0f, 1.0f), brdf::Lobe::Ggx,
         45.0f},
        {"ggx metal r0.8 75deg", brdf::surfaceFrom(glm::vec3(1.0f), 1.0f, 0.8f, 1.0f), brdf::Lobe::Ggx,
         75.0f},
        {"ggx dielectric r0.4 45deg", brdf::surfaceFrom(glm::vec3(0.5f, 0.7f, 0.2f), 0.0f, 0.4f, 1.0f),
         brdf::Lobe::Ggx, 45.0f},
        {"ggx half-metal r0.35 20deg", brdf::surfaceFrom(glm::vec3(0.8f), 0.5f, 0.35f, 1.0f), brdf::Lobe::Ggx,
         20.0f},
        {"phong metal r0.3 20deg", brdf::surfaceFrom(glm::vec3(1.0f), 1.0f, 0.3f, 1.0f), brdf::Lobe::Phong,
         20.0f},
        {"phong dielectric r0.6 50deg", brdf::surfaceFrom(glm::vec3(0.4f), 0.0f, 0.6f, 1.0f),
         brdf::Lobe::Phong, 50.0f},
    };
    const glm::vec3 n(0.0f, 0.0f, 1.0f);
    constexpr int kSamples = 200000;
    for (const Case& c : cases) {
        const glm::vec3 wo = viewAt(c.theta);
        const glm::dvec3 expected = integratedAlbedo(c.s, c.lobe, wo);
        reference::Rng rng(7, 0, 0);
        glm::dvec3 sum(0.0);
        for (int i = 0; i < kSamples; ++i) {
            reference::BrdfSample bs;
            const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
            ASSERT_TRUE(reference::sampleBrdf(c.s, c.lobe, n, wo, u0, u1, u2, bs)) << c.name;
            for (int k = 0; k < 3; ++k)
                ASSERT_TRUE(std::isfinite(bs.weight[k]) && bs.weight[k] >= 0.0f) << c.name;
            if (bs.weight.x > 0.0f) {
                // The density the weight used is the density the sampler has.
                EXPECT_NEAR(bs.pdf, reference::brdfPdf(c.s, c.lobe, n, bs.wi, wo), 1e-4f * bs.pdf) << c.name;
            }
            sum += glm::dvec3(bs.weight);
        }
        const glm::dvec3 got = sum / static_cast<double>(kSamples);
        for (int k = 0; k < 3; ++k)
            EXPECT_NEAR(got[k], expected[k], 0.01 * expected[k])
                << c.name << " channel " << k << ": sampled " << got[k] << " integrated " << expected[k];
        std::printf("%-28s E = %.4f %.4f %.4f (sampled %.4f %.4f %.4f)\n", c.name, expected.x, expected.y,
                    expected.z, got.x, got.y, got.z);
    }
}

// (a) White furnace: a white GGX metal (F0 = F90 = 1) under an enclosing sphere of unit emission, seen
// at 45 degrees. Every sample weighs F G2 / G1 <= 1, so no pixel exceeds 1, and the image is the
// single-scattering directional albedo, which loses energy with roughness.
TEST(ReferenceBrdf, WhiteFurnaceGgxMetalMatchesItsDirectionalAlbedo) {
    for (const float roughness : {0.5f, 1.0f}) {
        Scene scene;
        scene.name = "test:furnace";
        scene.materials.push_back(metal(glm::vec3(1.0f), roughness));
        scene.materials.push_back(emitter(glm::vec3(1.0f)));
        scene.meshes.push_back(makeQuadY(0.0f, -1.0f, 1.0f, -1.0f, 1.0f, 0));
        Mesh sky = makeInwardSphere(5.0f, 32);
        sky.material = 1;
        scene.meshes.push_back(sky);
        finalizeScene(scene, "furnace");
        const Camera cam = lookAt({0.0f, 1.0f, 1.0f}, {0.0f, 0.0f, 0.0f}, 4.0f); // 45 degrees off the normal
        FrameState state = frameFor(cam, pointLight({0.0f, 1.0f, 0.0f}, 1.0f), 16, 16);
        state.lights.at(0).enabled = false;
        ReferenceRenderer renderer(scene);
        const ReferenceImage img = renderer.render(state, {.mode = "path", .spp = 256, .maxDepth = 2});
        ASSERT_TRUE(allFiniteNonNegative(img.rgb));
        for (float v : img.rgb) EXPECT_LE(v, 1.0f + 1e-5f);
        const brdf::Surface s = brdf::surfaceFrom(glm::vec3(1.0f), 1.0f, roughness, 1.0f);
        const double expected = integratedAlbedo(s, brdf::Lobe::Ggx, viewAt(45.0f)).x;
        const glm::dvec3 got = meanRgb(img);
        std::printf("roughness %.1f: furnace %.4f, directional albedo %.4f\n", roughness, got.x, expected);
        EXPECT_LT(expected, 0.99); // single scattering loses energy
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], expected, 0.01 * expected);
    }
}

// (c) A mirror (metallic 1, roughness 0: alpha at its 2e-3 floor) reflecting a large emitter: the
// reflected radiance is F(30 deg) x emission = F0 x emission (Schlick's excess (1 - cos)^5 is 4e-5 there)
// at 64 spp, because the GGX sampler's weight F G2 / G1 hardly varies.
TEST(ReferenceBrdf, MirrorReflectsAnEmitterTimesF0) {
    const glm::vec3 f0(0.9f, 0.6f, 0.3f);
    const glm::vec3 le(2.0f, 1.5f, 1.0f);
    Scene scene;
    scene.name = "test:mirror";
    scene.materials.push_back(metal(f0, 0.0f));
    scene.materials.push_back(emitter(le));
    scene.meshes.push_back(makeQuadY(0.0f, -2.0f, 2.0f, -2.0f, 2.0f, 0));
    scene.meshes.push_back(makeQuadY(2.0f, -4.0f, 4.0f, -4.0f, 4.0f, 1));
    finalizeScene(scene, "mirror");
    const Camera cam = lookAt({0.0f, 1.0f, std::tan(glm::radians(30.0f))}, {0.0f, 0.0f, 0.0f}, 10.0f);
    FrameState state = frameFor(cam, pointLight({0.0f, 1.5f, 0.0f}, 1.0f), 8, 8);
    state.lights.at(0).enabled = false;
    ReferenceRenderer renderer(scene);
    const ReferenceImage img = renderer.render(state, {.mode = "path", .spp = 64, .maxDepth = 2});
    ASSERT_TRUE(allFiniteNonNegative(img.rgb));
    for (size_t i = 0; i < img.rgb.size(); ++i) {
        const double expected =
            static_cast<double>(f0[static_cast<int>(i % 3)]) * le[static_cast<int>(i % 3)];
        EXPECT_NEAR(img.rgb[i], expected, 0.015 * expected) << "value " << i;
    }
    const glm::dvec3 m = meanRgb(img);
    std::printf("mirror: %.4f %.4f %.4f, F0 x Le = %.4f %.4f %.4f\n", m.x, m.y, m.z, f0.x * le.x, f0.y * le.y,
                f0.z * le.z);
}

// (d) GGX and Phong lobes render the gallery (glossy floor, mirror, gold, copper) in every mode without
// NaN, Inf or negative values; the lobe choice and effect_specular=off change the image.
TEST(ReferenceBrdf, GgxAndPhongRenderTheGalleryFinite) {
    const Scene scene = loadScene("builtin:gallery");
    ReferenceRenderer renderer(scene);
    for (const char* mode : {"direct", "one-bounce-unoccluded", "one-bounce", "path"}) {
        const ReferenceOptions o{.mode = mode, .spp = 2, .maxDepth = 4};
        const ReferenceImage ggx = renderer.render(stateWithParams(scene, 24, 24, "ggx"), o);
        const ReferenceImage phong = renderer.render(stateWithParams(scene, 24, 24, "phong"), o);
        const ReferenceImage off = renderer.render(stateWithParams(scene, 24, 24, "ggx", "off"), o);
        EXPECT_TRUE(allFiniteNonNegative(ggx.rgb)) << mode;
        EXPECT_TRUE(allFiniteNonNegative(phong.rgb)) << mode;
        EXPECT_TRUE(allFiniteNonNegative(off.rgb)) << mode;
        EXPECT_GT(meanRgb(ggx).x, 0.0) << mode;
        EXPECT_GT(meanRgb(phong).x, 0.0) << mode;
        EXPECT_NE(ggx.rgb, phong.rgb) << mode;
        EXPECT_NE(ggx.rgb, off.rgb) << mode;
    }
}

// (b) A Lambertian scene ignores the lobe and the specular switch bit for bit (its estimator is the
// Lambertian one; AnalyticTest.cpp checks its values against closed forms).
TEST(ReferenceBrdf, LambertianSceneIgnoresLobeAndSpecularSwitch) {
    const Scene scene = loadScene("builtin:cornell");
    ReferenceRenderer renderer(scene);
    for (const char* mode : {"direct", "one-bounce-unoccluded", "one-bounce", "path"}) {
        const ReferenceOptions o{.mode = mode, .spp = 2};
        const ReferenceImage ggx = renderer.render(stateWithParams(scene, 16, 16, "ggx"), o);
        FrameState bare = stateWithParams(scene, 16, 16, "ggx");
        bare.frameParams = ParamSet(); // as the analytic tests build it
        EXPECT_EQ(ggx.rgb, renderer.render(bare, o).rgb) << mode;
        EXPECT_EQ(ggx.rgb, renderer.render(stateWithParams(scene, 16, 16, "phong"), o).rgb) << mode;
        EXPECT_EQ(ggx.rgb, renderer.render(stateWithParams(scene, 16, 16, "ggx", "off"), o).rgb) << mode;
        ReferenceOptions regularised = o;
        regularised.causticMinRoughness = 1.0f;
        EXPECT_EQ(ggx.rgb, renderer.render(stateWithParams(scene, 16, 16, "ggx"), regularised).rgb) << mode;
    }
}

TEST(ReferenceCacheKey, FollowsTheReflectionModel) {
    const Scene scene = loadScene("builtin:gallery");
    const FrameState state = stateWithParams(scene, 32, 32, "ggx");
    const ReferenceOptions o{.mode = "path", .spp = 16};
    const std::string key = referenceCacheKey(scene, state, o);
    EXPECT_NE(key, referenceCacheKey(scene, stateWithParams(scene, 32, 32, "phong"), o));
    EXPECT_NE(key, referenceCacheKey(scene, stateWithParams(scene, 32, 32, "ggx", "off"), o));
    EXPECT_EQ(key, referenceCacheKey(scene, stateWithParams(scene, 32, 32, "ggx", "on"), o)); // shade alike
    ReferenceOptions regularised = o;
    regularised.causticMinRoughness = 0.35f;
    EXPECT_NE(key, referenceCacheKey(scene, state, regularised));
    regularised.causticMinRoughness = 1.5f;
    EXPECT_THROW(validateReferenceOptions(regularised), InputError);
    for (auto change : {+[](Material& m) { m.metallic = 0.25f; }, +[](Material& m) { m.roughness = 0.3f; },
                        +[](Material& m) { m.specular = 0.5f; }}) {
        Scene changed = scene;
        change(changed.materials[0]);
        EXPECT_NE(key, referenceCacheKey(changed, state, o));
    }
}
