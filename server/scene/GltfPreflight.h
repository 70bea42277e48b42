// Checks a glTF document's JSON before the parser builds a model from it, so that a file this service
// cannot show is refused with what is wrong, where (a JSON path such as `textures[2].source`) and
// what to do, rather than with a parser message about a consequence:
//   - `asset.version` (and `asset.minVersion`) must be 2.x: glTF 1.0 and any later major version are
//     refused;
//   - every extension in `extensionsRequired` must be one the loader reads (gltfReadableExtensions;
//     Draco and meshopt are decoded before this check, scene/GltfDecompress.h); compressed textures
//     get advice on how to export without them;
//   - every index into another array (scene nodes, node children, meshes, cameras, lights,
//     primitive attributes, indices and materials, material textures, texture images and samplers,
//     accessor and image buffer views, buffer view buffers) must name an element that exists.
// Throws gis::InputError naming `fileName`; a document that is not JSON at all is left to the parser.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace gis {

/// The extensions a file may require: the loader reads them.
const std::vector<std::string>& gltfReadableExtensions();

/// What the checked document holds, for the loader's progress (zeros when the JSON does not parse).
struct GltfOutline {
    std::size_t images = 0;
};

GltfOutline preflightGltfJson(std::string_view json, const std::string& fileName);

} // namespace gis
