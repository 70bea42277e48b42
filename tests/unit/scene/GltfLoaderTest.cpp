#include <cmath>
#include <fstream>
#include <iterator>
#include <map>

#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>

#include "GltfBuilder.h"
#include "core/Error.h"
#include "scene/SceneLoader.h"

namespace gis {
namespace {

using test::GltfBuilder;
using test::TempDir;

void expectNear(const glm::vec3& a, const glm::vec3& b, float eps = 1e-5f) {
    EXPECT_NEAR(a.x, b.x, eps);
    EXPECT_NEAR(a.y, b.y, eps);
    EXPECT_NEAR(a.z, b.z, eps);
}

TEST(GltfLoader, GltfWithDataUriBufferAndU16Indices) {
    TempDir dir;
    GltfBuilder b;
    b.setScene({b.addTriangleNode()});
    const std::string path = b.writeGltf(dir, "tri.gltf");
    const Scene s = loadGltf(path);
    EXPECT_EQ(s.name, path);
    ASSERT_EQ(s.meshes.size(), 1u);
    const Mesh& m = s.meshes[0];
    EXPECT_EQ(m.name, "tri");
    ASSERT_EQ(m.positions.size(), 3u);
    expectNear(m.positions[1], {1, 0, 0});
    EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2}));
    EXPECT_TRUE(m.texcoords.empty());
    ASSERT_EQ(s.materials.size(), 1u); // the default material
    EXPECT_EQ(m.material, 0);
    EXPECT_EQ(s.materials[0].baseColor, glm::vec4(1.0f));
    ASSERT_EQ(s.cameras.size(), 1u); // a framing camera
    expectNear(s.bounds.min, {0, 0, -1});
    expectNear(s.bounds.max, {1, 0, 0});
}

TEST(GltfLoader, GlbWithU8U32AndNonIndexedPrimitives) {
    TempDir dir;
    GltfBuilder b;
    const int pos = b.addVec3s({{0, 0, 0}, {1, 0, 0}, {0, 0, -1}, {1, 0, -1}});
    const int i8 = b.addIndices(std::vector<std::uint8_t>{0, 1, 2, 2, 1, 3}, test::kUnsignedByte);
    const int i32 = b.addIndices(std::vector<std::uint32_t>{2, 1, 3}, test::kUnsignedInt);
    const int posFlat = b.addVec3s({{0, 1, 0}, {1, 1, 0}, {0, 1, -1}});
    const int m8 = b.addMesh("u8", {{"attributes", {{"POSITION", pos}}}, {"indices", i8}});
    const int m32 = b.addMesh("u32", {{"attributes", {{"POSITION", pos}}}, {"indices", i32}});
    const int mFlat = b.addMesh("flat", {{"attributes", {{"POSITION", posFlat}}}});
    b.setScene({b.addNode({{"mesh", m8}}), b.addNode({{"mesh", m32}}), b.addNode({{"mesh", mFlat}})});
    const Scene s = loadGltf(b.writeGlb(dir, "three.glb"));
    ASSERT_EQ(s.meshes.size(), 3u);
    EXPECT_EQ(s.meshes[0].indices, (std::vector<std::uint32_t>{0, 1, 2, 2, 1, 3}));
    EXPECT_EQ(s.meshes[1].indices, (std::vector<std::uint32_t>{2, 1, 3}));
    EXPECT_EQ(s.meshes[2].indices, (std::vector<std::uint32_t>{0, 1, 2}));
    expectNear(s.meshes[2].positions[2], {0, 1, -1});
    EXPECT_EQ(s.triangleCount(), 4u);
}

TEST(GltfLoader, ChildTranslatedUnderScaledParentGetsWorldPositions) {
    TempDir dir;
    GltfBuilder b;
    const int pos = b.addVec3s({{0, 0, 0}, {1, 0, 0}, {0, 0, -1}});
    const int mesh = b.addMesh("child_tri", {{"attributes", {{"POSITION", pos}}}});
    const int child = b.addNode({{"mesh", mesh}, {"translation", {1, 0, 0}}});
    const int parent = b.addNode({{"scale", {2, 2, 2}}, {"children", {child}}});
    b.setScene({parent});
    const Scene s = loadGltf(b.writeGlb(dir, "tree.glb"));
    ASSERT_EQ(s.meshes.size(), 1u);
    expectNear(s.meshes[0].positions[0], {2, 0, 0});
    expectNear(s.meshes[0].positions[1], {4, 0, 0});
    expectNear(s.meshes[0].positions[2], {2, 0, -2});
}

TEST(GltfLoader, MatrixTransformAndNoSceneUsesAllRoots) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode();
    // Column-major: translation in elements 12..14, uniform scale 3.
    b.doc["nodes"][tri]["matrix"] = {3, 0, 0, 0, 0, 3, 0, 0, 0, 0, 3, 0, 5, 6, 7, 1};
    const Scene s = loadGltf(b.writeGltf(dir, "matrix.gltf")); // no "scenes": every root node is drawn
    ASSERT_EQ(s.meshes.size(), 1u);
    expectNear(s.meshes[0].positions[1], {8, 6, 7});
}

TEST(GltfLoader, RotationAndNonUniformScaleTransformSuppliedNormals) {
    TempDir dir;
    GltfBuilder b;
    // A 45-degree slope x = y; its normal (-1,1,0)/sqrt2 must follow the inverse transpose.
    const int pos = b.addVec3s({{0, 0, 0}, {0, 0, 1}, {1, 1, 0}});
    const glm::vec3 n = glm::normalize(glm::vec3(-1, 1, 0));
    const int nrm = b.addVec3s({n, n, n});
    const int mesh = b.addMesh("slope", {{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}}}});
    b.setScene({b.addNode({{"mesh", mesh}, {"scale", {2, 1, 1}}})});
    const Scene s = loadGltf(b.writeGlb(dir, "slope.glb"));
    // Scaled slope is x = 2y, whose normal is (-1, 2, 0)/sqrt5.
    expectNear(s.meshes[0].normals[0], glm::normalize(glm::vec3(-1, 2, 0)));
}

TEST(GltfLoader, MirroredNodeKeepsCounterClockwiseFrontFaces) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode();
    b.doc["nodes"][tri]["scale"] = {-1, 1, 1};
    b.setScene({tri});
    const Scene s = loadGltf(b.writeGlb(dir, "mirror.glb"));
    const Mesh& m = s.meshes[0];
    const glm::vec3 geometric = glm::cross(m.positions[m.indices[1]] - m.positions[m.indices[0]],
                                           m.positions[m.indices[2]] - m.positions[m.indices[0]]);
    EXPECT_GT(geometric.y, 0.0f);
    expectNear(m.normals[0], {0, 1, 0});
}

TEST(GltfLoader, MeshSharedByNodesIsStoredOnceWithOneMatrixPerNode) {
    TempDir dir;
    GltfBuilder b;
    const int pos = b.addVec3s({{0, 0, 0}, {1, 0, 0}, {0, 0, -1}});
    const int mesh = b.addMesh("shared_tri", {{"attributes", {{"POSITION", pos}}}});
    const int a = b.addNode({{"mesh", mesh}, {"translation", {10, 0, 0}}});
    const int c = b.addNode({{"mesh", mesh}, {"scale", {2, 2, 2}}});
    const int d = b.addNode({{"mesh", mesh}, {"rotation", {0, 0.7071068, 0, 0.7071068}}});
    b.setScene({a, c, d});
    const Scene s = loadGltf(b.writeGlb(dir, "shared.glb"));
    ASSERT_EQ(s.meshes.size(), 1u);
    const Mesh& m = s.meshes[0];
    ASSERT_EQ(m.instances.size(), 3u);
    expectNear(m.positions[1], {1, 0, 0}); // the mesh's own space
    expectNear(glm::vec3(m.instances[0] * glm::vec4(m.positions[1], 1.0f)), {11, 0, 0});
    expectNear(glm::vec3(m.instances[1] * glm::vec4(m.positions[1], 1.0f)), {2, 0, 0});
    expectNear(glm::vec3(m.instances[2] * glm::vec4(m.positions[1], 1.0f)), {0, 0, -1});
    EXPECT_EQ(s.triangleCount(), 3u);
    EXPECT_EQ(s.storedTriangleCount(), 1u);
    EXPECT_EQ(s.instanceCount(), 3u);
    // Bounds cover every placement.
    expectNear(s.bounds.max, {11, 0, 0});
    expectNear(s.bounds.min, {-1, 0, -2});

    // Flattened, the placements are world-space copies in one mesh, as single-use nodes would give.
    const Scene flat = flattenInstances(s);
    ASSERT_EQ(flat.meshes.size(), 1u);
    EXPECT_TRUE(flat.meshes[0].instances.empty());
    ASSERT_EQ(flat.meshes[0].positions.size(), 9u);
    expectNear(flat.meshes[0].positions[5], {0, 0, -2});
    EXPECT_EQ(flat.meshes[0].indices, (std::vector<std::uint32_t>{0, 1, 2, 3, 4, 5, 6, 7, 8}));
    EXPECT_EQ(flat.triangleCount(), 3u);
}

TEST(GltfLoader, GpuInstancingExtensionPlacesTheMeshPerElement) {
    TempDir dir;
    GltfBuilder b;
    const int pos = b.addVec3s({{0, 0, 0}, {1, 0, 0}, {0, 0, -1}});
    const int mesh = b.addMesh("blade", {{"attributes", {{"POSITION", pos}}}});
    const int translation = b.addVec3s({{0, 0, 0}, {5, 0, 0}, {0, 0, 5}});
    const int scale = b.addVec3s({{1, 1, 1}, {2, 2, 2}, {1, 3, 1}});
    const int node = b.addNode({{"mesh", mesh},
                                {"translation", {0, 1, 0}},
                                {"extensions",
                                 {{"EXT_mesh_gpu_instancing",
                                   {{"attributes", {{"TRANSLATION", translation}, {"SCALE", scale}}}}}}}});
    b.doc["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
    b.doc["extensionsRequired"] = {"EXT_mesh_gpu_instancing"};
    b.setScene({node});
    const Scene s = loadGltf(b.writeGlb(dir, "field.glb"));
    EXPECT_TRUE(s.notShown.empty());
    ASSERT_EQ(s.meshes.size(), 1u);
    ASSERT_EQ(s.meshes[0].instances.size(), 3u);
    // The node's own transform, then the instance's translation and scale.
    expectNear(glm::vec3(s.meshes[0].instances[1] * glm::vec4(1, 0, 0, 1)), {7, 1, 0});
    expectNear(glm::vec3(s.meshes[0].instances[2] * glm::vec4(0, 0, -1, 1)), {0, 1, 4});

    // Counts that differ are refused with the node and the extension named.
    b.doc["accessors"][scale]["count"] = 2;
    try {
        loadGltf(b.writeGlb(dir, "uneven.glb"));
        FAIL() << "uneven instance attributes were accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("node 0: EXT_mesh_gpu_instancing"), std::string::npos)
            << e.what();
    }
}

TEST(GltfLoader, PlacementsAreChargedAsTheFlattenedCopiesTheyStandFor) {
    TempDir dir;
    GltfBuilder b;
    const int pos = b.addVec3s({{0, 0, 0}, {1, 0, 0}, {0, 0, -1}});
    const int mesh = b.addMesh("blade", {{"attributes", {{"POSITION", pos}}}});
    std::vector<glm::vec3> offsets;
    for (int i = 0; i < 1000; ++i)
        offsets.emplace_back(static_cast<float>(i % 40), 0.0f, static_cast<float>(i / 40));
    const int translation = b.addVec3s(offsets);
    b.setScene({b.addNode(
        {{"mesh", mesh},
         {"extensions", {{"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", translation}}}}}}}})});
    b.doc["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
    const std::string path = b.writeGlb(dir, "field.glb");
    // 1,000 placements of a 48-byte triangle: the flattened copies the reference would build are
    // about 110 KB, so a 64 KiB budget refuses the file, saying what to do, and 1 MiB takes it.
    try {
        loadGltf(path, SceneLoadOptions{.maxDecodedBytes = 64 << 10});
        FAIL() << "placements past the budget were accepted";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("of mesh 'blade'"), std::string::npos) << what;
        EXPECT_NE(what.find("fewer instances"), std::string::npos) << what;
    }
    const Scene s = loadGltf(path, SceneLoadOptions{.maxDecodedBytes = 1 << 20});
    EXPECT_EQ(s.instanceCount(), 1000u);
}

TEST(GltfLoader, SharedMeshWithAMirroredPlacementIsFlattened) {
    TempDir dir;
    GltfBuilder b;
    const int pos = b.addVec3s({{0, 0, 0}, {1, 0, 0}, {0, 0, -1}});
    const int mesh = b.addMesh("shared_tri", {{"attributes", {{"POSITION", pos}}}});
    const int a = b.addNode({{"mesh", mesh}});
    const int mirrored = b.addNode({{"mesh", mesh}, {"scale", {-1, 1, 1}}});
    b.setScene({a, mirrored});
    const Scene s = loadGltf(b.writeGlb(dir, "mirrored.glb"));
    ASSERT_EQ(s.meshes.size(), 2u);
    EXPECT_TRUE(s.meshes[0].instances.empty());
    EXPECT_TRUE(s.meshes[1].instances.empty());
    expectNear(s.meshes[1].positions[1], {-1, 0, 0});
}

TEST(GltfLoader, InstanceWithANonFiniteMatrixIsRefusedByValidation) {
    TempDir dir;
    GltfBuilder b;
    const int pos = b.addVec3s({{0, 0, 0}, {1, 0, 0}, {0, 0, -1}});
    const int mesh = b.addMesh("shared_tri", {{"attributes", {{"POSITION", pos}}}});
    b.setScene({b.addNode({{"mesh", mesh}}), b.addNode({{"mesh", mesh}, {"translation", {1, 0, 0}}})});
    Scene s = loadGltf(b.writeGlb(dir, "two.glb"));
    ASSERT_EQ(s.meshes.size(), 1u);
    ASSERT_EQ(s.meshes[0].instances.size(), 2u);
    EXPECT_NO_THROW(validateScene(s, "two.glb"));
    s.meshes[0].instances[1][3][0] = std::nanf("");
    try {
        validateScene(s, "two.glb");
        FAIL() << "a NaN instance matrix was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("instance 1"), std::string::npos) << e.what();
    }
}

TEST(GltfLoader, MissingNormalsAreGeneratedUnitLengthOnTheCounterClockwiseSide) {
    TempDir dir;
    GltfBuilder b;
    // Two triangles sharing an edge at a 90-degree fold: shared vertices get the averaged normal.
    const int pos = b.addVec3s({{0, 0, 0}, {0, 0, -1}, {1, 0, 0}, {0, 1, 0}});
    const int idx = b.addIndices(std::vector<std::uint16_t>{0, 2, 1, 0, 1, 3}, test::kUnsignedShort);
    const int mesh = b.addMesh("fold", {{"attributes", {{"POSITION", pos}}}, {"indices", idx}});
    b.setScene({b.addNode({{"mesh", mesh}})});
    const Scene s = loadGltf(b.writeGltf(dir, "fold.gltf"));
    const Mesh& m = s.meshes[0];
    ASSERT_EQ(m.normals.size(), 4u);
    for (const auto& nrm : m.normals) EXPECT_NEAR(glm::length(nrm), 1.0f, 1e-5f);
    expectNear(m.normals[2], {0, 1, 0});                                 // floor only
    expectNear(m.normals[3], {1, 0, 0});                                 // wall x = 0 only
    expectNear(m.normals[0], glm::normalize(glm::vec3(1, 1, 0)), 1e-5f); // shared, equal areas
}

TEST(GltfLoader, NanSuppliedNormalIsRepairedWithTheFaceNormal) {
    TempDir dir;
    GltfBuilder b;
    const int pos = b.addVec3s({{0, 0, 0}, {1, 0, 0}, {0, 0, -1}});
    const float nan = std::nanf("");
    const int nrm = b.addVec3s({{0, 1, 0}, {nan, nan, nan}, {0, 0, 0}});
    const int mesh = b.addMesh("tri", {{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}}}});
    b.setScene({b.addNode({{"mesh", mesh}})});
    const Scene s = loadGltf(b.writeGlb(dir, "nan_normal.glb"));
    for (const auto& nrm_ : s.meshes[0].normals) expectNear(nrm_, {0, 1, 0});
}

TEST(GltfLoader, PerspectiveCameraAndSpotLightFromNodeWorldTransforms) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode();
    b.doc["cameras"] = {{{"name", "cam"},
                         {"type", "perspective"},
                         {"perspective", {{"yfov", 0.8}, {"znear", 0.1}, {"zfar", 50.0}}}}};
    b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    b.doc["extensionsRequired"] = {"KHR_lights_punctual"};
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
        {{"name", "spot"},
         {"type", "spot"},
         {"color", {1.0, 0.5, 0.25}},
         {"intensity", 12.0},
         {"range", 8.0},
         {"spot", {{"innerConeAngle", 0.3}, {"outerConeAngle", 0.6}}}}};
    const int cam = b.addNode({{"camera", 0}, {"translation", {0, 1, 5}}});
    // -90 degrees about X turns the light's -Z axis into -Y.
    const float h = std::sqrt(0.5f);
    const int light = b.addNode({{"translation", {0, 2, 0}},
                                 {"rotation", {-h, 0, 0, h}},
                                 {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    const int rig = b.addNode({{"translation", {1, 0, 0}}, {"children", {cam, light}}});
    b.setScene({tri, rig});
    const Scene s = loadGltf(b.writeGltf(dir, "camlight.gltf"));

    ASSERT_EQ(s.cameras.size(), 1u);
    const Camera& c = s.cameras[0];
    EXPECT_EQ(c.name, "cam");
    expectNear(c.position, {1, 1, 5});
    expectNear(glm::normalize(c.target - c.position), {0, 0, -1});
    expectNear(c.up, {0, 1, 0});
    EXPECT_FLOAT_EQ(c.yfovRadians, 0.8f);
    EXPECT_FLOAT_EQ(c.znear, 0.1f);
    EXPECT_FLOAT_EQ(c.zfar, 50.0f);

    ASSERT_EQ(s.lights.size(), 1u);
    const Light& l = s.lights[0];
    EXPECT_EQ(l.name, "spot");
    EXPECT_EQ(l.type, LightType::Spot);
    expectNear(l.position, {1, 2, 0});
    expectNear(l.direction, {0, -1, 0});
    expectNear(l.color, {1.0f, 0.5f, 0.25f});
    EXPECT_FLOAT_EQ(l.intensity, 12.0f);
    EXPECT_FLOAT_EQ(l.range, 8.0f);
    EXPECT_FLOAT_EQ(l.innerConeAngle, 0.3f);
    EXPECT_FLOAT_EQ(l.outerConeAngle, 0.6f);
}

TEST(GltfLoader, InfiniteFarPlaneIsClosedBeyondTheScene) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode();
    b.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}}};
    b.setScene({tri, b.addNode({{"camera", 0}, {"translation", {0, 0, 10}}})});
    const Scene s = loadGltf(b.writeGlb(dir, "inf.glb"));
    ASSERT_EQ(s.cameras.size(), 1u);
    EXPECT_GT(s.cameras[0].zfar, 11.0f);
}

// A 2x1 24-bit BMP: one red and one green pixel.
std::vector<std::uint8_t> tinyBmp() {
    std::vector<std::uint8_t> f(54 + 8, 0);
    const auto u32 = [&f](std::size_t at, std::uint32_t v) {
        for (int i = 0; i < 4; ++i)
            f[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
    };
    f[0] = 'B';
    f[1] = 'M';
    u32(2, static_cast<std::uint32_t>(f.size()));
    u32(10, 54);
    u32(14, 40);
    u32(18, 2);
    u32(22, 1);
    f[26] = 1;
    f[28] = 24;
    u32(34, 8);
    const std::uint8_t pixels[] = {0, 0, 255, 0, 255, 0, 0, 0}; // BGR BGR + row padding
    std::copy(std::begin(pixels), std::end(pixels), f.begin() + 54);
    return f;
}

/// Texture 0: tinyBmp() as image 0.
void addTinyTexture(GltfBuilder& b) {
    b.doc["images"] = {{{"uri", "data:image/bmp;base64," + test::base64(tinyBmp())}}};
    b.doc["textures"] = {{{"source", 0}}};
}

TEST(GltfLoader, MaterialFactorsEmissiveStrengthAndBaseColorTexture) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode();
    b.doc["meshes"][0]["primitives"][0]["material"] = 0;
    addTinyTexture(b);
    b.doc["materials"] = {
        {{"name", "paint"},
         {"pbrMetallicRoughness",
          {{"baseColorFactor", {0.5, 0.25, 1.0, 1.0}},
           {"metallicFactor", 0.2},
           {"roughnessFactor", 0.7},
           {"baseColorTexture", {{"index", 0}}}}},
         {"emissiveFactor", {1.0, 0.5, 0.0}},
         {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4.0}}}}}}};
    b.setScene({tri});
    const Scene s = loadGltf(b.writeGltf(dir, "material.gltf"));
    ASSERT_EQ(s.materials.size(), 1u);
    const Material& m = s.materials[0];
    EXPECT_EQ(m.name, "paint");
    EXPECT_EQ(m.baseColor, glm::vec4(0.5f, 0.25f, 1.0f, 1.0f));
    EXPECT_FLOAT_EQ(m.metallic, 0.2f);
    EXPECT_FLOAT_EQ(m.roughness, 0.7f);
    expectNear(m.emissive, {4.0f, 2.0f, 0.0f});
    ASSERT_EQ(m.baseColorTexture, 0);
    ASSERT_EQ(s.textures.size(), 1u);
    const TextureImage& t = s.textures[0];
    EXPECT_EQ(t.width, 2);
    EXPECT_EQ(t.height, 1);
    EXPECT_EQ(t.rgba, (std::vector<std::uint8_t>{255, 0, 0, 255, 0, 255, 0, 255}));
}

// What a file asks for and the renderer does not show is listed (Scene::notShown, stats.not_shown),
// naming the materials, meshes or nodes; a file the renderer shows whole lists nothing.
TEST(GltfLoader, FeaturesTheRendererDoesNotShowAreListed) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode("leaves");
    b.doc["meshes"][0]["primitives"][0]["material"] = 0;
    b.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = 0; // the positions, as colours
    b.doc["textures"] = {nlohmann::json::object()};
    b.doc["materials"] = {{{"name", "foliage"},
                           {"alphaMode", "BLEND"},
                           {"occlusionTexture", {{"index", 0}}},
                           {"extensions", {{"KHR_materials_clearcoat", {{"clearcoatFactor", 1.0}}}}}},
                          {{"name", "bark"}, {"occlusionTexture", {{"index", 0}}}}};
    b.doc["nodes"][tri]["extensions"] = {{"MSFT_lod", {{"ids", nlohmann::json::array()}}}};
    b.doc["extensionsUsed"] = {"KHR_materials_clearcoat", "MSFT_lod", "KHR_lights_punctual"};
    b.setScene({tri});
    const Scene s = loadGltf(b.writeGlb(dir, "unshown.glb"));
    std::map<std::string, std::string> listed;
    for (const NotShown& n : s.notShown) listed[n.feature] = n.detail;
    EXPECT_EQ(listed.size(), 3u) << "clearcoat, level of detail, BLEND";
    EXPECT_EQ(listed["KHR_materials_clearcoat"],
              "1 material ('foliage'): clear coat is not rendered: the base layer shows alone");
    EXPECT_NE(listed["MSFT_lod"].find("1 node ('node 0')"), std::string::npos) << listed["MSFT_lod"];
    EXPECT_FALSE(listed.count("occlusionTexture")) << "occlusion maps are applied";
    EXPECT_NE(listed["alphaMode BLEND"].find("approximated as a cutout"), std::string::npos);
    EXPECT_EQ(s.materials[0].alphaMode, Material::Alpha::Blend);
    EXPECT_FLOAT_EQ(s.materials[0].cutoff(), 0.5f);
    EXPECT_FALSE(listed.count("COLOR_0")) << "vertex colours are applied";
    // COLOR_0 (here the positions, VEC3): read as RGBA with alpha 1, clamped to [0, 1].
    ASSERT_EQ(s.meshes[0].colors.size(), 3u);
    EXPECT_EQ(s.meshes[0].colors[1], glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
    EXPECT_EQ(s.meshes[0].colors[2], glm::vec4(0.0f, 0.0f, 0.0f, 1.0f)) << "z = -1 clamped to 0";
    EXPECT_FALSE(listed.count("KHR_lights_punctual")) << "read, so shown";

    GltfBuilder plain;
    plain.setScene({plain.addTriangleNode()});
    EXPECT_TRUE(loadGltf(plain.writeGlb(dir, "plain.glb")).notShown.empty());
}

// The base colour texture's UV set and KHR_texture_transform (offset, rotation, scale: T R S as the
// extension defines them) are baked into the mesh's texture coordinates.
TEST(GltfLoader, BaseColorTextureTransformAndUvSetAreApplied) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode();
    const int uv0 = b.addAccessor(b.addView(std::vector<float>{9, 9, 9, 9, 9, 9}), test::kFloat, 3, "VEC2");
    const int uv1 = b.addAccessor(b.addView(std::vector<float>{0, 0, 1, 0, 0, 1}), test::kFloat, 3, "VEC2");
    b.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = uv0;
    b.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_1"] = uv1;
    b.doc["meshes"][0]["primitives"][0]["material"] = 0;
    addTinyTexture(b);
    const double quarterTurn = glm::half_pi<double>();
    b.doc["materials"] = {{{"pbrMetallicRoughness",
                            {{"baseColorTexture",
                              {{"index", 0},
                               {"texCoord", 0},
                               {"extensions",
                                {{"KHR_texture_transform",
                                  {{"offset", {0.5, 0.25}},
                                   {"rotation", quarterTurn},
                                   {"scale", {2.0, 3.0}},
                                   {"texCoord", 1}}}}}}}}}}};
    b.doc["extensionsUsed"] = {"KHR_texture_transform"};
    b.doc["extensionsRequired"] = {"KHR_texture_transform"};
    b.setScene({tri});
    const Scene s = loadGltf(b.writeGlb(dir, "transform.glb"));
    ASSERT_EQ(s.meshes.size(), 1u);
    const auto& t = s.meshes[0].texcoords;
    ASSERT_EQ(t.size(), 3u);
    // TEXCOORD_1 (the transform's texCoord overrides the textureInfo's 0): (0,0), (1,0), (0,1) scaled
    // to (0,0), (2,0), (0,3), turned a quarter counter-clockwise to (0,0), (0,2), (-3,0), then offset.
    const glm::vec2 expected[] = {{0.5f, 0.25f}, {0.5f, 2.25f}, {-2.5f, 0.25f}};
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(t[i].x, expected[i].x, 1e-5f) << i;
        EXPECT_NEAR(t[i].y, expected[i].y, 1e-5f) << i;
    }
    EXPECT_TRUE(s.notShown.empty()) << s.notShown.front().feature;
}

// Metallic-roughness textures are linear data, base colour and emissive textures sRGB colour: one image
// used both ways becomes two textures, flagged accordingly.
TEST(GltfLoader, MetallicRoughnessAndEmissiveTexturesAreRead) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode();
    b.doc["meshes"][0]["primitives"][0]["material"] = 0;
    addTinyTexture(b);
    b.doc["materials"] = {
        {{"pbrMetallicRoughness",
          {{"baseColorTexture", {{"index", 0}}}, {"metallicRoughnessTexture", {{"index", 0}}}}},
         {"emissiveTexture", {{"index", 0}}},
         {"emissiveFactor", {1.0, 1.0, 1.0}}}};
    b.setScene({tri});
    const Scene s = loadGltf(b.writeGlb(dir, "maps.glb"));
    const Material& m = s.materials[0];
    ASSERT_EQ(s.textures.size(), 2u);
    EXPECT_EQ(m.baseColorTexture, m.emissiveTexture) << "both colour: one texture";
    EXPECT_NE(m.metallicRoughnessTexture, m.baseColorTexture);
    EXPECT_TRUE(s.textures[static_cast<size_t>(m.baseColorTexture)].srgb);
    EXPECT_FALSE(s.textures[static_cast<size_t>(m.metallicRoughnessTexture)].srgb);
    EXPECT_EQ(s.textures[0].rgba, s.textures[1].rgba);
    for (const NotShown& n : s.notShown) ADD_FAILURE() << "listed as not shown: " << n.feature;
    EXPECT_TRUE(s.meshes[0].tangents.empty()) << "no normal map, no tangents";
}

// A normal map gets tangents generated from the texture coordinates: unit, orthogonal to the normal,
// along +u, with the bitangent's handedness (glTF's: up the image, along -v).
TEST(GltfLoader, NormalMapGetsTangentsAlongU) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode(); // (0,0,0), (1,0,0), (0,0,-1), facing +y
    // u along +x, v along -z (so that +v runs toward the third vertex).
    const int uv = b.addAccessor(b.addView(std::vector<float>{0, 0, 1, 0, 0, 1}), test::kFloat, 3, "VEC2");
    b.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = uv;
    b.doc["meshes"][0]["primitives"][0]["material"] = 0;
    addTinyTexture(b);
    b.doc["materials"] = {{{"normalTexture", {{"index", 0}, {"scale", 0.5}}}}};
    b.setScene({tri});
    const Scene s = loadGltf(b.writeGlb(dir, "normal.glb"));
    const Material& m = s.materials[0];
    ASSERT_GE(m.normalTexture, 0);
    EXPECT_FALSE(s.textures[static_cast<size_t>(m.normalTexture)].srgb);
    EXPECT_FLOAT_EQ(m.normalScale, 0.5f);
    const Mesh& mesh = s.meshes[0];
    ASSERT_EQ(mesh.tangents.size(), 3u);
    for (const glm::vec4& t : mesh.tangents) {
        EXPECT_NEAR(t.x, 1.0f, 1e-5f);
        EXPECT_NEAR(t.y, 0.0f, 1e-5f);
        EXPECT_NEAR(t.z, 0.0f, 1e-5f);
        // b = w cross(n, t) = w cross(+y, +x) = -w z must run along -v (up the image: glTF's v runs
        // down it, a normal map's +y up), i.e. +z: w = -1.
        EXPECT_EQ(t.w, -1.0f);
    }
    EXPECT_TRUE(s.notShown.empty());
}

// Against another tool's tangents: the corpus box with its checker as a normal map and MikkTSpace
// tangents from glTF Transform (tests/data/corpus/compress.sh). The tangents generated when the file
// has none point the same way and have the same handedness at every vertex.
TEST(GltfLoader, GeneratedTangentsAgreeWithMikkTSpace) {
    const std::string path =
        std::string(GIS_SOURCE_DIR) + "/tests/data/corpus/textured_box_normalmap_mikk.glb";
    const Scene withFile = loadGltf(path);
    // The same file without its TANGENT attribute, as a GltfBuilder holding its JSON and binary chunk.
    std::ifstream in(path, std::ios::binary);
    const std::vector<std::uint8_t> glb((std::istreambuf_iterator<char>(in)),
                                        std::istreambuf_iterator<char>());
    ASSERT_GT(glb.size(), 28u);
    auto u32 = [&](std::size_t at) {
        return std::uint32_t(glb[at]) | std::uint32_t(glb[at + 1]) << 8 | std::uint32_t(glb[at + 2]) << 16 |
               std::uint32_t(glb[at + 3]) << 24;
    };
    const std::size_t jsonLength = u32(12);
    GltfBuilder b;
    b.doc =
        nlohmann::json::parse(glb.begin() + 20, glb.begin() + 20 + static_cast<std::ptrdiff_t>(jsonLength));
    b.bin.assign(glb.begin() + 28 + static_cast<std::ptrdiff_t>(jsonLength), glb.end());
    for (auto& mesh : b.doc["meshes"])
        for (auto& primitive : mesh["primitives"]) ASSERT_EQ(primitive["attributes"].erase("TANGENT"), 1u);
    TempDir dir;
    const Scene generated = loadGltf(b.writeGlb(dir, "no_tangents.glb"));

    ASSERT_EQ(withFile.meshes.size(), generated.meshes.size());
    int vertices = 0, sameSide = 0, sameHandedness = 0;
    for (std::size_t m = 0; m < withFile.meshes.size(); ++m) {
        const auto &a = withFile.meshes[m].tangents, &g = generated.meshes[m].tangents;
        ASSERT_EQ(a.size(), g.size());
        for (std::size_t i = 0; i < a.size(); ++i) {
            ++vertices;
            sameSide += glm::dot(glm::vec3(a[i]), glm::vec3(g[i])) > 0.99f ? 1 : 0;
            sameHandedness += a[i].w == g[i].w ? 1 : 0;
        }
    }
    EXPECT_GT(vertices, 0);
    EXPECT_EQ(sameSide, vertices);
    EXPECT_EQ(sameHandedness, vertices);
}

// glTF doubleSided: false unless the file says true (the built-in scenes' materials are double-sided).
TEST(GltfLoader, DoubleSidedFollowsTheFile) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode();
    b.doc["meshes"][0]["primitives"][0]["material"] = 0;
    b.doc["materials"] = {{{"name", "one"}}, {{"name", "two"}, {"doubleSided", true}}};
    b.setScene({tri});
    const Scene s = loadGltf(b.writeGlb(dir, "sides.glb"));
    ASSERT_GE(s.materials.size(), 2u);
    EXPECT_FALSE(s.materials[0].doubleSided);
    EXPECT_TRUE(s.materials[1].doubleSided);
    EXPECT_TRUE(makeBuiltinScene("cornell").materials[0].doubleSided);
}

// The file's own TANGENT attribute is used where it maps normals (not regenerated), carried through
// the node's transform: a mirror flips the handedness; a zero tangent stays zero (unmapped there).
TEST(GltfLoader, NormalMapUsesTheFilesTangents) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode(); // facing +y
    const int uv = b.addAccessor(b.addView(std::vector<float>{0, 0, 1, 0, 0, 1}), test::kFloat, 3, "VEC2");
    // Deliberately not what generation would give (+x): the file's (0, 0, 1) and (0, 0, 0).
    const int tangents = b.addAccessor(b.addView(std::vector<float>{0, 0, 1, 1, 0, 0, 1, -1, 0, 0, 0, 1}),
                                       test::kFloat, 3, "VEC4");
    auto& prim = b.doc["meshes"][0]["primitives"][0];
    prim["attributes"]["TEXCOORD_0"] = uv;
    prim["attributes"]["TANGENT"] = tangents;
    prim["material"] = 0;
    addTinyTexture(b);
    b.doc["materials"] = {{{"normalTexture", {{"index", 0}}}}};
    b.doc["nodes"][static_cast<std::size_t>(tri)]["scale"] = {-2.0, 1.0, 1.0}; // a mirror in x
    b.setScene({tri});
    const Scene s = loadGltf(b.writeGlb(dir, "tangents.glb"));
    const Mesh& mesh = s.meshes[0];
    ASSERT_EQ(mesh.tangents.size(), 3u);
    EXPECT_EQ(mesh.tangents[0], glm::vec4(0, 0, 1, -1)) << "mirrored: w flips";
    EXPECT_EQ(mesh.tangents[1], glm::vec4(0, 0, 1, 1));
    EXPECT_EQ(mesh.tangents[2], glm::vec4(0.0f)) << "a zero tangent leaves that vertex unmapped";

    // Without a normal map the attribute is not needed and not kept.
    b.doc["materials"] = {{{"name", "plain"}}};
    EXPECT_TRUE(loadGltf(b.writeGlb(dir, "plain.glb")).meshes[0].tangents.empty());
}

TEST(GltfLoader, SpecularFactorDefaultsToGltfsDielectricAndReadsTheExtension) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode();
    b.doc["meshes"][0]["primitives"][0]["material"] = 0;
    b.doc["materials"] = {
        {{"name", "plain"}},
        {{"name", "matte"}, {"extensions", {{"KHR_materials_specular", {{"specularFactor", 0.0}}}}}},
        {{"name", "half"}, {"extensions", {{"KHR_materials_specular", {{"specularFactor", 0.5}}}}}}};
    b.doc["extensionsUsed"] = {"KHR_materials_specular"};
    b.doc["extensionsRequired"] = {"KHR_materials_specular"}; // supported, so accepted
    b.setScene({tri});
    const Scene s = loadGltf(b.writeGltf(dir, "specular.gltf"));
    ASSERT_GE(s.materials.size(), 3u);
    EXPECT_FLOAT_EQ(s.materials[0].specular, 1.0f); // glTF: every dielectric reflects F0 = 0.04
    EXPECT_FLOAT_EQ(s.materials[1].specular, 0.0f); // exactly Lambertian (scene/Brdf.h)
    EXPECT_FLOAT_EQ(s.materials[2].specular, 0.5f);
}

TEST(GltfLoader, InterleavedStrideAndNormalizedTexcoords) {
    TempDir dir;
    GltfBuilder b;
    // Position and normal interleaved: 24-byte stride.
    const std::vector<float> interleaved = {0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 1, 0, 0, 0, -1, 0, 1, 0};
    const int view = b.addView(interleaved, 24);
    const int pos = b.addAccessor(view, test::kFloat, 3, "VEC3");
    const int nrm = b.addAccessor(view, test::kFloat, 3, "VEC3", {{"byteOffset", 12}});
    const std::vector<std::uint8_t> uv8 = {0, 255, 255, 0, 51, 102};
    const int uv = b.addAccessor(b.addView(uv8), test::kUnsignedByte, 3, "VEC2", {{"normalized", true}});
    const int mesh =
        b.addMesh("il", {{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}, {"TEXCOORD_0", uv}}}});
    b.setScene({b.addNode({{"mesh", mesh}})});
    const Scene s = loadGltf(b.writeGlb(dir, "interleaved.glb"));
    const Mesh& m = s.meshes[0];
    expectNear(m.positions[1], {1, 0, 0});
    expectNear(m.normals[2], {0, 1, 0});
    ASSERT_EQ(m.texcoords.size(), 3u);
    EXPECT_FLOAT_EQ(m.texcoords[0].y, 1.0f);
    EXPECT_FLOAT_EQ(m.texcoords[2].x, 0.2f);
    EXPECT_FLOAT_EQ(m.texcoords[2].y, 0.4f);
}

TEST(GltfLoader, StripsAreConvertedAndLinesSkipped) {
    TempDir dir;
    GltfBuilder b;
    const int pos = b.addVec3s({{0, 0, 0}, {1, 0, 0}, {0, 0, -1}, {1, 0, -1}});
    const int strip = b.addMesh("strip", {{"attributes", {{"POSITION", pos}}}, {"mode", 5}});
    const int lines = b.addMesh("lines", {{"attributes", {{"POSITION", pos}}}, {"mode", 1}});
    b.setScene({b.addNode({{"mesh", strip}}), b.addNode({{"mesh", lines}})});
    const Scene s = loadGltf(b.writeGlb(dir, "strip.glb"));
    ASSERT_EQ(s.meshes.size(), 1u);
    const Mesh& m = s.meshes[0];
    ASSERT_EQ(m.indices.size(), 6u);
    for (std::size_t t = 0; t < 6; t += 3) {
        const glm::vec3 n = glm::cross(m.positions[m.indices[t + 1]] - m.positions[m.indices[t]],
                                       m.positions[m.indices[t + 2]] - m.positions[m.indices[t]]);
        EXPECT_GT(n.y, 0.0f) << "triangle " << t / 3;
    }
}

TEST(SceneLoader, DispatchesOnPrefixAndExtension) {
    TempDir dir;
    GltfBuilder b;
    b.setScene({b.addTriangleNode()});
    EXPECT_EQ(loadScene(b.writeGltf(dir, "UPPER.GLTF")).meshes.size(), 1u);
    EXPECT_EQ(loadScene("builtin:crease").name, "builtin:crease");
    try {
        loadScene("model.obj");
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("model.obj"), std::string::npos) << what;
        EXPECT_NE(what.find("builtin:"), std::string::npos) << what;
        EXPECT_NE(what.find(".gltf"), std::string::npos) << what;
        EXPECT_NE(what.find(".glb"), std::string::npos) << what;
    }
}

} // namespace
} // namespace gis
