// Zipped glTF uploads: a real .gltf + .bin + PNG archive made by another tool loads like the .glb it
// came from; hostile or unusable archives are refused with what to do, and leave nothing behind.
#include "scene/SceneArchive.h"

#include <fstream>
#include <iterator>

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <zip.h>

#include "GltfBuilder.h"
#include "scene/SceneLoader.h"

namespace gis {
namespace {
namespace fs = std::filesystem;

std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct Entry {
    std::string name, content;
    bool symlink = false;
};

/// A zip of `entries` written by libzip (deflated), as bytes.
std::string makeZip(const std::vector<Entry>& entries) {
    const test::TempDir dir;
    const std::string path = dir.file("a.zip");
    int error = 0;
    zip_t* z = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
    EXPECT_NE(z, nullptr);
    for (const Entry& e : entries) {
        zip_source_t* s = zip_source_buffer(z, e.content.data(), e.content.size(), 0);
        const zip_int64_t i = zip_file_add(z, e.name.c_str(), s, ZIP_FL_ENC_UTF_8);
        EXPECT_GE(i, 0) << e.name;
        if (e.symlink)
            zip_file_set_external_attributes(z, static_cast<zip_uint64_t>(i), 0, ZIP_OPSYS_UNIX,
                                             static_cast<zip_uint32_t>(S_IFLNK | 0777) << 16);
    }
    EXPECT_EQ(zip_close(z), 0);
    return readFile(path);
}

std::string refusal(const std::string& bytes, const fs::path& dest, ArchiveLimits limits = {}) {
    try {
        extractSceneArchive(bytes, dest, limits, "upload:a.zip");
    } catch (const InputError& e) {
        EXPECT_EQ(e.where(), "upload:a.zip");
        EXPECT_FALSE(fs::exists(dest)) << "an error left the folder behind";
        return e.reason();
    }
    ADD_FAILURE() << "expected a refusal";
    return {};
}

TEST(SceneArchive, AGltfWithItsBinAndTexturesLoadsLikeTheGlb) {
    // glTF Transform's .gltf + .bin + PNG of the corpus box, texture in textures/, zipped by Python.
    const std::string corpus = std::string(GIS_SOURCE_DIR) + "/tests/data/corpus/";
    const test::TempDir dir;
    const fs::path dest = dir.file("box.zip");
    const std::string scene =
        extractSceneArchive(readFile(corpus + "textured_box_gltf.zip"), dest, {}, "upload:box.zip");
    EXPECT_EQ(scene, "textured_box/textured_box.gltf");
    EXPECT_EQ(findArchivedScene(dest), dest / scene);

    const Scene zipped = loadScene((dest / scene).string(), {.displayName = "upload:box.zip"});
    const Scene glb = loadScene(corpus + "textured_box.glb");
    EXPECT_EQ(zipped.triangleCount(), glb.triangleCount());
    ASSERT_EQ(zipped.textures.size(), 1u);
    ASSERT_EQ(glb.textures.size(), 1u);
    EXPECT_EQ(zipped.textures[0].rgba, glb.textures[0].rgba);
    EXPECT_EQ(zipped.meshes[0].positions, glb.meshes[0].positions);
}

TEST(SceneArchive, MacMetadataAndFoldersAreFine) {
    const test::TempDir dir;
    std::string glb = readFile(std::string(GIS_SOURCE_DIR) + "/tests/data/corpus/suzanne.glb");
    const std::string bytes = makeZip({{"model/", ""},
                                       {"model/suzanne.glb", glb},
                                       {"__MACOSX/model/._suzanne.glb", "junk"},
                                       {"model/._suzanne.glb", "junk"},
                                       {"model/readme.txt", "CC-BY"}});
    EXPECT_EQ(extractSceneArchive(bytes, dir.file("s.zip"), {}, "upload:s.zip"), "model/suzanne.glb");
    EXPECT_FALSE(fs::exists(fs::path(dir.file("s.zip")) / "__MACOSX"));
    EXPECT_GT(loadScene(dir.file("s.zip") + "/model/suzanne.glb").triangleCount(), 0u);
}

TEST(SceneArchive, RefusesWhatItCannotUseAndSaysWhatToDo) {
    const test::TempDir dir;
    const fs::path dest = dir.file("x.zip");
    EXPECT_NE(refusal("not a zip at all", dest).find("not a zip archive"), std::string::npos);
    std::string damaged = makeZip({{"a.gltf", "{}"}});
    damaged.resize(damaged.size() / 2);
    EXPECT_NE(refusal(damaged, dest).find("damaged"), std::string::npos);
    EXPECT_NE(refusal(makeZip({{"readme.txt", "hi"}}), dest).find("no .gltf or .glb"), std::string::npos);
    const std::string two = refusal(makeZip({{"a.gltf", "{}"}, {"b/b.glb", "glTF"}}), dest);
    EXPECT_NE(two.find("2 scene files ('a.gltf', 'b/b.glb')"), std::string::npos) << two;
    for (const char* evil : {"../escape.gltf", "/etc/escape.gltf", "a/../../escape.gltf", "a\\..\\b.gltf"}) {
        const std::string r = refusal(makeZip({{evil, "{}"}}), dest);
        EXPECT_NE(r.find("not a plain relative path"), std::string::npos) << evil << ": " << r;
    }
    EXPECT_FALSE(fs::exists(fs::path(dir.file("escape.gltf"))));
    EXPECT_NE(
        refusal(makeZip({{"a.gltf", "{}"}, {"link.bin", "/etc/passwd", true}}), dest).find("symbolic link"),
        std::string::npos);
    // Limits: entries, and bytes as they are unpacked (a zip bomb stops at the budget).
    std::vector<Entry> many;
    for (int i = 0; i < 20; ++i) {
        Entry e;
        e.name = std::string("f") + char('a' + i) + ".txt";
        e.content = "x";
        many.push_back(e);
    }
    EXPECT_NE(refusal(makeZip(many), dest, {.maxEntries = 10}).find("20 entries"), std::string::npos);
    const std::string bomb = makeZip({{"a.gltf", std::string(8 << 20, ' ')}});
    EXPECT_LT(bomb.size(), 100000u);
    try {
        extractSceneArchive(bomb, dest, {.maxBytes = 1 << 20}, "upload:a.zip");
        ADD_FAILURE() << "the bomb was unpacked";
    } catch (const ArchiveTooLarge& e) {
        EXPECT_NE(std::string(e.what()).find("more than 1 MiB"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dest));
}

} // namespace
} // namespace gis
