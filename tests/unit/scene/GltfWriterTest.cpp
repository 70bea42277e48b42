// gi-render --export's writer: a scene written as .glb and read back by the loader is the same
// scene (geometry, materials, textures, cutouts, lights, camera).
#include "scene/GltfWriter.h"

#include <gtest/gtest.h>

#include "GltfBuilder.h"
#include "core/Error.h"
#include "scene/SceneLoader.h"

namespace gis {
namespace {

void expectNear(const glm::vec3& a, const glm::vec3& b, float eps, const std::string& what) {
    EXPECT_LE(glm::length(a - b), eps) << what << ": (" << a.x << ", " << a.y << ", " << a.z << ") vs ("
                                       << b.x << ", " << b.y << ", " << b.z << ")";
}

Scene roundTrip(const Scene& scene, const test::TempDir& dir) {
    const std::string path = dir.file("scene.glb");
    writeGlb(scene, path);
    return loadScene(path);
}

TEST(GltfWriter, InstancesStayInstances) {
    const test::TempDir dir;
    const Scene original = loadScene(std::string(GIS_SOURCE_DIR) + "/tests/data/corpus/colonnade.glb");
    ASSERT_EQ(original.instanceCount(), 12u);
    const Scene back = roundTrip(original, dir);
    EXPECT_EQ(back.instanceCount(), 12u);
    EXPECT_EQ(back.storedTriangleCount(), original.storedTriangleCount());
    EXPECT_EQ(back.triangleCount(), original.triangleCount());
    expectNear(back.bounds.min, original.bounds.min, 1e-5f, "bounds min");
    expectNear(back.bounds.max, original.bounds.max, 1e-5f, "bounds max");
}

TEST(GltfWriter, BuiltinScenesReadBackTheSame) {
    for (const char* name : {"builtin:cornell-colored", "builtin:gallery", "builtin:atrium-10k"}) {
        SCOPED_TRACE(name);
        const test::TempDir dir;
        const Scene original = loadScene(name);
        const Scene back = roundTrip(original, dir);

        EXPECT_EQ(back.triangleCount(), original.triangleCount());
        ASSERT_EQ(back.meshes.size(), original.meshes.size());
        for (std::size_t m = 0; m < original.meshes.size(); ++m) {
            const Mesh &a = original.meshes[m], &b = back.meshes[m];
            EXPECT_EQ(b.name, a.name);
            ASSERT_EQ(b.positions.size(), a.positions.size()) << a.name;
            EXPECT_EQ(b.indices, a.indices) << a.name;
            for (std::size_t i = 0; i < a.positions.size(); i += 97)
                expectNear(b.positions[i], a.positions[i], 1e-6f, a.name);
            EXPECT_EQ(b.texcoords, a.texcoords) << a.name;
            const Material &ma = original.materials[static_cast<std::size_t>(a.material)],
                           &mb = back.materials[static_cast<std::size_t>(b.material)];
            EXPECT_EQ(mb.name, ma.name);
            EXPECT_EQ(mb.baseColor, ma.baseColor) << ma.name;
            EXPECT_EQ(mb.metallic, ma.metallic) << ma.name;
            EXPECT_EQ(mb.roughness, ma.roughness) << ma.name;
            EXPECT_EQ(mb.alphaMode, ma.alphaMode) << ma.name;
            EXPECT_EQ(mb.doubleSided, ma.doubleSided) << ma.name;
            EXPECT_EQ(mb.baseColorTexture >= 0, ma.baseColorTexture >= 0) << ma.name;
            if (ma.baseColorTexture >= 0 && mb.baseColorTexture >= 0) {
                const TextureImage &ta = original.textures[static_cast<std::size_t>(ma.baseColorTexture)],
                                   &tb = back.textures[static_cast<std::size_t>(mb.baseColorTexture)];
                EXPECT_EQ(tb.rgba, ta.rgba) << ta.name << ": PNG is lossless";
            }
        }
        ASSERT_EQ(back.lights.size(), original.lights.size());
        for (std::size_t l = 0; l < original.lights.size(); ++l) {
            const Light &a = original.lights[l], &b = back.lights[l];
            EXPECT_EQ(b.type, a.type) << a.name;
            EXPECT_FLOAT_EQ(b.intensity, a.intensity) << a.name;
            expectNear(b.direction, a.direction, 1e-5f, a.name + " direction");
            if (a.type != LightType::Directional) {
                expectNear(b.position, a.position, 1e-6f, a.name + " position");
            }
            if (a.type == LightType::Spot) {
                EXPECT_NEAR(b.outerConeAngle, a.outerConeAngle, 1e-6f) << a.name;
            }
        }
        ASSERT_FALSE(back.cameras.empty());
        const Camera &ca = original.cameras.front(), &cb = back.cameras.front();
        expectNear(cb.position, ca.position, 1e-5f, "camera position");
        expectNear(glm::normalize(cb.target - cb.position), glm::normalize(ca.target - ca.position), 1e-5f,
                   "camera direction");
        EXPECT_NEAR(cb.yfovRadians, ca.yfovRadians, 1e-6f);
    }
}

TEST(GltfWriter, RefusesAPathItCannotWrite) {
    const Scene s = loadScene("builtin:crease");
    EXPECT_THROW(writeGlb(s, "/nonexistent-directory/scene.glb"), Error);
}

} // namespace
} // namespace gis
