// Compressed glTF, decoded before the parser sees the file: tinygltf (Debian's shared library, built
// without Draco) reads only plain accessors, so a file that uses
//   - KHR_draco_mesh_compression (Draco, through Debian's libdraco): each compressed primitive's
//     indices and attributes are decoded to uint32 indices and float attributes (normalized integer
//     data scaled to [0, 1] or [-1, 1] as the accessor says);
//   - EXT_meshopt_compression / KHR_meshopt_compression (through Debian's libmeshoptimizer): each
//     compressed buffer view is decoded (ATTRIBUTES, TRIANGLES, INDICES; the OCTAHEDRAL, QUATERNION
//     and EXPONENTIAL filters) in place of its fallback buffer;
// is rewritten into the same container with the decoded bytes appended (a GLB's binary chunk, or a
// new data-URI buffer for .gltf) and the extensions removed from the document. Compressed data in an
// external file is read through `readExternal` (the loader's sandbox, which refuses it for uploads).
// Every decoded block is charged to `spend` before it is allocated.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gis {

struct DecompressedGltf {
    std::string bytes;                ///< the rewritten file (same container as the input)
    std::vector<std::string> decoded; ///< what was decoded, for the log ("Draco: 3 primitives")
};

/// The extensions decompressGltf decodes.
const std::vector<std::string>& gltfDecodedExtensions();

/// `bytes`: the whole file (`binary`: a GLB); `json`: its JSON (the GLB's JSON chunk). nullopt when
/// the document uses no compression. Throws gis::InputError naming `fileName` when data cannot be
/// decoded, or when `spend(bytes, what)` refuses the memory (its own refusal is the message then).
/// `readExternal(uri)` returns an external buffer's bytes or throws gis::InputError.
std::optional<DecompressedGltf>
decompressGltf(const std::string& bytes, bool binary, std::string_view json, const std::string& fileName,
               const std::function<bool(std::uint64_t, const std::string&)>& spend,
               const std::function<std::string(const std::string& uri)>& readExternal);

} // namespace gis
