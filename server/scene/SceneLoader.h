// Scene loading entry points: built-in scenes and glTF files, both finished the same way so every
// consumer can rely on the guarantees listed on finalizeScene. Only gis::InputError leaves these
// functions; bad files never crash the process.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/Error.h"
#include "scene/Scene.h"

namespace gis {

/// What a scene file may reach and cost, and what its errors call it. The defaults fit files an
/// operator or a developer chose; the server loads clients' files with a display name, a budget and,
/// for uploads, no external files.
///
/// Whatever the options, a glTF file's external URIs resolve only inside the file's own directory:
/// absolute paths and '..' segments are refused, and symbolic links that lead out of it too.
/// Where a glTF load is, for a user waiting on a big file. Stages run in this order (a stage the file
/// does not need is passed over): reading the file, decoding Draco/meshopt data, decoding images,
/// reading the node graph's meshes, finishing (normals, tangents, validation).
struct SceneLoadProgress {
    enum class Stage { Reading, Decompressing, Images, Meshes, Finishing } stage = Stage::Reading;
    std::size_t done = 0, total = 0; ///< images decoded / mesh primitives read (0 of 0 elsewhere)
    std::uint64_t bytesRead = 0;     ///< of the file and its external files so far
    std::uint64_t fileBytes = 0;     ///< the file's own size
    double share = 0.0;              ///< of the whole load, [0, 1], never falling
    /// "decoding images: 3 of 12", for a progress line.
    std::string describe() const;
};

struct SceneLoadOptions {
    std::string displayName;           ///< how errors, logs and Scene::name call the file ("": the path)
    bool allowExternalFiles = true;    ///< false: only the GLB's own chunk and data: URIs (uploads)
    std::uint64_t maxDecodedBytes = 0; ///< file + external files + decoded images + geometry; 0: none
    /// Called on the loading thread as a glTF load advances (every file chunk, image and mesh
    /// primitive: the callee throttles); null for none. It must not throw. Built-in scenes, which
    /// generate in milliseconds, report nothing.
    std::function<void(const SceneLoadProgress&)> onProgress;
    /// Asked on the loading thread between file chunks, images and mesh primitives; once it answers
    /// true the load stops there and throws LoadCancelled (a newer scene was asked for, or the
    /// session ended). Null: never cancelled. It must not throw.
    std::function<bool()> cancelled;
};

/// A load stopped because SceneLoadOptions::cancelled asked it to: no fault of the file.
class LoadCancelled : public InputError {
public:
    explicit LoadCancelled(std::string where) : InputError(std::move(where), "the load was cancelled") {}
};

/// Deepest JSON nesting a glTF file may have: far beyond what exporters write (extras included),
/// and shallow enough for tinygltf's recursive walk of extras and extensions.
constexpr int kMaxGltfJsonDepth = 128;

/// "builtin:NAME" for a scene generated in code, otherwise a path ending in .gltf or .glb.
Scene loadScene(const std::string& name, const SceneLoadOptions& options = {});

/// Names accepted by makeBuiltinScene (and by loadScene after "builtin:").
std::vector<std::string> builtinSceneNames();
Scene makeBuiltinScene(const std::string& name);

/// Loads a .gltf (JSON, external or data-URI buffers) or .glb file, flattened to world space.
/// Every InputError names `options.displayName` (or the path), never another server path.
Scene loadGltf(const std::string& path, const SceneLoadOptions& options = {});

/// Brings a freshly built scene to the loaded-scene guarantees, then validates it:
///  - missing normals generated as area-weighted vertex normals (cross products summed over the
///    triangles sharing an index, so shared vertices smooth and split vertices stay hard);
///  - non-finite or zero normals replaced by the face normal, or (0, 1, 0) on degenerate faces;
///  - a default white diffuse material when there is none;
///  - bounds recomputed, and a camera framing them when there is none.
/// Throws InputError(where, ...) when the scene is still invalid.
void finalizeScene(Scene& scene, const std::string& where);

/// Checks the invariants documented in Scene.h; throws InputError(where, message naming the mesh,
/// light, material or camera and the problem). Degenerate triangles are allowed.
void validateScene(const Scene& scene, const std::string& where);

} // namespace gis
