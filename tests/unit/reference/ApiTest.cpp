// API contract: option validation, numeric guards, EXR round trip and the on-disk cache.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>

#include <gtest/gtest.h>
#include <unistd.h>

#include "ReferenceTestScenes.h"
#include "core/Error.h"
#include "reference/ReferenceRenderer.h"

using namespace gis;
using namespace gis::test;

namespace {

Scene smallScene() {
    Scene scene;
    scene.name = "test:small";
    scene.materials.push_back(diffuse(glm::vec3(0.7f)));
    scene.meshes.push_back(makeQuadY(0.0f, -1.0f, 1.0f, -1.0f, 1.0f, 0));
    finalizeScene(scene, "small");
    return scene;
}

FrameState smallState(const Scene&) {
    return frameFor(lookAt({0.0f, 1.5f, 1.5f}, {0.0f, 0.0f, 0.0f}), pointLight({0.0f, 1.0f, 0.0f}, 1.0f), 8,
                    8);
}

std::string whereOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.where();
    }
    return "<no InputError>";
}

bool allFiniteNonNegative(const std::vector<float>& v) {
    return std::all_of(v.begin(), v.end(), [](float x) { return std::isfinite(x) && x >= 0.0f; });
}

struct TempDir {
    std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("gis_reference_test_" + std::to_string(::getpid()));
    TempDir() { std::filesystem::create_directories(path); }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
};

} // namespace

TEST(ReferenceApi, ListsItsModes) {
    const std::vector<std::string> expected{"direct", "one-bounce-unoccluded", "one-bounce", "path"};
    EXPECT_EQ(referenceModes(), expected);
}

TEST(ReferenceApi, BadOptionsNameTheOption) {
    const Scene scene = smallScene();
    ReferenceRenderer renderer(scene);
    const FrameState state = smallState(scene);
    EXPECT_EQ(whereOf([&] { renderer.render(state, {.mode = "bidirectional"}); }), "mode");
    EXPECT_EQ(whereOf([&] { renderer.render(state, {.mode = "direct", .spp = 0}); }), "spp");
    EXPECT_EQ(whereOf([&] { renderer.render(state, {.mode = "path", .maxDepth = 0}); }), "max_depth");
    EXPECT_EQ(whereOf([&] { renderer.render(state, {.mode = "path", .timeBudgetSeconds = -1}); }),
              "time_budget");
    EXPECT_EQ(whereOf([&] { renderer.render(state, {.mode = "path", .timeBudgetSeconds = NAN}); }),
              "time_budget");
    EXPECT_EQ(whereOf([&] { renderer.render(state, {.mode = "path", .threads = -2}); }), "threads");
    FrameState bad = state;
    bad.width = 0;
    EXPECT_EQ(whereOf([&] { renderer.render(bad, {.mode = "direct"}); }), "width");
    bad = state;
    bad.height = -3;
    EXPECT_EQ(whereOf([&] { renderer.render(bad, {.mode = "direct"}); }), "height");
    try {
        renderer.render(state, {.mode = "bidirectional"});
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("one-bounce-unoccluded"), std::string::npos) << e.what();
    }
}

TEST(ReferenceApi, HardCasesStayFiniteAndNonNegative) {
    // The light on the surface (d^2 = 0 at one point, grazing everywhere else), inside the camera's near
    // plane, and a NaN light colour: every mode keeps the output finite and >= 0.
    Scene scene = smallScene();
    scene.meshes.push_back(makeQuadY(0.3f, -0.2f, 0.2f, -0.2f, 0.2f, 0));
    finalizeScene(scene, "hard");
    ReferenceRenderer renderer(scene);
    for (const glm::vec3 lightPos :
         {glm::vec3(0, 0, 0), glm::vec3(-1, 0, -1), glm::vec3(0, 0.3f, 0), glm::vec3(0.0f, 1.5f, 1.5f)}) {
        FrameState state = smallState(scene);
        state.lights.at(0).light.position = lightPos;
        for (const std::string& mode : referenceModes()) {
            const ReferenceImage img = renderer.render(state, {.mode = mode, .spp = 4, .jitter = true});
            EXPECT_TRUE(allFiniteNonNegative(img.rgb)) << mode;
        }
    }
    FrameState nanLight = smallState(scene);
    nanLight.lights.at(0).light.color = glm::vec3(NAN, 1.0f, INFINITY);
    const ReferenceImage img = renderer.render(nanLight, {.mode = "path", .spp = 4});
    EXPECT_TRUE(allFiniteNonNegative(img.rgb));
}

TEST(ReferenceApi, LightOffLeavesEmissionOnlyAndBackgroundIsZero) {
    Scene scene = smallScene();
    scene.materials[0].emissive = glm::vec3(0.25f, 0.5f, 1.0f);
    FrameState state = smallState(scene);
    state.lights.at(0).enabled = false;
    ReferenceRenderer renderer(scene);
    state.camera = lookAt({0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, 30.0f); // looks straight down at the quad
    const ReferenceImage img = renderer.render(state, {.mode = "one-bounce", .spp = 2});
    for (size_t i = 0; i < img.rgb.size(); i += 3) {
        EXPECT_FLOAT_EQ(img.rgb[i], 0.25f);
        EXPECT_FLOAT_EQ(img.rgb[i + 1], 0.5f);
        EXPECT_FLOAT_EQ(img.rgb[i + 2], 1.0f);
    }
    state.camera = lookAt({0.0f, 1.0f, 0.0f}, {0.0f, 2.0f, 0.0f}); // looks up into nothing
    const ReferenceImage sky = renderer.render(state, {.mode = "path", .spp = 2});
    EXPECT_TRUE(std::all_of(sky.rgb.begin(), sky.rgb.end(), [](float v) { return v == 0.0f; }));
}

TEST(ReferenceApi, TimeBudgetStopsEarlyAndReportsWhatItDid) {
    const Scene scene = loadScene("builtin:cornell");
    FrameState state = makeFrameState(scene, "rsm_gather");
    state.width = state.height = 32;
    ReferenceRenderer renderer(scene);
    const ReferenceImage img =
        renderer.render(state, {.mode = "path", .spp = 1000000, .timeBudgetSeconds = 0.3});
    EXPECT_GE(img.spp, 1);
    EXPECT_LT(img.spp, 1000000);
    EXPECT_GT(img.seconds, 0.0);
    EXPECT_LT(img.seconds, 3.0);
}

TEST(ReferenceApi, ExrRoundTripKeepsPixelsAndMetadata) {
    TempDir dir;
    ReferenceImage img;
    img.width = 3;
    img.height = 2;
    img.rgb = {0.0f, 0.5f, 1.0f, 2.0f, 3.5f, 1e-4f, 10.0f, 0.25f, 0.125f,
               7.0f, 8.0f, 9.0f, 1e6f, 0.0f, 3.0f,  4.0f,  5.0f,  6.0f};
    img.spp = 37;
    img.seconds = 1.5;
    img.mode = "one-bounce";
    img.key = "0123456789abcdef0123456789abcdef";
    img.variance = {0.0f, 1e-6f, 2e-6f, 3e-3f, 4.0f, 5e-9f, 6.0f, 7.0f, 8.0f,
                    9.0f, 1.0f,  0.5f,  1e4f,  0.0f, 0.0f,  2.0f, 1.0f, 0.25f};
    const std::string path = (dir.path / "x.exr").string();
    writeReferenceExr(path, img);
    const ReferenceImage back = readReferenceExr(path);
    EXPECT_EQ(back.variance, img.variance);
    // Without the variance the file has three channels and reads back with the variance unknown.
    ReferenceImage plain = img;
    plain.variance.clear();
    writeReferenceExr((dir.path / "plain.exr").string(), plain);
    const ReferenceImage plainBack = readReferenceExr((dir.path / "plain.exr").string());
    EXPECT_EQ(plainBack.rgb, img.rgb);
    EXPECT_TRUE(plainBack.variance.empty());
    EXPECT_EQ(back.width, 3);
    EXPECT_EQ(back.height, 2);
    EXPECT_EQ(back.rgb, img.rgb);
    EXPECT_EQ(back.spp, 37);
    EXPECT_NEAR(back.seconds, 1.5, 1e-6);
    EXPECT_EQ(back.mode, "one-bounce");
    EXPECT_EQ(back.key, img.key);
    EXPECT_EQ(whereOf([&] { readReferenceExr((dir.path / "missing.exr").string()); }),
              (dir.path / "missing.exr").string());
}

TEST(ReferenceApi, CacheRendersOnceThenHits) {
    TempDir dir;
    const Scene scene = loadScene("builtin:cornell");
    FrameState state = makeFrameState(scene, "rsm_gather");
    state.width = state.height = 16;
    const ReferenceOptions o{.mode = "one-bounce", .spp = 4};
    bool hit = true;
    const ReferenceImage first = renderReferenceCached(scene, state, o, dir.path.string(), &hit);
    EXPECT_FALSE(hit);
    EXPECT_TRUE(std::filesystem::exists(dir.path / (first.key + ".exr")));
    const ReferenceImage second = renderReferenceCached(scene, state, o, dir.path.string(), &hit);
    EXPECT_TRUE(hit);
    EXPECT_EQ(second.rgb, first.rgb);
    EXPECT_EQ(second.variance, first.variance);
    EXPECT_EQ(second.variance.size(), first.rgb.size());
    EXPECT_EQ(second.spp, first.spp);
    EXPECT_EQ(second.key, first.key);
    // A corrupt file for the key is replaced, not trusted.
    { std::ofstream(dir.path / (first.key + ".exr"), std::ios::trunc) << "not an exr"; }
    const ReferenceImage third = renderReferenceCached(scene, state, o, dir.path.string(), &hit);
    EXPECT_FALSE(hit);
    EXPECT_EQ(third.rgb, first.rgb);
}
