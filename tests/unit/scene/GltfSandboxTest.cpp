// Hostile files (issue #17): external URIs stay inside the file's own folder (uploads reach none),
// deep JSON never reaches tinygltf, and what a file costs once decoded is checked against the budget
// from image headers and instance counts before the memory is spent. Errors name the file as the
// client knows it, never a server path.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "GltfBuilder.h"
#include "core/Error.h"
#include "scene/SceneLoader.h"

namespace gis {
namespace {

namespace fs = std::filesystem;
using test::GltfBuilder;
using test::TempDir;

/// Loads `path` with `options`, expecting an InputError; returns its message.
std::string loadError(const std::string& path, const SceneLoadOptions& options = {}) {
    try {
        (void)loadGltf(path, options);
    } catch (const InputError& e) {
        return e.what();
    } catch (const std::exception& e) {
        return std::string("wrong exception type: ") + e.what();
    }
    return "loaded";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// A one-triangle file whose POSITION data lives in an external buffer `uri` (12 floats: 3 used).
GltfBuilder externalBufferFile(const std::string& uri) {
    GltfBuilder b;
    b.setScene({b.addTriangleNode()});
    b.doc["accessors"][0]["bufferView"] = 2; // positions from the external buffer
    b.doc["bufferViews"].push_back({{"buffer", 1}, {"byteOffset", 0}, {"byteLength", 36}});
    b.doc["extraBuffers"] = {{{"byteLength", 48}, {"uri", uri}}};
    return b;
}

/// Writes `b` as .gltf with its extra buffers appended after the embedded one.
std::string writeWithExtraBuffers(GltfBuilder b, const TempDir& dir, const std::string& name) {
    const nlohmann::json extra = b.doc["extraBuffers"];
    b.doc.erase("extraBuffers");
    const std::string path = b.writeGltf(dir, name);
    std::ifstream in(path);
    nlohmann::json doc = nlohmann::json::parse(in);
    for (const auto& e : extra) doc["buffers"].push_back(e);
    test::writeText(path, doc.dump());
    return path;
}

void writeFloats(const std::string& path) {
    const std::vector<float> v = {0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0};
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(float)));
}

TEST(GltfSandbox, ExternalBufferInsideTheFolderLoads) {
    TempDir dir;
    fs::create_directories(dir.file("data"));
    writeFloats(dir.file("data/tri.bin"));
    const std::string path = writeWithExtraBuffers(externalBufferFile("data/tri.bin"), dir, "ok.gltf");
    EXPECT_EQ(loadGltf(path).triangleCount(), 1u);
}

TEST(GltfSandbox, PathsOutOfTheFolderAreRefusedWithoutNamingServerFiles) {
    TempDir dir;
    fs::create_directories(dir.file("inner"));
    writeFloats(dir.file("secret.bin")); // beside the folder: must not be read
    const SceneLoadOptions named{.displayName = "file:inner/scene.gltf"};
    for (const std::string& uri : std::vector<std::string>{"../secret.bin", "%2e%2e/secret.bin", "sub/../../secret.bin",
                                  dir.file("secret.bin"), "/etc/passwd", "../../../../etc/passwd"}) {
        const std::string path = writeWithExtraBuffers(externalBufferFile(uri), dir, "inner/scene.gltf");
        const std::string error = loadError(path, named);
        EXPECT_TRUE(contains(error, "file:inner/scene.gltf: refers to")) << uri << ": " << error;
        EXPECT_TRUE(contains(error, "outside its own folder")) << uri << ": " << error;
        // The file's own text may be quoted; nothing the server derived from its paths.
        if (uri[0] != '/') {
            EXPECT_FALSE(contains(error, dir.file(""))) << uri << ": a server path in: " << error;
        }
        EXPECT_FALSE(contains(error, std::to_string(fs::file_size("/etc/passwd")))) << error;
    }
}

TEST(GltfSandbox, SymbolicLinksOutOfTheFolderAreRefused) {
    TempDir dir;
    fs::create_directories(dir.file("inner"));
    writeFloats(dir.file("secret.bin"));
    fs::create_symlink(dir.file("secret.bin"), dir.file("inner/link.bin"));
    const std::string path = writeWithExtraBuffers(externalBufferFile("link.bin"), dir, "inner/scene.gltf");
    const std::string error = loadError(path);
    EXPECT_TRUE(contains(error, "leads outside its own folder")) << error;
}

TEST(GltfSandbox, UploadsReachNoExternalFile) {
    TempDir dir;
    writeFloats(dir.file("tri.bin"));
    const std::string path = writeWithExtraBuffers(externalBufferFile("tri.bin"), dir, "up.gltf");
    const std::string error =
        loadError(path, {.displayName = "upload:up.glb", .allowExternalFiles = false, .maxDecodedBytes = 0});
    EXPECT_TRUE(contains(error, "upload:up.glb: refers to the external file 'tri.bin'")) << error;
    EXPECT_TRUE(contains(error, "self-contained")) << error;
}

/// A PNG that is only a signature and an IHDR chunk: enough for a header read, nothing to decode.
std::vector<std::uint8_t> pngHeader(std::uint32_t width, std::uint32_t height) {
    std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A, 0, 0, 0, 13, 'I', 'H', 'D', 'R'};
    for (std::uint32_t v : {width, height})
        for (int s = 24; s >= 0; s -= 8) png.push_back(static_cast<std::uint8_t>(v >> s));
    png.insert(png.end(), {8, 0, 0, 0, 0, 0, 0, 0, 0}); // 8-bit grey, then a CRC stb does not check
    return png;
}

std::string fileWithImage(const TempDir& dir, const std::vector<std::uint8_t>& png) {
    GltfBuilder b;
    b.setScene({b.addTriangleNode()});
    const int view = b.addView(png.data(), png.size());
    b.doc["images"] = {{{"bufferView", view}, {"mimeType", "image/png"}}};
    b.doc["textures"] = {{{"source", 0}}};
    return b.writeGlb(dir, "image.glb");
}

TEST(GltfBudget, ImagesAreChargedFromTheirHeaderBeforeDecoding) {
    TempDir dir;
    const std::string path = fileWithImage(dir, pngHeader(16384, 16384));
    const std::string error = loadError(path, {.displayName = "upload:bomb.glb", .maxDecodedBytes = 256u << 20});
    EXPECT_TRUE(contains(error, "upload:bomb.glb: image 0 (16384x16384) would take 2048 MiB")) << error;
    EXPECT_TRUE(contains(error, "at most 256 MiB")) << error;
    // Past the largest texture side nothing is decoded whatever the budget.
    const std::string huge = loadError(fileWithImage(dir, pngHeader(20000, 8)));
    EXPECT_TRUE(contains(huge, "20000x8; textures may be at most 16384 pixels on a side")) << huge;
}

TEST(GltfBudget, InstancesCountAgainstTheBudget) {
    // Twelve levels of two children each name one triangle 4096 times in a file of a few KiB.
    GltfBuilder b;
    int node = b.addTriangleNode();
    for (int level = 0; level < 12; ++level) node = b.addNode({{"children", {node, node}}});
    b.setScene({node});
    TempDir dir;
    const std::string kept = b.writeGlb(dir, "instances.glb");
    EXPECT_EQ(loadGltf(kept).triangleCount(), 4096u);
    const std::string error = loadError(kept, {.displayName = "upload:i.glb", .maxDecodedBytes = 64u << 10});
    EXPECT_TRUE(contains(error, "fewer instances")) << error;
}

TEST(GltfBudget, DeepJsonNeverReachesTheParser) {
    TempDir dir;
    GltfBuilder b;
    b.setScene({b.addTriangleNode()});
    // .gltf: extras with 100,000 nested arrays; .glb: nested objects under extensions.
    const std::string plain = b.doc.dump();
    const std::string text = "{\"extras\":" + std::string(100000, '[') + std::string(100000, ']') + "," +
                             plain.substr(1);
    test::writeText(dir.file("deep.gltf"), text);
    std::string error = loadError(dir.file("deep.gltf"));
    EXPECT_TRUE(contains(error, "nested deeper than 128 levels")) << error;

    std::string nested;
    for (int i = 0; i < 100000; ++i) nested += "{\"a\":";
    nested += '1';
    nested.append(100000, '}');
    const std::string json = "{\"extensions\":" + nested + ",\"asset\":{\"version\":\"2.0\"}}";
    std::string padded = json;
    while (padded.size() % 4 != 0) padded += ' ';
    std::vector<std::uint8_t> out;
    const auto u32 = [&out](std::uint32_t v) {
        for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    };
    u32(0x46546C67);
    u32(2);
    u32(static_cast<std::uint32_t>(12 + 8 + padded.size()));
    u32(static_cast<std::uint32_t>(padded.size()));
    u32(0x4E4F534A);
    out.insert(out.end(), padded.begin(), padded.end());
    test::writeBytes(dir.file("deep.glb"), out);
    error = loadError(dir.file("deep.glb"), {.displayName = "upload:deep.glb"});
    EXPECT_TRUE(contains(error, "upload:deep.glb: malformed JSON: arrays and objects nested deeper than 128"))
        << error;
}

} // namespace
} // namespace gis
