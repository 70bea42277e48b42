// Compressed glTF files made by other tools (tests/data/corpus/compress.sh: gltf-transform's Draco,
// gltfpack's meshopt from the Blender exports) load as their uncompressed originals, and damaged ones
// are refused with the extension and the JSON path.
#include <cstring>
#include <fstream>
#include <iterator>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "GltfBuilder.h"
#include "core/Error.h"
#include "scene/SceneLoader.h"

namespace gis {
namespace {

using test::TempDir;

std::string corpus(const std::string& name) {
    return std::string(GIS_SOURCE_DIR) + "/tests/data/corpus/" + name;
}

std::string readAll(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

void writeAll(const std::string& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::uint32_t u32(const std::string& b, std::size_t at) {
    std::uint32_t v = 0;
    std::memcpy(&v, b.data() + at, 4);
    return v;
}

double surfaceArea(const Scene& scene) {
    double area = 0;
    for (const Mesh& mesh : scene.meshes)
        for (std::size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
            const glm::vec3 a = mesh.positions[mesh.indices[i]], b = mesh.positions[mesh.indices[i + 1]],
                            c = mesh.positions[mesh.indices[i + 2]];
            area += 0.5 * glm::length(glm::cross(b - a, c - a));
        }
    return area;
}

void expectSameGeometry(const Scene& original, const Scene& compressed, double tolerance) {
    EXPECT_EQ(compressed.triangleCount(), original.triangleCount());
    EXPECT_EQ(compressed.materials.size(), original.materials.size());
    EXPECT_EQ(compressed.textures.size(), original.textures.size());
    const float diagonal = glm::length(original.bounds.max - original.bounds.min);
    EXPECT_LT(glm::length(compressed.bounds.min - original.bounds.min), tolerance * diagonal);
    EXPECT_LT(glm::length(compressed.bounds.max - original.bounds.max), tolerance * diagonal);
    EXPECT_NEAR(surfaceArea(compressed), surfaceArea(original), tolerance * surfaceArea(original));
    bool texcoords = false, compressedTexcoords = false;
    for (const Mesh& m : original.meshes) texcoords |= !m.texcoords.empty();
    for (const Mesh& m : compressed.meshes) compressedTexcoords |= !m.texcoords.empty();
    // Texture coordinates where a texture needs them (gltfpack drops them from untextured meshes).
    if (!original.textures.empty()) {
        EXPECT_EQ(compressedTexcoords, texcoords);
    }
}

TEST(GltfCompressed, DracoFilesLoadAsTheirOriginals) {
    // gltf-transform's Draco quantizes positions to 14 bits: well under 1 % of the model.
    for (const char* name : {"suzanne", "textured_box"}) {
        SCOPED_TRACE(name);
        const Scene original = loadGltf(corpus(std::string(name) + ".glb"));
        const Scene draco = loadGltf(corpus(std::string(name) + "_draco.glb"));
        expectSameGeometry(original, draco, 0.01);
    }
}

TEST(GltfCompressed, MeshoptFilesLoadAsTheirOriginals) {
    // suzanne_meshopt is also quantized (KHR_mesh_quantization, the dequantizing node transform);
    // textured_box_meshopt is not.
    for (const char* name : {"suzanne", "textured_box"}) {
        SCOPED_TRACE(name);
        const Scene original = loadGltf(corpus(std::string(name) + ".glb"));
        const Scene meshopt = loadGltf(corpus(std::string(name) + "_meshopt.glb"));
        expectSameGeometry(original, meshopt, 0.01);
    }
}

// The GLB split into .gltf + .bin, as gltfpack writes .gltf: the compressed buffer is an external file.
TEST(GltfCompressed, ExternalCompressedBufferIsReadThroughTheSandbox) {
    TempDir dir;
    const std::string glb = readAll(corpus("suzanne_meshopt.glb"));
    const std::uint32_t jsonLength = u32(glb, 12);
    nlohmann::json doc = nlohmann::json::parse(glb.substr(20, jsonLength));
    const std::size_t binAt = 20 + jsonLength;
    writeAll(dir.file("data.bin"), glb.substr(binAt + 8, u32(glb, binAt)));
    doc["buffers"][0]["uri"] = "data.bin";
    const std::string path = dir.file("split.gltf");
    writeAll(path, doc.dump());
    const Scene split = loadGltf(path);
    EXPECT_EQ(split.triangleCount(), loadGltf(corpus("suzanne.glb")).triangleCount());

    // Uploads carry no external files, compressed or not.
    SceneLoadOptions upload;
    upload.allowExternalFiles = false;
    upload.displayName = "split.gltf";
    try {
        loadGltf(path, upload);
        ADD_FAILURE() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("self-contained"), std::string::npos) << e.what();
    }
}

/// `name` with its binary chunk overwritten (the compressed streams with it).
std::string damaged(const TempDir& dir, const std::string& name) {
    std::string glb = readAll(corpus(name));
    const std::size_t binAt = 20 + u32(glb, 12);
    for (std::size_t i = binAt + 8; i < glb.size(); ++i) glb[i] = static_cast<char>(0x5A ^ (i * 31));
    const std::string path = dir.file("damaged_" + name);
    writeAll(path, glb);
    return path;
}

void expectRefusal(const std::string& path, const std::vector<std::string>& fragments) {
    try {
        loadGltf(path);
        ADD_FAILURE() << path << ": expected InputError";
    } catch (const InputError& e) {
        for (const auto& f : fragments)
            EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << "'" << f << "' in: " << e.what();
    }
}

TEST(GltfCompressed, DamagedStreamsAreRefusedWithTheirPath) {
    TempDir dir;
    expectRefusal(
        damaged(dir, "textured_box_draco.glb"),
        {"meshes[0].primitives[0].extensions.KHR_draco_mesh_compression", "Draco data does not decode"});
    expectRefusal(damaged(dir, "suzanne_meshopt.glb"),
                  {"bufferViews[0].extensions.EXT_meshopt_compression", "meshopt data does not decode"});
}

TEST(GltfCompressed, DecodedDataIsChargedToTheMemoryBudget) {
    SceneLoadOptions tight;
    const std::string path = corpus("suzanne_draco.glb");
    tight.maxDecodedBytes = readAll(path).size() + 1024; // the file, and not its decoded mesh
    try {
        loadGltf(path, tight);
        ADD_FAILURE() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("KHR_draco_mesh_compression"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("would take"), std::string::npos) << e.what();
    }
}

} // namespace
} // namespace gis
