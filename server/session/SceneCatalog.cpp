#include "session/SceneCatalog.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <optional>
#include <system_error>

#include "core/Error.h"
#include "scene/SceneArchive.h"
#include "scene/SceneLoader.h"

namespace gis {
namespace fs = std::filesystem;
namespace {

bool isSceneFile(const fs::path& p) {
    const std::string ext = p.extension().string();
    return ext == ".glb" || ext == ".gltf";
}

// True when `path` (made canonical) lies inside `root` (canonical).
bool inside(const fs::path& path, const std::string& root, std::string& resolved) {
    std::error_code ec;
    fs::path canonical = fs::canonical(path, ec);
    if (ec) return false;
    resolved = canonical.string();
    return resolved.size() > root.size() && resolved.compare(0, root.size(), root) == 0 &&
           resolved[root.size()] == '/';
}

} // namespace

SceneCatalog::SceneCatalog(std::vector<std::string> sceneDirs, std::string defaultScene,
                           std::uint64_t maxDecodedBytes)
    : mDefault(std::move(defaultScene)), mMaxDecodedBytes(maxDecodedBytes) {
    for (const auto& d : sceneDirs) {
        std::error_code ec;
        fs::path c = fs::canonical(d, ec);
        if (ec || !fs::is_directory(c))
            throw InputError("--scene-dir", "directory '" + d + "' does not exist");
        mDirs.push_back(c.string());
    }
}

std::vector<std::string> SceneCatalog::list(const std::string& uploadDir) const {
    std::vector<std::string> out;
    for (const auto& n : builtinSceneNames()) out.push_back("builtin:" + n);
    std::vector<std::string> files;
    for (const auto& dir : mDirs) {
        std::error_code ec;
        // Two levels deep is enough for "scenes/<name>/<name>.gltf" layouts and bounds the walk.
        for (auto it =
                 fs::recursive_directory_iterator(dir, fs::directory_options::skip_permission_denied, ec);
             !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
            if (it.depth() > 1) it.disable_recursion_pending();
            if (it->is_regular_file(ec) && isSceneFile(it->path()))
                files.push_back("file:" + fs::relative(it->path(), dir, ec).string());
        }
    }
    std::sort(files.begin(), files.end());
    files.erase(std::unique(files.begin(), files.end()), files.end());
    out.insert(out.end(), files.begin(), files.end());
    if (!uploadDir.empty()) {
        std::vector<std::string> uploads;
        std::error_code ec;
        for (auto it = fs::directory_iterator(uploadDir, ec); !ec && it != fs::directory_iterator();
             it.increment(ec))
            // A .glb file, or the folder a .zip was extracted into (scene/SceneArchive.h).
            if ((it->is_regular_file(ec) && it->path().extension() == ".glb") ||
                (it->is_directory(ec) && it->path().extension() == ".zip" &&
                 it->path().filename().string()[0] != '.'))
                uploads.push_back("upload:" + it->path().filename().string());
        std::sort(uploads.begin(), uploads.end());
        out.insert(out.end(), uploads.begin(), uploads.end());
    }
    if (!mDefault.empty() && std::find(out.begin(), out.end(), mDefault) == out.end())
        out.push_back(mDefault);
    return out;
}

std::string SceneCatalog::resolve(const std::string& name, const std::string& uploadDir) const {
    if (name == mDefault && !name.empty()) return name;
    if (name.rfind("builtin:", 0) == 0) {
        for (const auto& n : builtinSceneNames())
            if (name == "builtin:" + n) return name;
    } else if (name.rfind("file:", 0) == 0) {
        const std::string rel = name.substr(5);
        if (!rel.empty() && rel[0] != '/' && isSceneFile(rel)) {
            for (const auto& dir : mDirs) {
                std::string resolved;
                if (inside(fs::path(dir) / rel, dir, resolved)) return resolved;
            }
        }
    } else if (name.rfind("upload:", 0) == 0 && !uploadDir.empty()) {
        const std::string file = name.substr(7);
        bool safe = true;
        try {
            checkUploadName(file);
        } catch (const InputError&) {
            safe = false;
        }
        std::error_code ec;
        const fs::path root = fs::canonical(uploadDir, ec);
        std::string resolved;
        if (safe && !ec && inside(root / file, root.string(), resolved)) {
            if (!file.ends_with(".zip")) return resolved;
            // An extracted archive: its one scene file, which must stay inside the folder.
            const std::optional<fs::path> scene = findArchivedScene(resolved);
            std::string sceneFile;
            if (scene && inside(*scene, resolved, sceneFile)) return sceneFile;
        }
    }
    throw InputError("/name",
                     "unknown scene '" + name + "': pick one from welcome.scenes or GET /api/scenes");
}

SceneLoadOptions SceneCatalog::loadOptions(const std::string& name) const {
    SceneLoadOptions options;
    options.displayName = name;
    if (name == mDefault) return options; // the operator's own choice: no budget
    // A zipped upload's .gltf reads its .bin and textures from its own folder (the sandbox keeps it
    // there); a .glb upload is self-contained.
    options.allowExternalFiles = name.rfind("upload:", 0) != 0 || name.ends_with(".zip");
    options.maxDecodedBytes = mMaxDecodedBytes;
    return options;
}

void SceneCatalog::checkUploadName(const std::string& name) {
    const bool charsOk = std::all_of(name.begin(), name.end(), [](unsigned char c) {
        return std::isalnum(c) || c == '.' || c == '_' || c == '-';
    });
    if (name.empty() || name.size() > 100 || !charsOk || name[0] == '.' ||
        !(name.ends_with(".glb") || name.ends_with(".zip")))
        throw InputError(
            "name", "upload names use letters, digits, '.', '_' and '-', end in .glb (binary glTF) or .zip "
                    "(a .gltf with its files) and have at most 100 characters, got '" +
                        name + "'");
}

} // namespace gis
