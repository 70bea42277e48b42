// A glTF load reports where it is (SceneLoadOptions::onProgress): stages in order, a share that never
// falls, the bytes read, and the images and mesh primitives counted against what the file holds.
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "GltfBuilder.h"
#include "core/Error.h"
#include "scene/SceneLoader.h"

namespace gis {
namespace {

using Stage = SceneLoadProgress::Stage;
using test::TempDir;

std::string corpus(const std::string& name) {
    return std::string(GIS_SOURCE_DIR) + "/tests/data/corpus/" + name;
}

std::vector<SceneLoadProgress> loadReporting(const std::string& path) {
    std::vector<SceneLoadProgress> reports;
    SceneLoadOptions options;
    options.onProgress = [&](const SceneLoadProgress& p) { reports.push_back(p); };
    loadScene(path, options);
    return reports;
}

/// The JSON chunk of a .glb, parsed.
nlohmann::json glbJson(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    const std::string bytes(std::istreambuf_iterator<char>(in), {});
    std::uint32_t length = 0;
    std::memcpy(&length, bytes.data() + 12, 4);
    return nlohmann::json::parse(bytes.substr(20, length));
}

const SceneLoadProgress* lastOf(const std::vector<SceneLoadProgress>& reports, Stage stage) {
    const SceneLoadProgress* last = nullptr;
    for (const auto& r : reports)
        if (r.stage == stage) last = &r;
    return last;
}

void expectOrdered(const std::vector<SceneLoadProgress>& reports) {
    ASSERT_FALSE(reports.empty());
    for (std::size_t i = 1; i < reports.size(); ++i) {
        EXPECT_GE(static_cast<int>(reports[i].stage), static_cast<int>(reports[i - 1].stage))
            << "report " << i;
        EXPECT_GE(reports[i].share, reports[i - 1].share) << "report " << i;
        EXPECT_LE(reports[i].share, 1.0);
        EXPECT_LE(reports[i].done, reports[i].total) << reports[i].describe();
    }
    EXPECT_EQ(reports.back().stage, Stage::Finishing);
    EXPECT_GE(reports.back().share, 0.95);
}

TEST(LoadProgress, TexturedFileCountsItsImagesAndPrimitives) {
    const std::string path = corpus("textured_box.glb");
    const nlohmann::json doc = glbJson(path);
    const auto reports = loadReporting(path);
    expectOrdered(reports);

    const SceneLoadProgress* reading = lastOf(reports, Stage::Reading);
    ASSERT_NE(reading, nullptr);
    EXPECT_EQ(reading->bytesRead, std::filesystem::file_size(path));
    EXPECT_EQ(reading->fileBytes, std::filesystem::file_size(path));
    EXPECT_DOUBLE_EQ(reading->share, 0.1);

    const SceneLoadProgress* images = lastOf(reports, Stage::Images);
    ASSERT_NE(images, nullptr);
    EXPECT_EQ(images->total, doc["images"].size());
    EXPECT_EQ(images->done, images->total);
    EXPECT_EQ(images->describe(),
              "decoding images: " + std::to_string(images->total) + " of " + std::to_string(images->total));

    std::size_t primitives = 0;
    for (const auto& node : doc["nodes"])
        if (node.contains("mesh")) primitives += doc["meshes"][node["mesh"].get<int>()]["primitives"].size();
    const SceneLoadProgress* meshes = lastOf(reports, Stage::Meshes);
    ASSERT_NE(meshes, nullptr);
    EXPECT_EQ(meshes->total, primitives);
    EXPECT_EQ(meshes->done, primitives);
    EXPECT_DOUBLE_EQ(meshes->share, 0.95);
    EXPECT_EQ(lastOf(reports, Stage::Decompressing), nullptr) << "nothing to decompress";
}

TEST(LoadProgress, CompressedFileReportsItsDecoding) {
    const auto reports = loadReporting(corpus("textured_box_draco.glb"));
    expectOrdered(reports);
    const SceneLoadProgress* decoding = lastOf(reports, Stage::Decompressing);
    ASSERT_NE(decoding, nullptr);
    EXPECT_EQ(decoding->describe(), "decoding compressed meshes");
}

TEST(LoadProgress, FileWithoutImagesGivesTheirShareToTheMeshes) {
    TempDir dir;
    test::GltfBuilder b;
    b.setScene({b.addTriangleNode("a"), b.addTriangleNode("b"), b.addTriangleNode("c")});
    const auto reports = loadReporting(b.writeGltf(dir, "three.gltf"));
    expectOrdered(reports);
    EXPECT_EQ(lastOf(reports, Stage::Images), nullptr);
    std::vector<double> meshShares;
    for (const auto& r : reports)
        if (r.stage == Stage::Meshes) meshShares.push_back(r.share);
    ASSERT_EQ(meshShares.size(), 4u) << "the stage's start, then each primitive";
    EXPECT_DOUBLE_EQ(meshShares.front(), 0.1) << "straight after reading";
    EXPECT_DOUBLE_EQ(meshShares[1], 0.1 + 0.85 / 3);
    EXPECT_EQ(lastOf(reports, Stage::Meshes)->describe(), "reading meshes: 3 of 3");
}

TEST(LoadProgress, BuiltinScenesAndFailuresNeedNoCallback) {
    std::size_t calls = 0;
    SceneLoadOptions options;
    options.onProgress = [&](const SceneLoadProgress&) { ++calls; };
    loadScene("builtin:cornell", options);
    EXPECT_EQ(calls, 0u) << "generated in milliseconds: nothing to report";
    EXPECT_THROW(loadScene(corpus("no-such-file.glb"), options), InputError);
}

TEST(LoadProgress, DescribesTheBytesRead) {
    SceneLoadProgress p;
    p.stage = Stage::Reading;
    p.bytesRead = 3u << 20;
    p.fileBytes = 12u << 20;
    EXPECT_EQ(p.describe(), "reading the file: 3.0 MiB of 12.0 MiB");
}

/// Loads `path`, asking for a cancel once a report of `stage` arrived; the reports seen.
std::vector<SceneLoadProgress> loadCancellingAt(const std::string& path, Stage stage) {
    std::vector<SceneLoadProgress> reports;
    bool wanted = true;
    SceneLoadOptions options;
    options.onProgress = [&](const SceneLoadProgress& p) {
        reports.push_back(p);
        if (p.stage == stage) wanted = false;
    };
    options.cancelled = [&] { return !wanted; };
    EXPECT_THROW(loadScene(path, options), LoadCancelled) << "cancelled at stage " << static_cast<int>(stage);
    return reports;
}

TEST(LoadProgress, ACancelledLoadStopsWithinTheStageItWasCancelledIn) {
    TempDir dir;
    test::GltfBuilder b;
    b.setScene({b.addTriangleNode("a"), b.addTriangleNode("b"), b.addTriangleNode("c")});
    const std::string plain = b.writeGltf(dir, "three.gltf");
    struct Case {
        std::string path;
        Stage stage;
    };
    for (const Case& c :
         {Case{corpus("textured_box.glb"), Stage::Reading}, Case{corpus("textured_box.glb"), Stage::Images},
          Case{corpus("textured_box_draco.glb"), Stage::Decompressing}, Case{plain, Stage::Meshes}}) {
        const auto reports = loadCancellingAt(c.path, c.stage);
        ASSERT_FALSE(reports.empty()) << c.path;
        EXPECT_EQ(reports.back().stage, c.stage) << c.path << ": nothing after the stage it was cancelled in";
        if (c.stage == Stage::Meshes) {
            EXPECT_LE(reports.back().done, 1u) << "at most the primitive under way";
        }
        if (c.stage == Stage::Images) {
            EXPECT_EQ(reports.back().done, 0u) << "no image decoded after the cancel";
        }
    }
    // A cancel function that never answers true changes nothing.
    SceneLoadOptions options;
    options.cancelled = [] { return false; };
    EXPECT_NO_THROW(loadScene(corpus("textured_box.glb"), options));
    // A cancelled load is an InputError like every other failed load: callers that catch only that
    // still catch it.
    options.cancelled = [] { return true; };
    EXPECT_THROW(loadScene(corpus("textured_box.glb"), options), InputError);
}

} // namespace
} // namespace gis
