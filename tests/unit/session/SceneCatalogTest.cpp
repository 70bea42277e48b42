// Scene names resolve only inside the configured places.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "core/Error.h"
#include "session/SceneCatalog.h"

namespace fs = std::filesystem;

namespace {
struct TempTree {
    fs::path root = fs::temp_directory_path() / ("gis_catalog_" + std::to_string(::getpid()));
    TempTree() {
        fs::create_directories(root / "scenes/sub");
        fs::create_directories(root / "uploads");
        std::ofstream(root / "scenes/a.glb") << "x";
        std::ofstream(root / "scenes/sub/b.gltf") << "x";
        std::ofstream(root / "scenes/notes.txt") << "x";
        std::ofstream(root / "secret.glb") << "x";
        std::ofstream(root / "uploads/mine.glb") << "x";
        // An extracted zip upload (scene/SceneArchive.h), one half-written, and one whose only scene
        // file is a link out of its folder.
        fs::create_directories(root / "uploads/pack.zip/model/textures");
        std::ofstream(root / "uploads/pack.zip/model/scene.gltf") << "x";
        std::ofstream(root / "uploads/pack.zip/model/textures/t.png") << "x";
        fs::create_directories(root / "uploads/.next.zip.part");
        std::ofstream(root / "uploads/.next.zip.part/a.gltf") << "x";
        fs::create_directories(root / "uploads/linked.zip");
        fs::create_symlink(root / "secret.glb", root / "uploads/linked.zip/a.glb");
        fs::create_symlink(root / "secret.glb", root / "scenes/link.glb");
    }
    ~TempTree() { fs::remove_all(root); }
};
} // namespace

TEST(SceneCatalog, ListsBuiltinsFilesAndUploads) {
    TempTree t;
    gis::SceneCatalog catalog({(t.root / "scenes").string()}, "builtin:cornell");
    auto names = catalog.list((t.root / "uploads").string());
    auto has = [&](const std::string& n) { return std::find(names.begin(), names.end(), n) != names.end(); };
    EXPECT_TRUE(has("builtin:cornell"));
    EXPECT_TRUE(has("file:a.glb"));
    EXPECT_TRUE(has("file:sub/b.gltf"));
    EXPECT_TRUE(has("upload:mine.glb"));
    EXPECT_TRUE(has("upload:pack.zip"));
    EXPECT_FALSE(has("upload:.next.zip.part"));
    EXPECT_FALSE(has("file:notes.txt"));
}

TEST(SceneCatalog, NamesNeverEscapeTheirDirectory) {
    TempTree t;
    gis::SceneCatalog catalog({(t.root / "scenes").string()}, "builtin:cornell");
    EXPECT_EQ(catalog.resolve("file:a.glb"), fs::canonical(t.root / "scenes/a.glb").string());
    EXPECT_EQ(catalog.resolve("builtin:crease"), "builtin:crease");
    for (const char* bad : {"file:../secret.glb", "file:/etc/passwd", "file:link.glb", "builtin:nope",
                            "/etc/passwd", "upload:mine.glb", "file:sub/../../secret.glb"}) {
        try {
            catalog.resolve(bad);
            ADD_FAILURE() << bad << " resolved";
        } catch (const gis::InputError& e) {
            EXPECT_EQ(e.where(), "/name") << bad;
        }
    }
    // Uploads resolve only with the session's own sandbox.
    EXPECT_NO_THROW(catalog.resolve("upload:mine.glb", (t.root / "uploads").string()));
    EXPECT_THROW(catalog.resolve("upload:../secret.glb", (t.root / "uploads").string()), gis::InputError);
    // A zip upload resolves to the scene file inside its folder, never to one outside.
    EXPECT_EQ(catalog.resolve("upload:pack.zip", (t.root / "uploads").string()),
              fs::canonical(t.root / "uploads/pack.zip/model/scene.gltf").string());
    EXPECT_THROW(catalog.resolve("upload:linked.zip", (t.root / "uploads").string()), gis::InputError);
    EXPECT_TRUE(catalog.loadOptions("upload:pack.zip").allowExternalFiles); // its .bin and textures
    EXPECT_FALSE(catalog.loadOptions("upload:mine.glb").allowExternalFiles);
}

TEST(SceneCatalog, UploadNamesAreChecked) {
    EXPECT_NO_THROW(gis::SceneCatalog::checkUploadName("room_2-final.glb"));
    EXPECT_NO_THROW(gis::SceneCatalog::checkUploadName("sponza.zip"));
    for (const char* bad : {"", ".hidden.glb", "a/b.glb", "x.gltf", "sp ace.glb", "..glb"})
        EXPECT_THROW(gis::SceneCatalog::checkUploadName(bad), gis::InputError) << bad;
    EXPECT_THROW(gis::SceneCatalog({"/nonexistent/dir"}, ""), gis::InputError);
}
