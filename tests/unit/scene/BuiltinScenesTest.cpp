#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "scene/SceneLoader.h"

namespace gis {
namespace {

const Mesh* findMesh(const Scene& s, const std::string& name) {
    const auto it =
        std::find_if(s.meshes.begin(), s.meshes.end(), [&](const Mesh& m) { return m.name == name; });
    return it == s.meshes.end() ? nullptr : &*it;
}

void expectNear(const glm::vec3& a, const glm::vec3& b, float eps = 1e-5f) {
    EXPECT_NEAR(a.x, b.x, eps);
    EXPECT_NEAR(a.y, b.y, eps);
    EXPECT_NEAR(a.z, b.z, eps);
}

TEST(BuiltinScenes, NamesList) {
    EXPECT_EQ(builtinSceneNames(), (std::vector<std::string>{
                                       "cornell", "cornell-empty", "cornell-dense", "crease", "cornell-black",
                                       "gallery", "cornell-point", "sun-room", "cornell-colored", "atrium"}));
}

TEST(BuiltinScenes, AtriumIsBigTexturedAndCutOut) {
    const Scene atrium = loadScene("builtin:atrium");
    EXPECT_GE(atrium.triangleCount(), 500000u);
    EXPECT_GE(atrium.textures.size(), 3u);
    int masked = 0, textured = 0;
    for (const Material& m : atrium.materials) {
        masked += m.alphaMode == Material::Alpha::Mask ? 1 : 0;
        textured += m.baseColorTexture >= 0 ? 1 : 0;
    }
    EXPECT_GE(masked, 2);
    EXPECT_GE(textured, 3);
    // The cutout textures are partly transparent, partly opaque.
    for (const TextureImage& t : atrium.textures) {
        if (t.name == "stone_tiles") continue;
        int transparent = 0, opaque = 0;
        for (std::size_t i = 3; i < t.rgba.size(); i += 4) (t.rgba[i] < 128 ? transparent : opaque) += 1;
        EXPECT_GT(transparent, 0) << t.name;
        EXPECT_GT(opaque, 0) << t.name;
    }
    // The 16 x 9 x 12 m courtyard: the scene-relative knobs' unit is its 16 m.
    EXPECT_NEAR(atrium.bounds.longestSide(), 16.0f, 1e-3f);
}

TEST(BuiltinScenes, AtriumSizesForTheBenchmarks) {
    for (const auto& [name, target] :
         {std::pair{"atrium-10k", 10000.0}, {"atrium-100k", 100000.0}, {"atrium-2000k", 2000000.0}}) {
        const Scene s = loadScene(std::string("builtin:") + name);
        const double ratio = static_cast<double>(s.triangleCount()) / target;
        EXPECT_GT(ratio, 0.75) << name << ": " << s.triangleCount();
        EXPECT_LT(ratio, 1.35) << name << ": " << s.triangleCount();
    }
    for (const char* bad :
         {"atrium-0k", "atrium-k", "atrium-01k", "atrium-10", "atrium-99999k", "atrium-1.5k"})
        EXPECT_THROW(makeBuiltinScene(bad), InputError) << bad;
}

TEST(BuiltinScenes, LightScenesHaveTheirLightTypes) {
    const Scene point = makeBuiltinScene("cornell-point");
    ASSERT_EQ(point.lights.size(), 1u);
    EXPECT_EQ(point.lights[0].type, LightType::Point);
    const Scene sun = makeBuiltinScene("sun-room");
    ASSERT_EQ(sun.lights.size(), 1u);
    EXPECT_EQ(sun.lights[0].type, LightType::Directional);
    // The room is closed but for the skylight: a ray from the camera's position towards the sun leaves
    // only through it, so the camera's position is inside the bounds.
    EXPECT_TRUE(glm::all(glm::greaterThan(sun.cameras[0].position, sun.bounds.min)));
    EXPECT_TRUE(glm::all(glm::lessThan(sun.cameras[0].position, sun.bounds.max)));
    const Scene colored = makeBuiltinScene("cornell-colored");
    ASSERT_EQ(colored.lights.size(), 3u);
    EXPECT_EQ(colored.lights[0].type, LightType::Spot);
    EXPECT_EQ(colored.lights[1].type, LightType::Point);
    EXPECT_EQ(colored.lights[2].type, LightType::Directional);
    for (const Light& l : colored.lights) EXPECT_NE(l.color, glm::vec3(1.0f)) << l.name << " is coloured";
}

TEST(BuiltinScenes, GalleryHasEachNonDiffuseMaterial) {
    const Scene g = makeBuiltinScene("gallery");
    auto material = [&](const std::string& mesh) -> const Material& {
        for (const Mesh& m : g.meshes)
            if (m.name == mesh) return g.materials[static_cast<size_t>(m.material)];
        ADD_FAILURE() << "no mesh " << mesh;
        return g.materials.front();
    };
    EXPECT_EQ(material("mirror").metallic, 1.0f);
    EXPECT_EQ(material("mirror").roughness, 0.0f);
    EXPECT_LT(material("gold_sphere").roughness, 0.35f);  // environment probe
    EXPECT_GE(material("copper_block").roughness, 0.35f); // glossy VPL transport
    EXPECT_GT(material("floor").specular, 0.0f);
    EXPECT_EQ(material("back_wall").specular, 0.0f); // Lambertian
}

TEST(BuiltinScenes, CornellBlackIsTheEmptyBoxWithDarkWalls) {
    const Scene black = makeBuiltinScene("cornell-black");
    const Scene empty = makeBuiltinScene("cornell-empty");
    ASSERT_EQ(black.meshes.size(), empty.meshes.size());
    for (std::size_t i = 0; i < black.meshes.size(); ++i)
        EXPECT_EQ(black.meshes[i].positions, empty.meshes[i].positions);
    for (const Material& m : black.materials) {
        EXPECT_GT(m.baseColor.r, 0.0f) << m.name; // dark, not absent
        EXPECT_LE(glm::max(m.baseColor.r, glm::max(m.baseColor.g, m.baseColor.b)), 0.01f) << m.name;
    }
    EXPECT_EQ(black.lights.size(), 1u);
}

TEST(BuiltinScenes, EachBuildsAndValidates) {
    for (const auto& name : builtinSceneNames()) {
        SCOPED_TRACE(name);
        const Scene s = loadScene("builtin:" + name);
        EXPECT_EQ(s.name, "builtin:" + name);
        EXPECT_NO_THROW(validateScene(s, s.name));
        EXPECT_GT(s.triangleCount(), 0u);
        EXPECT_GE(s.lights.size(), 1u);
        ASSERT_EQ(s.cameras.size(), 1u);
        EXPECT_EQ(s.cameras[0].name, "default");
        for (const Mesh& m : s.meshes) {
            EXPECT_EQ(m.texcoords.size(), m.positions.size()) << m.name;
            // Winding is CCW seen from the side the stored normal points to.
            for (std::size_t t = 0; t < m.indices.size(); t += 3) {
                const glm::vec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]],
                                c = m.positions[m.indices[t + 2]];
                ASSERT_GT(glm::dot(glm::cross(b - a, c - a), m.normals[m.indices[t]]), 0.0f)
                    << m.name << " triangle " << t / 3;
            }
        }
    }
}

TEST(BuiltinScenes, CornellRoomMaterialsLightAndCamera) {
    const Scene s = makeBuiltinScene("cornell");
    expectNear(s.bounds.min, {-1, 0, -1});
    expectNear(s.bounds.max, {1, 2, 1});

    const Mesh* left = findMesh(s, "left_wall");
    ASSERT_NE(left, nullptr);
    for (const auto& p : left->positions) EXPECT_FLOAT_EQ(p.x, -1.0f);
    for (const auto& n : left->normals) expectNear(n, {1, 0, 0});
    EXPECT_EQ(s.materials[static_cast<std::size_t>(left->material)].name, "red");
    EXPECT_EQ(s.materials[static_cast<std::size_t>(left->material)].baseColor,
              glm::vec4(0.63f, 0.065f, 0.05f, 1.0f));
    EXPECT_GE(left->indices.size() / 3, 128u); // subdivided, not one quad

    const Mesh* right = findMesh(s, "right_wall");
    ASSERT_NE(right, nullptr);
    for (const auto& n : right->normals) expectNear(n, {-1, 0, 0});
    EXPECT_EQ(s.materials[static_cast<std::size_t>(right->material)].name, "green");
    for (const char* white : {"floor", "ceiling", "back_wall", "short_box", "tall_box"}) {
        const Mesh* m = findMesh(s, white);
        ASSERT_NE(m, nullptr) << white;
        EXPECT_EQ(s.materials[static_cast<std::size_t>(m->material)].name, "white") << white;
    }
    EXPECT_EQ(findMesh(s, "front_wall"), nullptr);

    ASSERT_EQ(s.lights.size(), 1u);
    const Light& l = s.lights[0];
    EXPECT_EQ(l.name, "ceiling_spot");
    EXPECT_EQ(l.type, LightType::Spot);
    expectNear(l.position, {0, 1.95f, 0});
    expectNear(l.direction, {0, -1, 0});
    EXPECT_FLOAT_EQ(l.intensity, 6.0f);
    EXPECT_NEAR(l.innerConeAngle, glm::radians(50.0f), 1e-6f);
    EXPECT_NEAR(l.outerConeAngle, glm::radians(60.0f), 1e-6f);

    const Camera& c = s.cameras[0];
    expectNear(c.position, {0, 1, 3.9f});
    expectNear(c.target, {0, 1, 0});
    EXPECT_NEAR(c.yfovRadians, glm::radians(40.0f), 1e-6f);
    EXPECT_FLOAT_EQ(c.znear, 0.05f);
    EXPECT_FLOAT_EQ(c.zfar, 20.0f);
}

TEST(BuiltinScenes, BoxesFaceOutwardAndSitOnTheFloor) {
    const Scene s = makeBuiltinScene("cornell");
    const struct {
        const char* name;
        glm::vec3 center;
        float height;
    } boxes[] = {{"short_box", {0.35f, 0.3f, 0.3f}, 0.6f}, {"tall_box", {-0.35f, 0.6f, -0.35f}, 1.2f}};
    for (const auto& box : boxes) {
        const Mesh* m = findMesh(s, box.name);
        ASSERT_NE(m, nullptr) << box.name;
        float minY = 10.0f, maxY = -10.0f;
        for (const auto& p : m->positions) {
            minY = std::min(minY, p.y);
            maxY = std::max(maxY, p.y);
        }
        EXPECT_NEAR(minY, 0.0f, 1e-5f) << box.name;
        EXPECT_NEAR(maxY, box.height, 1e-5f) << box.name;
        for (std::size_t t = 0; t < m->indices.size(); t += 3) {
            const glm::vec3 centroid = (m->positions[m->indices[t]] + m->positions[m->indices[t + 1]] +
                                        m->positions[m->indices[t + 2]]) /
                                       3.0f;
            EXPECT_GT(glm::dot(m->normals[m->indices[t]], centroid - box.center), 0.0f) << box.name;
        }
    }
}

TEST(BuiltinScenes, CornellEmptyHasNoBoxes) {
    const Scene s = makeBuiltinScene("cornell-empty");
    EXPECT_EQ(s.meshes.size(), 5u);
    EXPECT_EQ(findMesh(s, "short_box"), nullptr);
    EXPECT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].name, "ceiling_spot");
}

TEST(BuiltinScenes, CornellDenseIsTheCornellRoomWithOneDenseObject) {
    const Scene s = makeBuiltinScene("cornell-dense");
    const Scene cornell = makeBuiltinScene("cornell");
    EXPECT_EQ(s.meshes.size(), 6u);
    EXPECT_EQ(findMesh(s, "short_box"), nullptr);
    EXPECT_EQ(findMesh(s, "tall_box"), nullptr);
    for (const char* wall : {"floor", "ceiling", "back_wall", "left_wall", "right_wall"}) {
        const Mesh *a = findMesh(s, wall), *b = findMesh(cornell, wall);
        ASSERT_NE(a, nullptr) << wall;
        ASSERT_NE(b, nullptr) << wall;
        EXPECT_EQ(a->positions, b->positions) << wall;
        EXPECT_EQ(s.materials[static_cast<std::size_t>(a->material)].baseColor,
                  cornell.materials[static_cast<std::size_t>(b->material)].baseColor)
            << wall;
    }
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].name, "ceiling_spot");
    expectNear(s.lights[0].position, cornell.lights[0].position);
    expectNear(s.cameras[0].position, cornell.cameras[0].position);
    expectNear(s.cameras[0].target, cornell.cameras[0].target);

    const Mesh* obj = findMesh(s, "bumpy_sphere");
    ASSERT_NE(obj, nullptr);
    EXPECT_EQ(s.materials[static_cast<std::size_t>(obj->material)].name, "white");
    const std::size_t triangles = obj->indices.size() / 3;
    EXPECT_GT(triangles, 30000u);
    EXPECT_LT(triangles, 100000u);
    EXPECT_GT(s.triangleCount(), 30000u);
    glm::vec3 lo(1e9f), hi(-1e9f);
    for (std::size_t k = 0; k < obj->positions.size(); ++k) {
        const glm::vec3& p = obj->positions[k];
        const glm::vec3& n = obj->normals[k];
        ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) << k;
        ASSERT_TRUE(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z)) << k;
        ASSERT_NEAR(glm::length(n), 1.0f, 1e-4f) << k;
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    // Inside the room, standing on the floor, centred, and well away from the walls.
    EXPECT_NEAR(lo.y, 0.0f, 1e-6f);
    EXPECT_LT(hi.y, 1.5f);
    EXPECT_GT(lo.x, -0.9f);
    EXPECT_LT(hi.x, 0.9f);
    EXPECT_GT(lo.z, -0.9f);
    EXPECT_LT(hi.z, 0.9f);
    expectNear(s.bounds.min, {-1, 0, -1});
    expectNear(s.bounds.max, {1, 2, 1});

    // Smooth: neighbouring vertex normals vary, i.e. the surface is really bumpy, not a plain sphere.
    float minDot = 1.0f;
    for (std::size_t t = 0; t < obj->indices.size(); t += 3)
        minDot = std::min(minDot, glm::dot(obj->normals[obj->indices[t]], obj->normals[obj->indices[t + 1]]));
    EXPECT_LT(minDot, 0.9f);

    // Deterministic: a second build is bit-identical.
    const Scene again = makeBuiltinScene("cornell-dense");
    const Mesh* obj2 = findMesh(again, "bumpy_sphere");
    ASSERT_NE(obj2, nullptr);
    EXPECT_EQ(obj->positions, obj2->positions);
    EXPECT_EQ(obj->normals, obj2->normals);
    EXPECT_EQ(obj->indices, obj2->indices);
}

TEST(BuiltinScenes, CreaseLightAimsAtTheCrease) {
    const Scene s = makeBuiltinScene("crease");
    EXPECT_EQ(s.meshes.size(), 2u);
    const Light& l = s.lights[0];
    expectNear(l.position, {0.2f, 1.5f, 0});
    expectNear(l.direction, glm::normalize(glm::vec3(-1, -1, 0)));
    EXPECT_NEAR(l.innerConeAngle, glm::radians(40.0f), 1e-6f);
    EXPECT_NEAR(l.outerConeAngle, glm::radians(50.0f), 1e-6f);
    expectNear(s.cameras[0].position, {1.6f, 1.2f, 2.8f});
    expectNear(s.cameras[0].target, {-0.6f, 0.4f, 0});
    EXPECT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].baseColor, glm::vec4(0.8f, 0.8f, 0.8f, 1.0f));
}

TEST(BuiltinScenes, UnknownNameListsKnownNames) {
    for (const auto& call : {+[] { makeBuiltinScene("teapot"); }, +[] { loadScene("builtin:teapot"); }}) {
        try {
            call();
            FAIL() << "expected InputError";
        } catch (const InputError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find("teapot"), std::string::npos) << what;
            for (const auto& n : builtinSceneNames()) EXPECT_NE(what.find(n), std::string::npos) << what;
        }
    }
}

} // namespace
} // namespace gis
