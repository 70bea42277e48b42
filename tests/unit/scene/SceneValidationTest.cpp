#include <cmath>
#include <functional>

#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "scene/SceneLoader.h"

namespace gis {
namespace {

/// One upward-facing triangle, a material, a camera and a spot light: valid as built.
Scene validScene() {
    Scene s;
    s.meshes.push_back(Mesh{.name = "tri",
                            .positions = {{0, 0, 0}, {1, 0, 0}, {0, 0, -1}},
                            .normals = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}},
                            .indices = {0, 1, 2}});
    s.materials.push_back(Material{.name = "white"});
    s.cameras.push_back(Camera{.name = "cam"});
    s.lights.push_back(Light{.name = "spot", .position = {0, 1, 0}});
    return s;
}

void expectInvalid(const Scene& s, const std::vector<std::string>& fragments) {
    try {
        validateScene(s, "test.gltf");
        ADD_FAILURE() << "expected InputError";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_EQ(e.where(), "test.gltf");
        for (const auto& f : fragments)
            EXPECT_NE(what.find(f), std::string::npos) << "'" << f << "' in: " << what;
    }
}

TEST(ValidateScene, AcceptsAValidScene) {
    EXPECT_NO_THROW(validateScene(validScene(), "test.gltf"));
}

TEST(ValidateScene, RejectsEachBrokenInvariant) {
    const std::vector<std::pair<std::function<void(Scene&)>, std::vector<std::string>>> cases = {
        {[](Scene& s) { s.meshes.clear(); }, {"no meshes"}},
        {[](Scene& s) {
             s.meshes[0].indices = {0, 1, 3};
         },
         {"mesh 'tri'", "index 3", "out of range"}},
        {[](Scene& s) {
             s.meshes[0].indices = {0, 1, 2, 0};
         },
         {"mesh 'tri'", "multiple of 3"}},
        {[](Scene& s) { s.meshes[0].normals.pop_back(); }, {"mesh 'tri'", "2 normals for 3 positions"}},
        {[](Scene& s) {
             s.meshes[0].texcoords = {{0, 0}};
         },
         {"mesh 'tri'", "1 texcoords"}},
        {[](Scene& s) { s.meshes[0].positions[2].z = INFINITY; }, {"mesh 'tri'", "position 2 is not finite"}},
        {[](Scene& s) { s.meshes[0].normals[1] = glm::vec3(NAN); }, {"mesh 'tri'", "normal 1"}},
        {[](Scene& s) {
             s.meshes[0].texcoords = {{0, 0}, {0, NAN}, {0, 0}};
         },
         {"texcoord 1 is not finite"}},
        {[](Scene& s) { s.meshes[0].material = 3; }, {"mesh 'tri'", "material 3 does not exist"}},
        {[](Scene& s) { s.materials[0].baseColorTexture = 0; },
         {"material 'white'", "texture 0 does not exist"}},
        {[](Scene& s) { s.lights[0].innerConeAngle = s.lights[0].outerConeAngle; }, {"light 'spot'", "cone"}},
        {[](Scene& s) { s.lights[0].outerConeAngle = 2.0f; }, {"light 'spot'", "cone"}},
        {[](Scene& s) { s.lights[0].innerConeAngle = -0.1f; }, {"light 'spot'", "cone"}},
        {[](Scene& s) { s.lights[0].intensity = -1.0f; }, {"light 'spot'", "intensity"}},
        {[](Scene& s) { s.lights[0].intensity = INFINITY; }, {"light 'spot'", "intensity"}},
        {[](Scene& s) { s.lights[0].direction = glm::vec3(0.0f); }, {"light 'spot'", "direction"}},
        {[](Scene& s) { s.cameras[0].znear = 0.0f; }, {"camera 'cam'", "znear"}},
        {[](Scene& s) { s.cameras[0].target = s.cameras[0].position; }, {"camera 'cam'", "coincides"}},
    };
    for (std::size_t i = 0; i < cases.size(); ++i) {
        SCOPED_TRACE("case " + std::to_string(i));
        Scene s = validScene();
        cases[i].first(s);
        expectInvalid(s, cases[i].second);
    }
}

TEST(ValidateScene, DegenerateTrianglesAndWideOuterConeOnPointLightsAreAllowed) {
    Scene s = validScene();
    s.meshes[0].positions[2] = s.meshes[0].positions[1];
    s.lights.push_back(Light{.name = "bulb", .type = LightType::Point, .outerConeAngle = 3.0f});
    EXPECT_NO_THROW(validateScene(s, "test.gltf"));
}

TEST(FinalizeScene, AddsDefaultsAndRepairsNormals) {
    Scene s;
    // Triangle 1 is degenerate; vertex 3 is only used by it, so it falls back to +Y.
    s.meshes.push_back(Mesh{.name = "m",
                            .positions = {{0, 0, 0}, {0, 1, 0}, {0, 0, 1}, {5, 5, 5}},
                            .normals = {{0, 0, 0}, {NAN, 0, 0}, {2, 0, 0}, {0, 0, 0}},
                            .indices = {0, 1, 2, 3, 3, 3}});
    finalizeScene(s, "here");
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].baseColor, glm::vec4(1.0f));
    const auto& n = s.meshes[0].normals;
    // Face (0,0,0),(0,1,0),(0,0,1): cross((0,1,0),(0,0,1)) = +X.
    EXPECT_EQ(n[0], glm::vec3(1, 0, 0));
    EXPECT_EQ(n[1], glm::vec3(1, 0, 0));
    EXPECT_EQ(n[2], glm::vec3(1, 0, 0)); // renormalised
    EXPECT_EQ(n[3], glm::vec3(0, 1, 0));
}

TEST(FinalizeScene, FramingCameraSeesTheWholeBoundingSphere) {
    Scene s;
    s.meshes.push_back(
        Mesh{.name = "m", .positions = {{-3, 1, -2}, {5, 1, -2}, {-3, 4, 6}}, .indices = {0, 1, 2}});
    finalizeScene(s, "here");
    ASSERT_EQ(s.cameras.size(), 1u);
    const Camera& c = s.cameras[0];
    const glm::vec3 center = s.bounds.center();
    EXPECT_EQ(c.target, center);
    EXPECT_NEAR(c.yfovRadians, glm::radians(40.0f), 1e-6f);
    // A three-quarter view from above: in front (+z), to the right (+x) and above (+y), so a flat
    // model is not seen edge-on.
    EXPECT_GT(c.position.z, center.z);
    EXPECT_GT(c.position.x, center.x);
    EXPECT_NEAR(glm::normalize(c.position - center).y, std::sin(glm::radians(25.0f)), 1e-5f);
    // The sphere's angular radius from the camera equals half the field of view.
    const float d = glm::distance(c.position, center);
    EXPECT_NEAR(std::asin(s.bounds.radius() / d), 0.5f * c.yfovRadians, 1e-4f);
    EXPECT_LT(c.znear, d - s.bounds.radius());
    EXPECT_GT(c.zfar, d + s.bounds.radius());
}

TEST(FinalizeScene, StillRejectsInvalidGeometry) {
    Scene s;
    s.meshes.push_back(Mesh{.name = "m", .positions = {{0, 0, 0}}, .indices = {0, 0, 9}});
    EXPECT_THROW(finalizeScene(s, "here"), InputError);
    Scene empty;
    EXPECT_THROW(finalizeScene(empty, "here"), InputError);
}

} // namespace
} // namespace gis
