// Camera and light JSON (frame/StateJson.h): what each field does, the errors' JSON pointers, all or
// nothing on error, and the round trip through cameraJson/lightJson.
#include <gtest/gtest.h>

#include <functional>

#include "core/Error.h"
#include "frame/FrameState.h"
#include "frame/StateJson.h"
#include "scene/SceneLoader.h"

namespace {

constexpr float kDegToRad = 0.017453292519943295f;

gis::FrameState cornellState() {
    static const gis::Scene scene = gis::loadScene("builtin:cornell");
    return gis::makeFrameState(scene, "none");
}

/// The where() of the InputError `f` throws, "(none)" when it throws nothing.
std::string whereOf(const std::function<void()>& f, std::string* message = nullptr) {
    try {
        f();
    } catch (const gis::InputError& e) {
        if (message) *message = e.reason();
        return e.where();
    }
    return "(none)";
}

void expectVec(glm::vec3 actual, glm::vec3 expected, float eps = 1e-6f) {
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(actual[i], expected[i], eps) << "component " << i;
}

TEST(StateJson, CameraSetsEveryField) {
    gis::FrameState s = cornellState();
    gis::applyCameraJson(
        s, {{"position", {1, 2, 3}}, {"target", {0, 1, 0}}, {"up", {0, 0, 1}}, {"fov_deg", 50}}, "/camera");
    expectVec(s.camera.position, {1, 2, 3});
    expectVec(s.camera.target, {0, 1, 0});
    expectVec(s.camera.up, {0, 0, 1});
    EXPECT_NEAR(s.camera.yfovRadians, 50 * kDegToRad, 1e-6f);
}

TEST(StateJson, CameraKeepsUpAndFovWhenAbsent) {
    gis::FrameState s = cornellState();
    const gis::Camera before = s.camera;
    gis::applyCameraJson(s, {{"type", "camera"}, {"position", {1, 2, 3}}, {"target", {0, 1, 0}}}, "");
    expectVec(s.camera.up, before.up);
    EXPECT_EQ(s.camera.yfovRadians, before.yfovRadians);
}

TEST(StateJson, CameraErrorsNameTheField) {
    gis::FrameState s = cornellState();
    const gis::Camera before = s.camera;
    std::string message;
    EXPECT_EQ(whereOf(
                  [&] {
                      gis::applyCameraJson(s, {{"position", {0, 1, 3}}}, "/camera");
                  },
                  &message),
              "/camera");
    EXPECT_NE(message.find("target"), std::string::npos) << message;
    EXPECT_EQ(whereOf(
                  [&] {
                      gis::applyCameraJson(s, {{"position", {0, 1, 3}}, {"target", {0, 1, 3}}}, "/camera");
                  },
                  &message),
              "/camera/target");
    EXPECT_NE(message.find("must differ"), std::string::npos) << message;
    EXPECT_EQ(whereOf([&] {
                  gis::applyCameraJson(s, {{"position", {0, 1, 3}}, {"target", {0, 1, 0}}, {"up", {0, 0, 0}}},
                                       "/camera");
              }),
              "/camera/up");
    EXPECT_EQ(whereOf([&] {
                  gis::applyCameraJson(s, {{"position", {0, 1}}, {"target", {0, 1, 0}}}, "/camera");
              }),
              "/camera/position");
    EXPECT_EQ(whereOf([&] {
                  gis::applyCameraJson(s, {{"position", {0, "x", 1}}, {"target", {0, 1, 0}}}, "");
              }),
              "/position/1");
    EXPECT_EQ(whereOf([&] {
                  gis::applyCameraJson(s, {{"position", {0, 1, 3}}, {"target", {0, 1, 0}}, {"fov_deg", 179}},
                                       "/camera");
              }),
              "/camera/fov_deg");
    EXPECT_EQ(whereOf([&] { gis::applyCameraJson(s, nlohmann::json::array({1, 2}), "/camera"); }), "/camera");
    // All or nothing: the failed calls changed nothing.
    expectVec(s.camera.position, before.position);
    expectVec(s.camera.target, before.target);
    expectVec(s.camera.up, before.up);
}

TEST(StateJson, LightChangesOnlyTheGivenFields) {
    gis::FrameState s = cornellState();
    const gis::Light before = s.lights.at(0).light;
    gis::applyLightJson(s, {{"intensity", 3.5}, {"direction", {0, -0.5, 0}}}, "/light");
    EXPECT_EQ(s.lights.at(0).light.intensity, 3.5f);
    expectVec(s.lights.at(0).light.direction, {0, -1, 0}); // normalised
    expectVec(s.lights.at(0).light.position, before.position);
    expectVec(s.lights.at(0).light.color, before.color);
    EXPECT_EQ(s.lights.at(0).light.outerConeAngle, before.outerConeAngle);
    EXPECT_TRUE(s.lights.at(0).enabled);
    gis::applyLightJson(s, {{"enabled", false}, {"color", {1, 0.5, 0.25}}, {"position", {0, 1.5, 0}}},
                        "/light");
    EXPECT_FALSE(s.lights.at(0).enabled);
    expectVec(s.lights.at(0).light.color, {1, 0.5f, 0.25f});
    expectVec(s.lights.at(0).light.position, {0, 1.5f, 0});
}

TEST(StateJson, ConeKeepsTheInnerOuterRatio) {
    gis::FrameState s = cornellState();
    ASSERT_GT(s.lights.at(0).light.outerConeAngle, 0.0f);
    const float ratio = s.lights.at(0).light.innerConeAngle / s.lights.at(0).light.outerConeAngle;
    gis::applyLightJson(s, {{"cone_deg", 30}}, "/light");
    EXPECT_NEAR(s.lights.at(0).light.outerConeAngle, 30 * kDegToRad, 1e-6f);
    EXPECT_NEAR(s.lights.at(0).light.innerConeAngle / s.lights.at(0).light.outerConeAngle,
                std::min(ratio, 0.99f), 1e-5f);
}

TEST(StateJson, LightErrorsNameTheFieldAndChangeNothing) {
    gis::FrameState s = cornellState();
    const gis::Light before = s.lights.at(0).light;
    std::string message;
    EXPECT_EQ(whereOf(
                  [&] {
                      gis::applyLightJson(s, {{"intensity", 9}, {"direction", {0, 0, 0}}}, "/light");
                  },
                  &message),
              "/light/direction");
    EXPECT_NE(message.find("must not be zero"), std::string::npos) << message;
    EXPECT_EQ(whereOf([&] { gis::applyLightJson(s, {{"intensity", -1}}, "/light"); }), "/light/intensity");
    EXPECT_EQ(whereOf([&] { gis::applyLightJson(s, {{"color", {1, 2, 0}}}, "/light"); }), "/light/color/1");
    EXPECT_EQ(whereOf([&] { gis::applyLightJson(s, {{"cone_deg", 89}}, "/light"); }), "/light/cone_deg");
    EXPECT_EQ(whereOf([&] { gis::applyLightJson(s, {{"enabled", 1}}, "/light"); }), "/light/enabled");
    EXPECT_EQ(whereOf([&] {
                  gis::applyLightJson(s, {{"enabled", false}, {"intensity", "bright"}}, "");
              }),
              "/intensity");
    EXPECT_EQ(s.lights.at(0).light.intensity, before.intensity);
    EXPECT_TRUE(s.lights.at(0).enabled);
}

TEST(StateJson, JsonRoundTrips) {
    gis::FrameState s = cornellState();
    gis::applyCameraJson(s, {{"position", {0.5, 1.2, 3}}, {"target", {0, 0.9, 0}}, {"fov_deg", 45}}, "");
    gis::applyLightJson(s, {{"cone_deg", 40}, {"intensity", 7}, {"enabled", false}}, "");
    const nlohmann::json camera = gis::cameraJson(s.camera);
    const nlohmann::json light = gis::lightJson(s);
    for (const char* k : {"position", "target", "up", "fov_deg"}) EXPECT_TRUE(camera.contains(k)) << k;
    for (const char* k : {"position", "direction", "intensity", "color", "cone_deg", "enabled"})
        EXPECT_TRUE(light.contains(k)) << k;
    EXPECT_NEAR(camera["fov_deg"].get<double>(), 45.0, 1e-4);
    EXPECT_NEAR(light["cone_deg"].get<double>(), 40.0, 1e-4);
    EXPECT_EQ(light["enabled"], false);

    gis::FrameState t = cornellState();
    gis::applyCameraJson(t, camera, "");
    gis::applyLightJson(t, light, "");
    expectVec(t.camera.position, s.camera.position);
    expectVec(t.camera.target, s.camera.target);
    expectVec(t.camera.up, s.camera.up);
    EXPECT_NEAR(t.camera.yfovRadians, s.camera.yfovRadians, 1e-6f);
    expectVec(t.lights.at(0).light.position, s.lights.at(0).light.position);
    expectVec(t.lights.at(0).light.direction, s.lights.at(0).light.direction);
    EXPECT_EQ(t.lights.at(0).light.intensity, s.lights.at(0).light.intensity);
    EXPECT_NEAR(t.lights.at(0).light.outerConeAngle, s.lights.at(0).light.outerConeAngle, 1e-6f);
    EXPECT_FALSE(t.lights.at(0).enabled);
}

} // namespace

TEST(StateJson, LightsByIdAddRemoveAndReplace) {
    gis::FrameState s = cornellState();
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].id, "light0");
    // Protocol 2: nested fields, the light's own type among them.
    const std::string id =
        gis::addLightJson(s, {{"type", "point"}, {"position", {0.1, 1.2, 0.3}}, {"intensity", 2}}, "/light");
    EXPECT_EQ(id, "light1");
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_EQ(s.lights[1].light.type, gis::LightType::Point);
    gis::applyLightJson(
        s, {{"type", "light"}, {"id", "light1"}, {"light", {{"type", "directional"}, {"intensity", 0.5}}}},
        "");
    EXPECT_EQ(s.lights[1].light.type, gis::LightType::Directional);
    EXPECT_EQ(s.lights[1].light.intensity, 0.5f);
    // Protocol 1's flat message edits the first light and never reads its "type" as the light's.
    gis::applyLightJson(s, {{"type", "light"}, {"intensity", 7}}, "");
    EXPECT_EQ(s.lights[0].light.intensity, 7.0f);
    EXPECT_EQ(s.lights[0].light.type, gis::LightType::Spot);
    // Errors name the id or the field and change nothing.
    std::string message;
    EXPECT_EQ(whereOf(
                  [&] {
                      gis::applyLightJson(s, {{"id", "light9"}, {"light", {{"intensity", 1}}}}, "");
                  },
                  &message),
              "/id");
    EXPECT_NE(message.find("light0, light1"), std::string::npos) << message;
    EXPECT_EQ(whereOf([&] {
                  gis::applyLightJson(s, {{"id", "light1"}, {"light", {{"direction", {0, 0, 0}}}}}, "");
              }),
              "/light/direction");
    EXPECT_EQ(whereOf([&] { gis::applyLightJson(s, {{"light", {{"type", "area"}}}}, ""); }), "/light/type");
    EXPECT_EQ(whereOf([&] { gis::addLightJson(s, {{"range", -1}}, "/light"); }), "/light/range");
    EXPECT_EQ(whereOf([&] { gis::addLightJson(s, {{"id", "light0"}}, "/light"); }), "/light/id");
    EXPECT_EQ(whereOf([&] { gis::removeLight(s, "nope", "/id"); }), "/id");
    EXPECT_EQ(whereOf([&] {
                  gis::addLightJson(s, {{"cone_deg", 30}, {"inner_cone_deg", 40}}, "/light");
              }),
              "/light/inner_cone_deg");
    EXPECT_EQ(s.lights.size(), 2u);
    gis::removeLight(s, "light0", "/id");
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(gis::nextLightId(s), "light2") << "ids are not reused";
    // Replace all, all or nothing.
    EXPECT_EQ(whereOf([&] {
                  gis::setLightsJson(s, {{{"type", "spot"}}, {{"intensity", 1}}}, "/lights");
              }),
              "/lights/1");
    EXPECT_EQ(s.lights.size(), 1u);
    gis::setLightsJson(s, {{{"type", "spot"}}, {{"type", "point"}, {"range", 2}}, {{"type", "directional"}}},
                       "/lights");
    ASSERT_EQ(s.lights.size(), 3u);
    EXPECT_EQ(s.lights[1].light.range, 2.0f);
    const nlohmann::json all = gis::lightsJson(s);
    ASSERT_EQ(all.size(), 3u);
    EXPECT_EQ(all[2]["type"], "directional");
    EXPECT_EQ(all[0]["id"], "light0");
    EXPECT_EQ(gis::lightJson(s)["id"], "light0") << "protocol 1's light is the first";
}
