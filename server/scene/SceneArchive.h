// Zipped glTF: a .gltf with its .bin and textures as model sites and exporters hand them out, or a
// .glb, in one .zip. Extracted with Debian's libzip into a folder of its own, every entry checked
// (hostile archives are expected: uploads), then loaded like any file in that folder.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "core/Error.h"

namespace gis {

/// The archive unpacks to more than ArchiveLimits::maxBytes (a budget answer, not a damaged file).
class ArchiveTooLarge : public InputError {
public:
    using InputError::InputError;
};

struct ArchiveLimits {
    std::uint64_t maxBytes = 256ull << 20; ///< all entries together, uncompressed (counted as read)
    int maxEntries = 4096;
};

/// Extracts the zip archive `bytes` into `dest` (created; it must not exist) and returns the path of
/// its scene file relative to `dest`. Refuses with InputError(displayName, what and what to do): not
/// a zip or damaged, encrypted entries, more entries or bytes than `limits`, entry names that are
/// absolute or climb out with '..', symbolic links, and archives holding no scene file or several
/// (named). macOS metadata (__MACOSX/, ._*) is left out. On an error nothing is left in `dest`.
std::string extractSceneArchive(const std::string& bytes, const std::filesystem::path& dest,
                                const ArchiveLimits& limits, const std::string& displayName);

/// The one .gltf or .glb under an extracted archive's folder, or nothing.
std::optional<std::filesystem::path> findArchivedScene(const std::filesystem::path& dir);

/// Whether `bytes` start like a zip archive (a local file header or an empty archive's end record).
bool looksLikeZip(const std::string& bytes);

} // namespace gis
