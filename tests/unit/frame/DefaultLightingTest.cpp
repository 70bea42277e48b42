#include <cmath>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "frame/DefaultLighting.h"
#include "frame/FrameState.h"
#include "frame/LightModel.h"

using namespace gis;

namespace {

Camera cameraAt(glm::vec3 position, glm::vec3 target) {
    Camera c;
    c.position = position;
    c.target = target;
    return c;
}

void expectKeyLightFor(const Bounds& b, const Camera& cam) {
    const Light l = defaultKeyLight(b, cam);
    const glm::vec3 centre = b.center();
    const float radius = b.radius();
    const glm::vec3 offset = l.position - centre;
    const float d = glm::length(offset);
    ASSERT_TRUE(std::isfinite(d));
    EXPECT_NEAR(d, 2.5f * radius, 1e-3f * d) << "outside the bounds, at a distance set by their size";
    EXPECT_NEAR(glm::dot(l.direction, -offset / d), 1.0f, 1e-5f) << "aimed at the centre";
    EXPECT_GE(std::sin(l.outerConeAngle), radius / d) << "the cone covers the bounding sphere";
    EXPECT_LT(l.innerConeAngle, l.outerConeAngle);
    // Over the camera's shoulder: on the camera's side, above it and to its right.
    const glm::vec3 toCamera = glm::normalize(cam.position - centre);
    const glm::vec3 right = glm::normalize(glm::cross(-toCamera, cam.up));
    EXPECT_GT(glm::dot(offset, toCamera), 0.0f);
    EXPECT_GT(glm::dot(offset, cam.up), 0.0f);
    EXPECT_GT(glm::dot(offset, right), 0.0f);
    // The illuminance at the centre is the same at every scale (cd / m^2 = lux).
    EXPECT_NEAR(l.intensity / (d * d), 1.6f, 1e-3f);
}

} // namespace

TEST(DefaultLighting, KeyLightIsSizedFromTheBoundsAtEveryScale) {
    for (float scale : {1e-3f, 1.0f, 500.0f, 1e4f}) {
        SCOPED_TRACE(scale);
        const Bounds b{glm::vec3(-1.0f, 0.0f, -0.5f) * scale, glm::vec3(1.0f, 1.5f, 0.5f) * scale};
        expectKeyLightFor(b, cameraAt(glm::vec3(0.3f, 1.0f, 4.0f) * scale, b.center()));
        expectKeyLightFor(b, cameraAt(glm::vec3(-3.0f, 0.2f, -1.0f) * scale, b.center()));
    }
}

TEST(DefaultLighting, DegenerateInputsGiveAFiniteLight) {
    const Bounds point{glm::vec3(2.0f), glm::vec3(2.0f)};
    for (const Camera& cam : {cameraAt(glm::vec3(2.0f), glm::vec3(2.0f)), // camera at the centre
                              cameraAt(glm::vec3(2.0f, 9.0f, 2.0f), glm::vec3(2.0f))}) { // looking along up
        const Light l = defaultKeyLight(point, cam);
        for (int i = 0; i < 3; ++i) {
            EXPECT_TRUE(std::isfinite(l.position[i]));
            EXPECT_TRUE(std::isfinite(l.direction[i]));
        }
        EXPECT_NEAR(glm::length(l.direction), 1.0f, 1e-5f);
        EXPECT_TRUE(std::isfinite(l.intensity));
        EXPECT_GT(l.intensity, 0.0f);
        EXPECT_GT(l.outerConeAngle, 0.0f);
    }
}

TEST(DefaultLighting, FrameStateUsesTheScenesSpotAndOtherwiseSaysWhy) {
    Scene scene;
    scene.name = "test";
    scene.bounds = {glm::vec3(-1.0f), glm::vec3(1.0f)};
    scene.cameras.push_back(cameraAt({0.0f, 0.0f, 5.0f}, {0.0f, 0.0f, 0.0f}));

    FrameState none = makeFrameState(scene, "none");
    EXPECT_EQ(none.lightSource, "default");
    EXPECT_NE(none.lightNote.find("no lights"), std::string::npos) << none.lightNote;
    ASSERT_EQ(none.lights.size(), 2u) << "a key and a fill";
    EXPECT_TRUE(none.lights.at(0).enabled);
    EXPECT_TRUE(makeLightModel(none.lights.at(0), scene.bounds).on) << "the default key is a valid, lit spot";
    EXPECT_EQ(none.lights.at(1).light.type, LightType::Directional);
    EXPECT_TRUE(makeLightModel(none.lights.at(1), scene.bounds).on) << "the fill is a lit directional light";
    EXPECT_LT(none.lights.at(1).light.intensity, 0.5f * 1.6f) << "the fill is dim next to the key's 1.6 lux";

    // A file's own lights are used as given, whatever their types.
    Light point;
    point.type = LightType::Point;
    Light sun;
    sun.type = LightType::Directional;
    scene.lights = {point, point, sun};
    FrameState own = makeFrameState(scene, "none");
    EXPECT_EQ(own.lightSource, "scene");
    ASSERT_EQ(own.lights.size(), 3u);
    EXPECT_EQ(own.lights.at(2).light.type, LightType::Directional);
    EXPECT_EQ(own.lights.at(0).id, "light0");
    EXPECT_EQ(own.lights.at(2).id, "light2");
    EXPECT_NE(own.lightNote.find("3 lights"), std::string::npos) << own.lightNote;
}
