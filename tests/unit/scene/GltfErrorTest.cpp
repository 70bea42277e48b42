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
    b.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_draco_mesh_compression"};
    b.doc["extensionsRequired"] = {"KHR_lights_punctual", "KHR_draco_mesh_compression"};
    expectInputError(b.writeGltf(dir, "draco.gltf"),
                     {"unsupported required extension 'KHR_draco_mesh_compression'"});
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
        expectInputError(b.writeGltf(dir, "material.gltf"), {"mesh 'mat'", "material 5 does not exist"});
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
