// Material maps against the CPU reference (direct mode, 16 jittered spp; its noise is printed beside
// each error) on a small scene built here: alpha cutouts, metallic-roughness, emissive and normal maps
// and vertex colours. Each test renders the card without and with the feature, and checks that GL
// stays as close to the reference with it as without, and that the feature changes both alike.
//
// Alpha cutouts (glTF alphaMode MASK; BLEND approximated at 0.5): a red card half cut out by its
// texture's alpha, over a floor, under a slanted sun. The GL frame (G-buffer and shadow map cut out)
// agrees with the CPU reference (its rays pass through the cut-out half) as closely as the same scene
// with an opaque card does, and both differ from the opaque card's frames where the cutout shows the
// floor and lets the sun through.
#include <algorithm>
#include <array>
#include <cstdio>
#include <memory>

#include <gtest/gtest.h>

#include "GlTestSupport.h"
#include "analysis/Accuracy.h"
#include "frame/FrameState.h"
#include "reference/ReferenceRenderer.h"
#include "render/FrameRenderer.h"
#include "scene/SceneLoader.h"

using namespace gis;

namespace {

Mesh quad(const std::string& name, float y, float half, int material) {
    Mesh m;
    m.name = name;
    m.positions = {{-half, y, -half}, {half, y, -half}, {half, y, half}, {-half, y, half}};
    m.normals.assign(4, glm::vec3(0.0f, 1.0f, 0.0f));
    m.texcoords = {{0.0f, 0.0f}, {1.0f, 0.0f}, {1.0f, 1.0f}, {0.0f, 1.0f}};
    m.indices = {0, 2, 1, 0, 3, 2};
    m.material = material;
    return m;
}

Scene cardScene(Material::Alpha mode) {
    Scene s;
    s.name = "card";
    s.meshes = {quad("floor", 0.0f, 1.0f, 0), quad("card", 0.5f, 0.5f, 1)};
    s.materials = {
        Material{.name = "floor", .baseColor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f)},
        Material{.name = "card", .baseColor = glm::vec4(0.9f, 0.1f, 0.1f, 1.0f), .baseColorTexture = 0}};
    s.materials[1].alphaMode = mode;
    s.materials[1].alphaCutoff = 0.5f;
    // 8 x 1 texels: alpha 0 on the left half of the card (u < 0.5), 1 on the right.
    TextureImage t;
    t.width = 8;
    t.height = 1;
    t.name = "half";
    for (int x = 0; x < 8; ++x)
        t.rgba.insert(t.rgba.end(), {255, 255, 255, static_cast<std::uint8_t>(x < 4 ? 0 : 255)});
    s.textures = {t};
    Light sun;
    sun.name = "sun";
    sun.type = LightType::Directional;
    sun.direction = glm::normalize(glm::vec3(0.35f, -1.0f, 0.15f));
    sun.intensity = 3.0f;
    s.lights = {sun};
    Camera c;
    c.name = "above";
    c.position = {0.0f, 2.6f, 1.6f};
    c.target = {0.0f, 0.2f, 0.0f};
    c.yfovRadians = 0.9f;
    c.znear = 0.05f;
    c.zfar = 20.0f;
    s.cameras = {c};
    s.updateBounds();
    finalizeScene(s, "card");
    return s;
}

constexpr int kSide = 64;

struct Frames {
    FrameOutput gl;
    ReferenceImage reference; // RGB, with its pixel means' variance
};

Frames renderScene(const Scene& scene) {
    FrameState state;
    Frames f;
    f.gl = test::renderScene(scene, "none", kSide, kSide, {{"shadow_map_size", 1024}},
                             [&](FrameState& used) { state = used; });
    ReferenceRenderer reference(scene);
    f.reference = reference.render(state, {.mode = "direct", .spp = 16, .seed = 3, .jitter = true});
    return f;
}

/// The card without (`base`) and with (`variant`) a feature: GL's error against its reference, that
/// reference's own noise, and how much the feature changes each side.
struct Comparison {
    double baseError, variantError, baseNoise, variantNoise, glChange, referenceChange;
};

Comparison compare(const char* label, const Frames& base, const Frames& variant) {
    const size_t pixels = kSide * kSide;
    const auto noise = [](const Frames& f) {
        return relativeNoise(ImageView(f.reference.rgb, kSide, kSide, 3), f.reference.variance);
    };
    const Comparison c{test::relativeRmseOf(base.gl.linear, 4, base.reference.rgb, 3, pixels),
                       test::relativeRmseOf(variant.gl.linear, 4, variant.reference.rgb, 3, pixels),
                       noise(base),
                       noise(variant),
                       test::relativeRmseOf(variant.gl.linear, 4, base.gl.linear, 4, pixels),
                       test::relativeRmseOf(variant.reference.rgb, 3, base.reference.rgb, 3, pixels)};
    std::printf(
        "[%s] GL against the reference (direct, 16 spp): without %.4f (reference noise %.4f), with %.4f "
        "(noise %.4f); the feature changes GL by %.3f, the reference by %.3f\n",
        label, c.baseError, c.baseNoise, c.variantError, c.variantNoise, c.glChange, c.referenceChange);
    return c;
}

Frames render(Material::Alpha mode) {
    return renderScene(cardScene(mode));
}

TextureImage halves(const std::string& name, std::array<std::uint8_t, 4> left,
                    std::array<std::uint8_t, 4> right, bool srgb) {
    TextureImage t;
    t.width = 8;
    t.height = 1;
    t.name = name;
    t.srgb = srgb;
    for (int x = 0; x < 8; ++x) {
        const auto& c = x < 4 ? left : right;
        t.rgba.insert(t.rgba.end(), c.begin(), c.end());
    }
    return t;
}

// The card opaque and grey; `maps`: its left half metallic (blue 255) and smooth (green 80), its right
// half dielectric and rough, and an emissive texture lit on the right half only.
Scene mappedScene(bool maps) {
    Scene s = cardScene(Material::Alpha::Opaque);
    Material& card = s.materials[1];
    card.baseColor = glm::vec4(0.7f, 0.6f, 0.3f, 1.0f);
    card.baseColorTexture = -1;
    card.metallic = 1.0f;
    card.roughness = 1.0f;
    card.specular = 1.0f;
    card.emissive = glm::vec3(0.6f, 0.3f, 0.1f);
    if (maps) {
        s.textures = {halves("metal-rough", {0, 80, 255, 255}, {0, 255, 0, 255}, false),
                      halves("glow", {0, 0, 0, 255}, {255, 255, 255, 255}, true)};
        card.metallicRoughnessTexture = 0;
        card.emissiveTexture = 1;
    }
    return s;
}

// The card opaque and white; `mapped`: its left half's normal map tilts the normal 35 degrees along
// +u (tangent space (0.57, 0, 0.82)), its right half is flat (0, 0, 1).
Scene normalScene(bool mapped) {
    Scene s = cardScene(Material::Alpha::Opaque);
    Material& card = s.materials[1];
    card.baseColor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
    card.baseColorTexture = -1;
    if (mapped) {
        s.textures = {halves("normals", {200, 128, 232, 255}, {128, 128, 255, 255}, false)};
        card.normalTexture = 0;
        card.normalScale = 1.0f;
        finalizeScene(s, "card"); // tangents for the mapped card
    }
    return s;
}

} // namespace

TEST(MaterialMaps, NormalMapMatchesTheReference) {
    const Frames flat = renderScene(normalScene(false));
    const Scene scene = normalScene(true);
    ASSERT_EQ(scene.meshes[1].tangents.size(), scene.meshes[1].positions.size());
    EXPECT_NEAR(scene.meshes[1].tangents[0].x, 1.0f, 1e-5f) << "+u runs along +x on the card";
    const Frames mapped = renderScene(scene);
    const Comparison c = compare("normal map", flat, mapped);
    EXPECT_EQ(test::badValues(mapped.gl), 0u);
    EXPECT_GT(c.glChange, 0.03);
    EXPECT_NEAR(c.glChange, c.referenceChange, 0.3 * c.referenceChange) << "the map changes both sides alike";
    EXPECT_LT(c.variantError, std::max(0.1, 1.5 * c.baseError));
}

// COLOR_0: the card's vertices red on its left edge, blue on its right, multiplying its white base.
TEST(MaterialMaps, VertexColoursMatchTheReference) {
    const Frames plain = renderScene(normalScene(false));
    Scene scene = normalScene(false);
    scene.meshes[1].colors = {{1.0f, 0.1f, 0.1f, 1.0f},
                              {0.1f, 0.1f, 1.0f, 1.0f},
                              {0.1f, 0.1f, 1.0f, 1.0f},
                              {1.0f, 0.1f, 0.1f, 1.0f}};
    const Comparison c = compare("vertex colours", plain, renderScene(scene));
    EXPECT_GT(c.glChange, 0.1);
    EXPECT_NEAR(c.glChange, c.referenceChange, 0.25 * c.referenceChange);
    EXPECT_LT(c.variantError, std::max(0.1, 1.5 * c.baseError));
}

TEST(MaterialMaps, MetallicRoughnessAndEmissiveTexturesMatchTheReference) {
    const Frames plain = renderScene(mappedScene(false));
    const Frames mapped = renderScene(mappedScene(true));
    const Comparison c = compare("maps", plain, mapped);
    EXPECT_EQ(test::badValues(mapped.gl), 0u);
    EXPECT_GT(c.glChange, 0.1);
    EXPECT_GT(c.referenceChange, 0.1);
    EXPECT_NEAR(c.glChange, c.referenceChange, 0.25 * c.referenceChange)
        << "the maps change both sides alike";
    EXPECT_LT(c.variantError, std::max(0.1, 1.5 * c.baseError));
}

TEST(AlphaCutout, MaskedCardMatchesTheReferenceInEveryPass) {
    const Frames opaque = render(Material::Alpha::Opaque);
    const Frames masked = render(Material::Alpha::Mask);
    const Frames blended = render(Material::Alpha::Blend);
    const Comparison c = compare("cutout", opaque, masked);
    EXPECT_EQ(test::badValues(masked.gl), 0u);
    // The cutout changes the image (the floor shows through and is lit through it) ...
    EXPECT_GT(c.glChange, 0.1);
    EXPECT_GT(c.referenceChange, 0.1);
    // ... the same way on both sides: GL stays as close to the reference as with an opaque card.
    EXPECT_LT(c.variantError, std::max(0.08, 1.5 * c.baseError));
    // BLEND is approximated by a cutout at 0.5: this texture's alpha is 0 or 1, so it renders the same.
    const size_t pixels = kSide * kSide;
    EXPECT_LT(test::relativeRmseOf(blended.gl.linear, 4, masked.gl.linear, 4, pixels), 1e-6);
    EXPECT_LT(test::relativeRmseOf(blended.reference.rgb, 3, masked.reference.rgb, 3, pixels), 1e-6);
}

// glTF doubleSided: the card turned face down over the floor, seen from above. Double-sided, the camera
// sees its back (lit on that side); single-sided (glTF's default), the G-buffer culls it and the
// reference's camera rays pass it, so the floor shows, still shadowed by the card (light views see
// both sides). Both renderers change alike.
TEST(DoubleSided, SingleSidedBackFacesAreNotSeenByTheCamera) {
    auto faceDown = [](bool doubleSided) {
        Scene s = cardScene(Material::Alpha::Opaque);
        Mesh& card = s.meshes[1];
        card.indices = {0, 1, 2, 0, 2, 3};
        card.normals.assign(4, glm::vec3(0.0f, -1.0f, 0.0f));
        s.materials[1].baseColorTexture = -1;
        s.materials[1].doubleSided = doubleSided;
        return s;
    };
    const Frames shown = renderScene(faceDown(true));
    const Frames culled = renderScene(faceDown(false));
    const Comparison c = compare("single-sided", shown, culled);
    EXPECT_EQ(test::badValues(culled.gl), 0u);
    EXPECT_GT(c.glChange, 0.1);
    EXPECT_GT(c.referenceChange, 0.1);
    EXPECT_NEAR(c.glChange, c.referenceChange, 0.25 * c.referenceChange);
    EXPECT_LT(c.variantError, std::max(0.1, 1.5 * c.baseError));
}
