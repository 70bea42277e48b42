// Which scene names a client may ask for, and where they live. Names never resolve outside the
// configured places:
//   builtin:NAME          the scenes built in code
//   file:REL/PATH.glb     a .gltf/.glb file under one of the scene directories (realpath checked)
//   upload:NAME.glb       a file in the asking session's upload sandbox
// plus the server's default scene exactly as configured (it may be any file the operator chose).
#pragma once

#include <string>
#include <vector>

namespace gis {

class SceneCatalog {
public:
    SceneCatalog() = default;
    /// Throws InputError when a directory does not exist.
    SceneCatalog(std::vector<std::string> sceneDirs, std::string defaultScene);

    /// Every name a client may load (built-in scenes, files of the scene directories, the default),
    /// sorted within each group. `uploadDir` adds that session's uploads.
    std::vector<std::string> list(const std::string& uploadDir = {}) const;
    /// The loadable name (builtin:NAME or an absolute file path) for a client's scene name. Throws
    /// InputError with where = "/name" when the name is unknown or escapes its directory.
    std::string resolve(const std::string& name, const std::string& uploadDir = {}) const;

    /// A safe file name for an upload: [A-Za-z0-9._-], ends in .glb, at most 100 characters, no
    /// leading dot. Throws InputError(where = "name") otherwise.
    static void checkUploadName(const std::string& name);

private:
    std::vector<std::string> mDirs; ///< realpaths
    std::string mDefault;
};

} // namespace gis
