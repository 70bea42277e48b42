// Every bad input must surface as a gis::InputError whose message names the file and the problem.
#include <cmath>
#include <functional>

#include <gtest/gtest.h>

#include "GltfBuilder.h"
#include "core/Error.h"
#include "scene/SceneLoader.h"

namespace gis {
namespace {

using test::GltfBuilder;
using test::TempDir;

/// Loads path, expecting an InputError whose what() contains the path and every fragment.
void expectInputError(const std::string& path, const std::vector<std::string>& fragments) {
    try {
        loadGltf(path);
        ADD_FAILURE() << path << ": expected InputError";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_EQ(e.where(), path);
        EXPECT_NE(what.find(path), std::string::npos) << what;
        for (const auto& f : fragments)
            EXPECT_NE(what.find(f), std::string::npos) << "'" << f << "' in: " << what;
    } catch (const std::exception& e) {
        ADD_FAILURE() << path << ": wrong exception type: " << e.what();
    }
}

TEST(GltfErrors, MissingFile) {
    TempDir dir;
    expectInputError(dir.file("absent.gltf"), {"file not found"});
    expectInputError(dir.file("absent.glb"), {"file not found"});
}

TEST(GltfErrors, MalformedJson) {
    TempDir dir;
    const std::string path = dir.file("broken.gltf");
    test::writeText(path, R"({"asset": {"version": "2.0"}, "nodes": [ {)");
    expectInputError(path, {"JSON"});
}

TEST(GltfErrors, TruncatedGlb) {
    TempDir dir;
    GltfBuilder b;
    b.setScene({b.addTriangleNode()});
    std::vector<std::uint8_t> bytes = b.glbBytes();
    bytes.resize(bytes.size() - 10);
    const std::string path = dir.file("truncated.glb");
    test::writeBytes(path, bytes);
    expectInputError(path, {"truncated GLB"});
}

TEST(GltfErrors, GlbExtensionOnJsonContent) {
    TempDir dir;
    GltfBuilder b;
    b.setScene({b.addTriangleNode()});
    const std::string gltf = b.writeGltf(dir, "text.gltf");
    const std::string path = dir.file("text.glb");
    std::filesystem::copy_file(gltf, path);
    expectInputError(path, {"magic"});
}

TEST(GltfErrors, IndexValueOutOfRange) {
    TempDir dir;
    GltfBuilder b;
    const int pos = b.addVec3s({{0, 0, 0}, {1, 0, 0}, {0, 0, -1}});
    const int idx = b.addIndices(std::vector<std::uint16_t>{0, 1, 7}, test::kUnsignedShort);
    b.setScene({b.addNode(
        {{"mesh", b.addMesh("bad_tri", {{"attributes", {{"POSITION", pos}}}, {"indices", idx}})}})});
    expectInputError(b.writeGlb(dir, "index.glb"),
                     {"mesh 'bad_tri'", "index 7", "out of range", "3 vertices"});
}

TEST(GltfErrors, AccessorPastTheEndOfItsBufferView) {
    TempDir dir;
    GltfBuilder b;
    const std::vector<glm::vec3> three = {{0, 0, 0}, {1, 0, 0}, {0, 0, -1}};
    const int pos = b.addAccessor(b.addView(three), test::kFloat, 10, "VEC3");
    b.setScene({b.addNode({{"mesh", b.addMesh("long", {{"attributes", {{"POSITION", pos}}}})}})});
    expectInputError(b.writeGlb(dir, "accessor.glb"),
                     {"mesh 'long'", "accessor 0", "past the end of bufferView 0"});
}

TEST(GltfErrors, AccessorOffsetPastTheEnd) {
    TempDir dir;
    GltfBuilder b;
    const std::vector<glm::vec3> three = {{0, 0, 0}, {1, 0, 0}, {0, 0, -1}};
    const int pos = b.addAccessor(b.addView(three), test::kFloat, 3, "VEC3", {{"byteOffset", 4}});
    b.setScene({b.addNode({{"mesh", b.addMesh("shifted", {{"attributes", {{"POSITION", pos}}}})}})});
    expectInputError(b.writeGltf(dir, "offset.gltf"), {"accessor 0", "past the end"});
}

TEST(GltfErrors, BufferViewPastTheEndOfItsBuffer) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode();
    b.doc["bufferViews"][0]["byteOffset"] = 4096;
    b.setScene({tri});
    expectInputError(b.writeGlb(dir, "view.glb"), {"bufferView 0", "past the end of buffer 0"});
}

TEST(GltfErrors, NanPosition) {
    TempDir dir;
    GltfBuilder b;
    const int pos = b.addVec3s({{0, 0, 0}, {std::nanf(""), 0, 0}, {0, 0, -1}});
    b.setScene({b.addNode({{"mesh", b.addMesh("nan_tri", {{"attributes", {{"POSITION", pos}}}})}})});
    expectInputError(b.writeGlb(dir, "nan.glb"), {"mesh 'nan_tri'", "position 1 is not finite"});
}

TEST(GltfErrors, InfinitePositionThroughTransform) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode("huge");
    b.doc["nodes"][tri]["scale"] = {1e38, 1e38, 1e38};
    b.doc["nodes"][tri]["translation"] = {3e38, 0, 0};
    b.setScene({tri});
    expectInputError(b.writeGltf(dir, "inf.gltf"), {"mesh 'huge'", "not finite"});
}

TEST(GltfErrors, UnsupportedRequiredExtension) {
    TempDir dir;
    GltfBuilder b;
    b.setScene({b.addTriangleNode()});
    b.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_texture_basisu"};
    b.doc["extensionsRequired"] = {"KHR_lights_punctual", "KHR_texture_basisu"};
    expectInputError(b.writeGltf(dir, "ktx2.gltf"),
                     {"unsupported required extension 'KHR_texture_basisu'", "KTX2", "PNG or JPEG"});
    b.doc["extensionsRequired"] = {"EXT_texture_webp"};
    expectInputError(b.writeGlb(dir, "webp.glb"), {"'EXT_texture_webp'", "PNG or JPEG"});
    b.doc["extensionsRequired"] = {"KHR_materials_volume_future"};
    expectInputError(b.writeGlb(dir, "other.glb"),
                     {"'KHR_materials_volume_future'", "it reads KHR_lights_punctual",
                      "KHR_mesh_quantization", "decodes KHR_draco_mesh_compression"});
    // Draco and meshopt are decoded: a file that requires them but compresses nothing loads.
    b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression", "EXT_meshopt_compression"};
    EXPECT_NO_THROW(loadGltf(b.writeGlb(dir, "listed_only.glb")));
}

// A Draco extension whose stream is not Draco (here: the positions' plain floats) is refused by its
// path; the parser used to say "accessor[0] invalid bufferView".
TEST(GltfErrors, DracoPrimitiveThatDoesNotDecodeNamesTheExtension) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode("squeezed");
    b.doc["accessors"][0].erase("bufferView");
    b.doc["meshes"][0]["primitives"][0]["extensions"] = {
        {"KHR_draco_mesh_compression", {{"bufferView", 0}, {"attributes", {{"POSITION", 0}}}}}};
    b.setScene({tri});
    expectInputError(
        b.writeGlb(dir, "draco_used.glb"),
        {"meshes[0].primitives[0].extensions.KHR_draco_mesh_compression", "Draco data does not decode"});
    expectInputError(
        b.writeGltf(dir, "draco_used.gltf"),
        {"meshes[0].primitives[0].extensions.KHR_draco_mesh_compression", "Draco data does not decode"});
}

TEST(GltfErrors, VersionOtherThanTwoIsRefused) {
    TempDir dir;
    GltfBuilder b;
    b.setScene({b.addTriangleNode()});
    b.doc["asset"]["version"] = "3.0";
    expectInputError(b.writeGltf(dir, "v3.gltf"), {"asset.version is \"3.0\"", "glTF 2.x only"});
    b.doc["asset"]["version"] = "1.0";
    expectInputError(b.writeGlb(dir, "v1.glb"), {"asset.version is \"1.0\"", "1-to-2"});
    b.doc["asset"]["version"] = 2;
    expectInputError(b.writeGltf(dir, "number.gltf"), {"asset.version must be a string"});
    b.doc["asset"]["version"] = "2.1";
    b.doc["asset"]["minVersion"] = "2.1";
    expectInputError(b.writeGltf(dir, "min.gltf"), {"asset.minVersion is \"2.1\""});
    b.doc["asset"].erase("minVersion");
    EXPECT_NO_THROW(loadGltf(b.writeGltf(dir, "minor.gltf"))) << "2.1 is still glTF 2";
    b.doc.erase("asset");
    expectInputError(b.writeGltf(dir, "noasset.gltf"), {"asset.version is missing"});
}

TEST(GltfErrors, DanglingReferencesAreRefusedWithTheirPath) {
    TempDir dir;
    struct Case {
        const char* name;
        std::function<void(GltfBuilder&)> damage;
        std::vector<std::string> fragments;
    };
    const std::vector<Case> cases = {
        {"texture_source",
         [](GltfBuilder& b) {
             b.doc["images"] = nlohmann::json::array({{{"uri", "data:image/png;base64,"}}});
             b.doc["textures"] = nlohmann::json::array({{{"source", 3}}});
         },
         {"textures[0].source: image 3 does not exist (the file has 1)", "export it again"}},
        {"texture_sampler",
         [](GltfBuilder& b) {
             b.doc["textures"] = nlohmann::json::array({{{"sampler", 0}}});
         },
         {"textures[0].sampler: sampler 0 does not exist (the file has none)"}},
        {"material_texture",
         [](GltfBuilder& b) {
             b.doc["materials"] = nlohmann::json::array({{{"normalTexture", {{"index", 2}}}}});
         },
         {"materials[0].normalTexture.index: texture 2 does not exist"}},
        {"base_color_texture",
         [](GltfBuilder& b) {
             b.doc["materials"] =
                 nlohmann::json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", -1}}}}}}});
         },
         {"materials[0].pbrMetallicRoughness.baseColorTexture.index: texture -1 does not exist"}},
        {"primitive_material",
         [](GltfBuilder& b) { b.doc["meshes"][0]["primitives"][0]["material"] = 5; },
         {"meshes[0].primitives[0].material: material 5 does not exist"}},
        {"attribute",
         [](GltfBuilder& b) { b.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 9; },
         {"meshes[0].primitives[0].attributes.NORMAL: accessor 9 does not exist"}},
        {"node_mesh",
         [](GltfBuilder& b) { b.doc["nodes"][0]["mesh"] = 4; },
         {"nodes[0].mesh: mesh 4 does not exist"}},
        {"node_child",
         [](GltfBuilder& b) { b.doc["nodes"][0]["children"] = {7}; },
         {"nodes[0].children[0]: node 7 does not exist"}},
        {"scene_node",
         [](GltfBuilder& b) {
             b.doc["scenes"][0]["nodes"] = {0, 12};
         },
         {"scenes[0].nodes[1]: node 12 does not exist"}},
        {"default_scene", [](GltfBuilder& b) { b.doc["scene"] = 2; }, {"scene: scene 2 does not exist"}},
        {"node_light",
         [](GltfBuilder& b) {
             b.doc["nodes"][0]["extensions"] = {{"KHR_lights_punctual", {{"light", 0}}}};
         },
         {"nodes[0].extensions.KHR_lights_punctual.light: light 0 does not exist"}},
        {"buffer_view",
         [](GltfBuilder& b) { b.doc["accessors"][0]["bufferView"] = 40; },
         {"accessors[0].bufferView: buffer view 40 does not exist"}},
        {"not_an_index",
         [](GltfBuilder& b) { b.doc["nodes"][0]["camera"] = "front"; },
         {"nodes[0].camera must be an index into cameras"}},
        {"not_an_array",
         [](GltfBuilder& b) {
             b.doc["materials"] = {{"name", "x"}};
         },
         {"materials must be an array"}},
    };
    for (const Case& c : cases) {
        GltfBuilder b;
        b.setScene({b.addTriangleNode()});
        c.damage(b);
        SCOPED_TRACE(c.name);
        expectInputError(b.writeGltf(dir, std::string(c.name) + ".gltf"), c.fragments);
        expectInputError(b.writeGlb(dir, std::string(c.name) + ".glb"), c.fragments);
    }
}

TEST(GltfErrors, SparseAccessor) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode();
    const int idxView = b.addView(std::vector<std::uint16_t>{1, 0});
    const int valView = b.addView(std::vector<glm::vec3>{{2, 0, 0}});
    b.doc["accessors"][0]["sparse"] = {
        {"count", 1},
        {"indices", {{"bufferView", idxView}, {"componentType", test::kUnsignedShort}}},
        {"values", {{"bufferView", valView}}}};
    b.setScene({tri});
    expectInputError(b.writeGlb(dir, "sparse.glb"), {"accessor 0", "sparse accessors are not supported"});
}

TEST(GltfErrors, WrongAccessorTypeAndIndexComponentType) {
    TempDir dir;
    {
        GltfBuilder b;
        const int pos =
            b.addAccessor(b.addView(std::vector<float>{0, 0, 1, 0, 0, 1}), test::kFloat, 3, "VEC2");
        b.setScene({b.addNode({{"mesh", b.addMesh("flat", {{"attributes", {{"POSITION", pos}}}})}})});
        expectInputError(b.writeGlb(dir, "vec2.glb"), {"POSITION", "expected 3 components"});
    }
    {
        GltfBuilder b;
        const int pos = b.addVec3s({{0, 0, 0}, {1, 0, 0}, {0, 0, -1}});
        const int idx = b.addAccessor(b.addView(std::vector<float>{0, 1, 2}), test::kFloat, 3, "SCALAR");
        b.setScene({b.addNode(
            {{"mesh", b.addMesh("fidx", {{"attributes", {{"POSITION", pos}}}, {"indices", idx}})}})});
        expectInputError(b.writeGlb(dir, "fidx.glb"), {"indices must be unsigned"});
    }
}

TEST(GltfErrors, MissingMaterialAndNodeCycle) {
    TempDir dir;
    {
        GltfBuilder b;
        const int tri = b.addTriangleNode("mat");
        b.doc["meshes"][0]["primitives"][0]["material"] = 5;
        b.setScene({tri});
        expectInputError(b.writeGltf(dir, "material.gltf"),
                         {"meshes[0].primitives[0].material", "material 5 does not exist"});
    }
    {
        GltfBuilder b;
        const int tri = b.addTriangleNode();
        const int a = b.addNode({{"children", {tri}}});
        b.doc["nodes"][tri]["children"] = {a};
        b.setScene({a});
        const std::string path = b.writeGltf(dir, "cycle.gltf");
        try {
            loadGltf(path);
            ADD_FAILURE() << "expected InputError";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
        }
    }
}

TEST(GltfErrors, BadSpotConeFromFile) {
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode();
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
        {{"name", "wide"}, {"type", "spot"}, {"spot", {{"innerConeAngle", 0.5}, {"outerConeAngle", 2.0}}}}};
    b.setScene({tri, b.addNode({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}})});
    expectInputError(b.writeGltf(dir, "cone.gltf"), {"light 'wide'", "cone"});
}

TEST(GltfErrors, ZeroLengthLightDirectionFromFileNamesTheLight) {
    for (const char* type : {"spot", "directional"}) {
        TempDir dir;
        GltfBuilder b;
        const int tri = b.addTriangleNode();
        nlohmann::json light = {{"name", "flat"}, {"type", type}};
        if (std::string(type) == "spot") light["spot"] = {{"outerConeAngle", 0.7}};
        b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {light};
        b.setScene({tri, b.addNode({{"scale", {0.0, 0.0, 0.0}},
                                    {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}})});
        expectInputError(b.writeGltf(dir, "flat.gltf"), {"light 'flat'", "direction"});
    }
    // A point light has no direction: a zero scale is harmless.
    TempDir dir;
    GltfBuilder b;
    const int tri = b.addTriangleNode();
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"name", "bulb"}, {"type", "point"}}};
    b.setScene({tri, b.addNode({{"scale", {0.0, 0.0, 0.0}},
                                {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}})});
    EXPECT_EQ(loadScene(b.writeGltf(dir, "bulb.gltf")).lights.size(), 1u);
}

// Corrupting bytes of a valid file anywhere must give a scene or an InputError, nothing else.
TEST(GltfErrors, CorruptedAndTruncatedGlbNeverEscapeAsOtherErrors) {
    TempDir dir;
    GltfBuilder b;
    b.setScene({b.addTriangleNode()});
    const std::vector<std::uint8_t> good = b.glbBytes();
    const std::string path = dir.file("fuzz.glb");
    std::uint32_t rng = 12345;
    const auto next = [&rng] { return rng = rng * 1664525u + 1013904223u; };
    for (int round = 0; round < 300; ++round) {
        std::vector<std::uint8_t> bytes = good;
        if (round % 3 == 0)
            bytes.resize(next() % bytes.size());
        else
            for (int k = 0; k < 1 + round % 4; ++k)
                bytes[next() % bytes.size()] = static_cast<std::uint8_t>(next() >> 24);
        test::writeBytes(path, bytes);
        try {
            loadGltf(path);
        } catch (const InputError&) {
        } catch (const std::exception& e) {
            ADD_FAILURE() << "round " << round << ": " << e.what();
        }
    }
}

} // namespace
} // namespace gis
