// Which scene names a client may ask for, and where they live. Names never resolve outside the
// configured places:
//   builtin:NAME          the scenes built in code
//   file:REL/PATH.glb     a .gltf/.glb file under one of the scene directories (realpath checked)
//   upload:NAME.glb       a file in the asking session's upload sandbox
// plus the server's default scene exactly as configured (it may be any file the operator chose).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "scene/SceneLoader.h"

namespace gis {

class SceneCatalog {
public:
    SceneCatalog() = default;
    /// Throws InputError when a directory does not exist. `maxDecodedBytes` (0: none) bounds what one
    /// client-chosen scene file (file: or upload:) may take once decoded.
    SceneCatalog(std::vector<std::string> sceneDirs, std::string defaultScene,
                 std::uint64_t maxDecodedBytes = 0);

    /// Every name a client may load (built-in scenes, files of the scene directories, the default),
    /// sorted within each group. `uploadDir` adds that session's uploads.
    std::vector<std::string> list(const std::string& uploadDir = {}) const;
    /// The loadable name (builtin:NAME or an absolute file path) for a client's scene name. Throws
    /// InputError with where = "/name" when the name is unknown or escapes its directory.
    std::string resolve(const std::string& name, const std::string& uploadDir = {}) const;

    /// How to load a client's scene name: errors name it as the client wrote it (never a server
    /// path); uploads may not reach external files; client-chosen files get the decoded-size budget.
    SceneLoadOptions loadOptions(const std::string& name) const;

    /// A safe file name for an upload: [A-Za-z0-9._-], ends in .glb or .zip (a .gltf with its files,
    /// extracted into a folder of that name), at most 100 characters, no leading dot. Throws
    /// InputError(where = "name") otherwise.
    static void checkUploadName(const std::string& name);

private:
    std::vector<std::string> mDirs; ///< realpaths
    std::string mDefault;
    std::uint64_t mMaxDecodedBytes = 0;
};

} // namespace gis
