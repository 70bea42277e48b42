// glTF 2.0 (.gltf / .glb) to Scene, through Debian's shared tinygltf build. tinygltf parses the
// JSON and decodes buffers and images; everything it does not check (accessor ranges, index values,
// transforms, extensions) is checked here before any byte is read, so a hostile file yields an
// InputError naming the file and the offending object instead of a crash.
#include <algorithm>
#include <functional>
#include <map>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <optional>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <stb_image.h>
#include <tiny_gltf.h>

#include "core/Error.h"
#include "core/JsonSchema.h"
#include "core/Log.h"
#include "scene/Geometry.h"
#include "scene/GltfDecompress.h"
#include "scene/GltfPreflight.h"
#include "scene/SceneLoader.h"

namespace gis {
namespace {

constexpr const char* kLightsExtension = "KHR_lights_punctual";
constexpr const char* kGpuInstancingExtension = "EXT_mesh_gpu_instancing";
constexpr const char* kEmissiveStrengthExtension = "KHR_materials_emissive_strength";
constexpr const char* kSpecularExtension = "KHR_materials_specular";
constexpr const char* kTextureTransformExtension = "KHR_texture_transform";
constexpr int kNotConverted = -2;

/// tinygltf joins several messages with newlines; an InputError reads best as one line.
std::string oneLine(const std::string& text) {
    std::string out;
    std::size_t start = 0;
    while (start < text.size()) {
        std::size_t end = text.find('\n', start);
        if (end == std::string::npos) end = text.size();
        std::string line = text.substr(start, end - start);
        line.erase(0, line.find_first_not_of(" \t\r"));
        line.erase(line.find_last_not_of(" \t\r") + 1);
        if (!line.empty()) out += (out.empty() ? "" : "; ") + line;
        start = end + 1;
    }
    return out;
}

std::string mib(std::uint64_t bytes) {
    return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB";
}

/// What one load may reach and spend, shared by tinygltf's file and image callbacks and the reader.
/// A refusal is recorded here (the callbacks can only answer false) and turned into the load's error.
struct LoadContext {
    std::string name;           ///< the file as errors call it
    std::string baseDir;        ///< the file's directory as tinygltf joins it ("/abs/dir")
    std::filesystem::path root; ///< canonical baseDir: external files must resolve below it
    bool allowExternal = true;
    std::uint64_t budget = 0; ///< 0: no limit
    std::uint64_t spent = 0;
    std::string refusal; ///< the first refusal, for the error message
    std::function<void(const SceneLoadProgress&)> onProgress;
    std::function<bool()> cancelled;
    bool cancelSeen = false;
    SceneLoadProgress progress;
    std::size_t imagesTotal = 0, imagesDecoded = 0; ///< images in the document, decoded so far

    /// Where each stage's share of the load starts; a stage the file does not need takes none.
    struct StageShares {
        double decompress = 0.1, images = 0.2, meshes = 0.6, finishing = 0.95;
    } shares;
    /// Reports `done` of `total` in `stage`; the share rises linearly inside the stage's range.
    void report(SceneLoadProgress::Stage stage, std::size_t done, std::size_t total) {
        if (!onProgress) return;
        using S = SceneLoadProgress::Stage;
        const double from = stage == S::Reading         ? 0.0
                            : stage == S::Decompressing ? shares.decompress
                            : stage == S::Images        ? shares.images
                            : stage == S::Meshes        ? shares.meshes
                                                        : shares.finishing;
        const double to = stage == S::Reading         ? shares.decompress
                          : stage == S::Decompressing ? shares.images
                          : stage == S::Images        ? shares.meshes
                          : stage == S::Meshes        ? shares.finishing
                                                      : 1.0;
        const double within = total > 0 ? static_cast<double>(std::min(done, total)) / total : 0.0;
        progress.stage = stage;
        progress.done = std::min(done, total);
        progress.total = total;
        progress.share = std::max(progress.share, from + (to - from) * within);
        onProgress(progress);
    }

    /// True once the load is no longer wanted (and from then on). tinygltf's callbacks answer false
    /// on it; the loader's own loops call throwIfCancelled.
    bool cancelRequested() {
        if (!cancelSeen && cancelled && cancelled()) cancelSeen = true;
        return cancelSeen;
    }
    void throwIfCancelled() {
        if (cancelRequested()) throw LoadCancelled(name);
    }

    /// Counts `bytes` against the budget; false (with the refusal recorded) when it would overflow.
    bool spend(std::uint64_t bytes, const std::string& what) {
        if (budget == 0 || (bytes <= budget && spent <= budget - bytes)) {
            spent += bytes;
            return true;
        }
        if (refusal.empty())
            refusal = what + " would take " + mib(bytes) + " in memory and the scene already uses " +
                      mib(spent) + "; this server loads scenes of at most " + mib(budget) +
                      " once decoded (buffers, images and geometry): use smaller or fewer textures, or "
                      "fewer instances";
        return false;
    }
    void refuse(const std::string& why) {
        if (refusal.empty()) refusal = why;
    }
};

bool hasDotDotSegment(const std::string& rel) {
    std::size_t start = 0;
    while (start <= rel.size()) {
        std::size_t end = rel.find_first_of("/\\", start);
        if (end == std::string::npos) end = rel.size();
        if (rel.compare(start, end - start, "..") == 0) return true;
        start = end + 1;
    }
    return false;
}

/// The URI as the file wrote it (after tinygltf's percent-decoding), when `absPath` is tinygltf's
/// candidate in the file's own directory; nullopt for its other candidate (the working directory),
/// which is never searched.
std::optional<std::string> uriInBaseDir(const LoadContext& c, const std::string& absPath) {
    const std::string prefix = c.baseDir + "/";
    if (absPath.compare(0, prefix.size(), prefix) != 0) return std::nullopt;
    return absPath.substr(prefix.size());
}

/// Whether the file tinygltf asks for may be read; records why not. Symbolic links are resolved: a
/// link inside the folder that points out of it is refused like a '..' path.
bool externalAllowed(LoadContext& c, const std::string& absPath) {
    const auto uri = uriInBaseDir(c, absPath);
    if (!uri) return false;
    if (!c.allowExternal) {
        c.refuse("refers to the external file '" + validUtf8(*uri) +
                 "'; uploaded files must be self-contained: export a binary glTF (.glb) with its buffers "
                 "and textures embedded");
        logWarn("scene: sandbox: " + c.name + " asked for external file '" + validUtf8(*uri) + "' (refused)");
        return false;
    }
    if (uri->empty() || (*uri)[0] == '/' || (*uri)[0] == '\\' || hasDotDotSegment(*uri) ||
        uri->find(':') != std::string::npos) {
        c.refuse("refers to '" + validUtf8(*uri) +
                 "', outside its own folder; external buffers and images must be relative paths below the "
                 "glTF file, without '..'");
        logWarn("scene: sandbox: " + c.name + " asked for '" + validUtf8(*uri) +
                "' (refused: outside its folder)");
        return false;
    }
    std::error_code ec;
    const std::filesystem::path resolved = std::filesystem::weakly_canonical(absPath, ec);
    const std::string r = resolved.string(), root = c.root.string() + "/";
    if (ec || r.compare(0, root.size(), root) != 0) {
        c.refuse("refers to '" + validUtf8(*uri) + "', which leads outside its own folder");
        logWarn("scene: sandbox: " + c.name + " asked for '" + validUtf8(*uri) +
                "' (refused: a link out of its folder)");
        return false;
    }
    return true;
}

bool sandboxFileExists(const std::string& absPath, void* user) {
    auto& c = *static_cast<LoadContext*>(user);
    if (c.cancelRequested() || !externalAllowed(c, absPath)) return false;
    std::error_code ec;
    return std::filesystem::is_regular_file(absPath, ec);
}

std::string sandboxExpandPath(const std::string& path, void*) {
    return path;
} // no ~ or $VAR expansion

bool sandboxReadFile(std::vector<unsigned char>* out, std::string* err, const std::string& absPath,
                     void* user) {
    auto& c = *static_cast<LoadContext*>(user);
    if (c.cancelRequested() || !externalAllowed(c, absPath)) return false;
    std::error_code ec;
    const auto size = std::filesystem::file_size(absPath, ec);
    const std::string uri = uriInBaseDir(c, absPath).value_or("?");
    if (ec) {
        if (err) *err = "cannot read '" + validUtf8(uri) + "'";
        return false;
    }
    if (!c.spend(size, "the external file '" + validUtf8(uri) + "'")) return false;
    std::ifstream in(absPath, std::ios::binary);
    out->resize(size);
    if (size > 0 && !in.read(reinterpret_cast<char*>(out->data()), static_cast<std::streamsize>(size))) {
        if (err) *err = "cannot read '" + validUtf8(uri) + "'";
        return false;
    }
    c.progress.bytesRead += size;
    return true;
}

bool sandboxWriteFile(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err = "the loader writes no files";
    return false;
}

/// tinygltf's image callback: the decoded size is read from the image's header and charged to the
/// budget before a pixel is decoded, so a small file with a huge texture costs only its header.
bool budgetedImageLoader(tinygltf::Image* image, const int index, std::string* err, std::string* warn,
                         int reqWidth, int reqHeight, const unsigned char* bytes, int size, void* user) {
    auto& c = *static_cast<LoadContext*>(user);
    if (c.cancelRequested()) return false; // the load throws LoadCancelled once tinygltf returns
    int w = 0, h = 0, comp = 0;
    if (size <= 0 || !stbi_info_from_memory(bytes, size, &w, &h, &comp) || w <= 0 || h <= 0) {
        if (err)
            *err +=
                "image " + std::to_string(index) + " is not a PNG, JPEG or other format the loader decodes\n";
        return false;
    }
    constexpr int kMaxSide = 16384; // GL_MAX_TEXTURE_SIZE on llvmpipe; larger could not be sampled anyway
    if (w > kMaxSide || h > kMaxSide) {
        c.refuse("image " + std::to_string(index) + " is " + std::to_string(w) + "x" + std::to_string(h) +
                 "; textures may be at most " + std::to_string(kMaxSide) + " pixels on a side");
        return false;
    }
    const bool wide = stbi_is_16_bit_from_memory(bytes, size) != 0;
    // tinygltf decodes to 4 channels; the reader then converts to RGBA8 beside it.
    const std::uint64_t pixels = static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h);
    const std::uint64_t cost = pixels * 4 * (wide ? 2 : 1) + pixels * 4;
    if (!c.spend(cost,
                 "image " + std::to_string(index) + " (" + std::to_string(w) + "x" + std::to_string(h) + ")"))
        return false;
    const bool decoded =
        tinygltf::LoadImageData(image, index, err, warn, reqWidth, reqHeight, bytes, size, nullptr);
    c.report(SceneLoadProgress::Stage::Images, ++c.imagesDecoded, c.imagesTotal);
    return decoded;
}

int componentCount(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR:
        return 1;
    case TINYGLTF_TYPE_VEC2:
        return 2;
    case TINYGLTF_TYPE_VEC3:
        return 3;
    case TINYGLTF_TYPE_VEC4:
        return 4;
    case TINYGLTF_TYPE_MAT2:
        return 4;
    case TINYGLTF_TYPE_MAT3:
        return 9;
    case TINYGLTF_TYPE_MAT4:
        return 16;
    default:
        return 0;
    }
}

std::size_t componentSize(int componentType) {
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return 4;
    default:
        return 0;
    }
}

template <typename T> T loadUnaligned(const unsigned char* p) {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return v;
}

/// One component as float, applying the glTF normalisation rules when the accessor is normalized.
float readComponent(const unsigned char* p, int componentType, bool normalized) {
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return loadUnaligned<float>(p);
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        const float v = loadUnaligned<std::int8_t>(p);
        return normalized ? std::max(v / 127.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
        const float v = loadUnaligned<std::uint8_t>(p);
        return normalized ? v / 255.0f : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        const float v = loadUnaligned<std::int16_t>(p);
        return normalized ? std::max(v / 32767.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        const float v = loadUnaligned<std::uint16_t>(p);
        return normalized ? v / 65535.0f : v;
    }
    default: {
        const auto v = static_cast<double>(loadUnaligned<std::uint32_t>(p));
        return static_cast<float>(normalized ? v / 4294967295.0 : v);
    }
    }
}

glm::mat4 localMatrix(const tinygltf::Node& node) {
    if (node.matrix.size() == 16) {
        glm::mat4 m(1.0f);
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r)
                m[c][r] = static_cast<float>(node.matrix[static_cast<std::size_t>(c * 4 + r)]);
        return m;
    }
    glm::mat4 m(1.0f);
    if (node.translation.size() == 3)
        m = glm::translate(m, glm::vec3(node.translation[0], node.translation[1], node.translation[2]));
    if (node.rotation.size() == 4) {
        // glTF stores (x, y, z, w); glm's constructor takes w first.
        glm::quat q(static_cast<float>(node.rotation[3]), static_cast<float>(node.rotation[0]),
                    static_cast<float>(node.rotation[1]), static_cast<float>(node.rotation[2]));
        const float len = glm::length(q);
        if (std::isfinite(len) && len > 1e-12f) m *= glm::mat4_cast(q / len);
    }
    if (node.scale.size() == 3) m = glm::scale(m, glm::vec3(node.scale[0], node.scale[1], node.scale[2]));
    return m;
}

std::string nameOr(const std::string& name, const char* kind, int index) {
    return name.empty() ? std::string(kind) + " " + std::to_string(index) : name;
}

/// Where an accessor's elements lie, after every range check has passed.
struct AccessorView {
    const unsigned char* data = nullptr;
    std::size_t count = 0;
    std::size_t stride = 0;
    int componentType = 0;
    int components = 0;
    bool normalized = false;
};

class GltfReader {
public:
    GltfReader(const tinygltf::Model& model, LoadContext& context)
        : mModel(model), mPath(context.name), mContext(context),
          mImageTexture(model.images.size(), kNotConverted),
          mLinearImageTexture(model.images.size(), kNotConverted), mOnPath(model.nodes.size(), false) {}

    Scene read() {
        checkRequiredExtensions();
        // Each node is one tree's (glTF): the nodes' primitives are what the walk reads.
        for (const auto& node : mModel.nodes)
            if (node.mesh >= 0 && node.mesh < static_cast<int>(mModel.meshes.size()))
                mPrimitivesTotal += mModel.meshes[static_cast<std::size_t>(node.mesh)].primitives.size();
        mContext.report(SceneLoadProgress::Stage::Meshes, 0, mPrimitivesTotal);
        readMaterials();
        collectNotShown();
        for (int root : rootNodes()) visitNode(root, glm::mat4(1.0f));
        addPlacedMeshes();
        mScene.name = mPath;
        mScene.updateBounds();
        closeInfiniteFarPlanes();
        mContext.throwIfCancelled();
        mContext.report(SceneLoadProgress::Stage::Finishing, 0, 0);
        finalizeScene(mScene, mPath);
        return std::move(mScene);
    }

private:
    [[noreturn]] void fail(const std::string& message) const { throw InputError(mPath, message); }
    void warn(const std::string& message) const { logWarn("scene: " + mPath + ": " + message); }

    // preflightGltfJson refused these already, with advice; a model built another way is checked too.
    void checkRequiredExtensions() const {
        const auto& readable = gltfReadableExtensions();
        for (const auto& ext : mModel.extensionsRequired)
            if (std::find(readable.begin(), readable.end(), ext) == readable.end())
                fail("unsupported required extension '" + ext + "'");
    }

    std::vector<int> rootNodes() const {
        if (!mModel.scenes.empty()) {
            const int s = mModel.defaultScene < 0 ? 0 : mModel.defaultScene;
            if (s >= static_cast<int>(mModel.scenes.size()))
                fail("default scene " + std::to_string(s) + " does not exist");
            return mModel.scenes[static_cast<std::size_t>(s)].nodes;
        }
        std::vector<bool> isChild(mModel.nodes.size(), false);
        for (const auto& node : mModel.nodes)
            for (int c : node.children)
                if (c >= 0 && c < static_cast<int>(isChild.size()))
                    isChild[static_cast<std::size_t>(c)] = true;
        std::vector<int> roots;
        for (std::size_t i = 0; i < isChild.size(); ++i)
            if (!isChild[i]) roots.push_back(static_cast<int>(i));
        return roots;
    }

    void visitNode(int index, const glm::mat4& parent) {
        if (index < 0 || index >= static_cast<int>(mModel.nodes.size()))
            fail("node " + std::to_string(index) + " does not exist");
        const auto i = static_cast<std::size_t>(index);
        if (mOnPath[i])
            fail("node " + std::to_string(index) + " is its own ancestor (cycle in the node graph)");
        mOnPath[i] = true;
        const tinygltf::Node& node = mModel.nodes[i];
        const glm::mat4 world = parent * localMatrix(node);
        if (node.mesh >= 0) {
            if (const auto ext = node.extensions.find(kGpuInstancingExtension); ext != node.extensions.end())
                addGpuInstances(index, world, ext->second);
            else
                mPlacements.push_back({node.mesh, world});
        }
        if (node.camera >= 0) addCamera(node, index, world);
        addNodeLight(node, index, world);
        for (int child : node.children) visitNode(child, world);
        mOnPath[i] = false;
    }

    // ---- accessors -------------------------------------------------------------------------------

    AccessorView accessorView(int index, int expectedType, const std::string& context) const {
        const std::string where = context + ": accessor " + std::to_string(index);
        if (index < 0 || index >= static_cast<int>(mModel.accessors.size())) fail(where + " does not exist");
        const tinygltf::Accessor& acc = mModel.accessors[static_cast<std::size_t>(index)];
        if (acc.sparse.isSparse) fail(where + ": sparse accessors are not supported");
        if (acc.type != expectedType)
            fail(where + ": expected " + std::to_string(componentCount(expectedType)) +
                 " components per element, got " + std::to_string(componentCount(acc.type)));
        const std::size_t componentBytes = componentSize(acc.componentType);
        if (componentBytes == 0)
            fail(where + ": unsupported component type " + std::to_string(acc.componentType));
        AccessorView view{.count = acc.count,
                          .componentType = acc.componentType,
                          .components = componentCount(acc.type),
                          .normalized = acc.normalized};
        if (acc.count == 0) return view;
        if (acc.bufferView < 0 || acc.bufferView >= static_cast<int>(mModel.bufferViews.size()))
            fail(where + ": bufferView " + std::to_string(acc.bufferView) + " does not exist");
        const tinygltf::BufferView& bv = mModel.bufferViews[static_cast<std::size_t>(acc.bufferView)];
        if (bv.buffer < 0 || bv.buffer >= static_cast<int>(mModel.buffers.size()))
            fail(where + ": buffer " + std::to_string(bv.buffer) + " does not exist");
        const std::vector<unsigned char>& data = mModel.buffers[static_cast<std::size_t>(bv.buffer)].data;
        if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
            fail(where + ": bufferView " + std::to_string(acc.bufferView) + " (offset " +
                 std::to_string(bv.byteOffset) + ", length " + std::to_string(bv.byteLength) +
                 ") extends past the end of buffer " + std::to_string(bv.buffer) + " (" +
                 std::to_string(data.size()) + " bytes)");
        const std::size_t elementBytes = componentBytes * static_cast<std::size_t>(view.components);
        view.stride = bv.byteStride != 0 ? bv.byteStride : elementBytes;
        if (view.stride < elementBytes)
            fail(where + ": byteStride " + std::to_string(view.stride) + " is smaller than an element (" +
                 std::to_string(elementBytes) + " bytes)");
        // Needs offset + (count - 1) * stride + elementBytes <= byteLength, written so nothing overflows.
        const bool fits = acc.byteOffset <= bv.byteLength && elementBytes <= bv.byteLength - acc.byteOffset &&
                          acc.count - 1 <= (bv.byteLength - acc.byteOffset - elementBytes) / view.stride;
        if (!fits)
            fail(where + " (offset " + std::to_string(acc.byteOffset) + ", " + std::to_string(acc.count) +
                 " elements, stride " + std::to_string(view.stride) + ") reads past the end of bufferView " +
                 std::to_string(acc.bufferView) + " (" + std::to_string(bv.byteLength) + " bytes)");
        view.data = data.data() + bv.byteOffset + acc.byteOffset;
        return view;
    }

    template <int N>
    std::vector<glm::vec<N, float>> readVectors(int index, int type, const std::string& context) const {
        const AccessorView v = accessorView(index, type, context);
        const std::size_t componentBytes = componentSize(v.componentType);
        std::vector<glm::vec<N, float>> out(v.count);
        for (std::size_t e = 0; e < v.count; ++e)
            for (int c = 0; c < N; ++c)
                out[e][c] =
                    readComponent(v.data + e * v.stride + static_cast<std::size_t>(c) * componentBytes,
                                  v.componentType, v.normalized);
        return out;
    }

    std::vector<std::uint32_t> readIndices(int index, const std::string& context) const {
        const AccessorView v = accessorView(index, TINYGLTF_TYPE_SCALAR, context);
        const int type = v.componentType;
        if (type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail(context + ": accessor " + std::to_string(index) +
                 ": indices must be unsigned byte, short or int");
        std::vector<std::uint32_t> out(v.count);
        for (std::size_t e = 0; e < v.count; ++e) {
            const unsigned char* p = v.data + e * v.stride;
            out[e] = type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? loadUnaligned<std::uint8_t>(p)
                     : type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? loadUnaligned<std::uint16_t>(p)
                                                                      : loadUnaligned<std::uint32_t>(p);
        }
        return out;
    }

    // ---- materials and textures ------------------------------------------------------------------

    void readMaterials() {
        for (std::size_t i = 0; i < mModel.materials.size(); ++i) {
            const tinygltf::Material& src = mModel.materials[i];
            const auto& pbr = src.pbrMetallicRoughness;
            Material m;
            m.name = nameOr(src.name, "material", static_cast<int>(i));
            if (pbr.baseColorFactor.size() == 4)
                m.baseColor = glm::clamp(glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1],
                                                   pbr.baseColorFactor[2], pbr.baseColorFactor[3]),
                                         0.0f, 1.0f);
            m.metallic = std::clamp(static_cast<float>(pbr.metallicFactor), 0.0f, 1.0f);
            m.roughness = std::clamp(static_cast<float>(pbr.roughnessFactor), 0.0f, 1.0f);
            if (src.emissiveFactor.size() == 3)
                m.emissive = glm::vec3(src.emissiveFactor[0], src.emissiveFactor[1], src.emissiveFactor[2]);
            const auto strength = src.extensions.find(kEmissiveStrengthExtension);
            if (strength != src.extensions.end() && strength->second.IsObject() &&
                strength->second.Has("emissiveStrength") &&
                strength->second.Get("emissiveStrength").IsNumber())
                m.emissive *=
                    static_cast<float>(strength->second.Get("emissiveStrength").GetNumberAsDouble());
            // glTF's default dielectric reflects F0 = 0.04; KHR_materials_specular scales it.
            m.specular = 1.0f;
            const auto spec = src.extensions.find(kSpecularExtension);
            if (spec != src.extensions.end() && spec->second.IsObject() &&
                spec->second.Has("specularFactor") && spec->second.Get("specularFactor").IsNumber()) {
                const double f = spec->second.Get("specularFactor").GetNumberAsDouble();
                m.specular = std::isfinite(f) ? std::clamp(static_cast<float>(f), 0.0f, 1.0f) : 1.0f;
            }
            const std::string where = "material '" + m.name + "'";
            if (pbr.baseColorTexture.index >= 0)
                m.baseColorTexture = convertTexture(pbr.baseColorTexture.index, where);
            if (pbr.metallicRoughnessTexture.index >= 0)
                m.metallicRoughnessTexture =
                    convertTexture(pbr.metallicRoughnessTexture.index, where + " metallic-roughness", false);
            if (src.emissiveTexture.index >= 0)
                m.emissiveTexture = convertTexture(src.emissiveTexture.index, where + " emissive");
            if (src.occlusionTexture.index >= 0) {
                m.occlusionTexture = convertTexture(src.occlusionTexture.index, where + " occlusion", false);
                m.occlusionStrength =
                    std::isfinite(src.occlusionTexture.strength)
                        ? std::clamp(static_cast<float>(src.occlusionTexture.strength), 0.0f, 1.0f)
                        : 1.0f;
            }
            if (src.normalTexture.index >= 0) {
                m.normalTexture = convertTexture(src.normalTexture.index, where + " normal", false);
                m.normalScale = std::isfinite(src.normalTexture.scale)
                                    ? static_cast<float>(src.normalTexture.scale)
                                    : 1.0f;
            }
            m.doubleSided = src.doubleSided;
            if (src.alphaMode == "MASK") m.alphaMode = Material::Alpha::Mask;
            if (src.alphaMode == "BLEND") m.alphaMode = Material::Alpha::Blend;
            m.alphaCutoff = std::isfinite(src.alphaCutoff)
                                ? std::clamp(static_cast<float>(src.alphaCutoff), 0.0f, 1.0f)
                                : 0.5f;
            mScene.materials.push_back(std::move(m));
        }
    }

    // ---- texture coordinates -------------------------------------------------------------------

    struct BaseColorUv {
        int set = 0;                        ///< TEXCOORD_<set>
        std::optional<glm::mat3> transform; ///< KHR_texture_transform, uv' = (T R S) (u, v, 1)
    };

    static double numberOr(const tinygltf::Value& object, const char* key, double fallback) {
        if (!object.Has(key) || !object.Get(key).IsNumber()) return fallback;
        const double v = object.Get(key).GetNumberAsDouble();
        return std::isfinite(v) ? v : fallback;
    }

    static glm::vec2 pairOr(const tinygltf::Value& object, const char* key, glm::vec2 fallback) {
        if (!object.Has(key)) return fallback;
        const tinygltf::Value& a = object.Get(key);
        if (!a.IsArray() || a.ArrayLen() != 2 || !a.Get(0).IsNumber() || !a.Get(1).IsNumber())
            return fallback;
        const glm::vec2 v(a.Get(0).GetNumberAsDouble(), a.Get(1).GetNumberAsDouble());
        return std::isfinite(v.x) && std::isfinite(v.y) ? v : fallback;
    }

    /// What decides a texture's coordinates: textureInfo and normalTextureInfo alike.
    struct UvSource {
        int index = -1;
        int texCoord = 0;
        const tinygltf::ExtensionMap* extensions = nullptr;
    };
    template <typename Info> static UvSource uvSource(const Info& info) {
        return {info.index, info.texCoord, &info.extensions};
    }

    BaseColorUv baseColorUv(int material) const {
        BaseColorUv uv;
        if (material < 0 || material >= static_cast<int>(mModel.materials.size())) return uv;
        // The base colour texture's coordinates, else those of the first other texture the renderer
        // samples (every one of them is mapped with one set: stats.not_shown says when they differ).
        const tinygltf::Material& m = mModel.materials[static_cast<std::size_t>(material)];
        UvSource info = uvSource(m.pbrMetallicRoughness.baseColorTexture);
        for (const UvSource& other :
             {uvSource(m.pbrMetallicRoughness.metallicRoughnessTexture), uvSource(m.emissiveTexture),
              uvSource(m.normalTexture), uvSource(m.occlusionTexture)})
            if (info.index < 0) info = other;
        if (info.index < 0) return uv;
        uv.set = std::max(0, info.texCoord);
        const auto ext = info.extensions->find(kTextureTransformExtension);
        if (ext == info.extensions->end() || !ext->second.IsObject()) return uv;
        const tinygltf::Value& t = ext->second;
        if (t.Has("texCoord") && t.Get("texCoord").IsInt())
            uv.set = std::max(0, t.Get("texCoord").GetNumberAsInt());
        const glm::vec2 offset = pairOr(t, "offset", glm::vec2(0.0f));
        const glm::vec2 scale = pairOr(t, "scale", glm::vec2(1.0f));
        const auto rotation = static_cast<float>(numberOr(t, "rotation", 0.0));
        // Column-major as the extension's own GLSL: translation * rotation * scale.
        const glm::mat3 translate(1, 0, 0, 0, 1, 0, offset.x, offset.y, 1);
        const glm::mat3 rotate(std::cos(rotation), std::sin(rotation), 0, -std::sin(rotation),
                               std::cos(rotation), 0, 0, 0, 1);
        const glm::mat3 scaling(scale.x, 0, 0, 0, scale.y, 0, 0, 0, 1);
        uv.transform = translate * rotate * scaling;
        return uv;
    }

    // ---- what the file asks for and the renderer does not show -----------------------------------

    /// "3 materials ('a', 'b', 'c')", at most three names.
    static std::string namedCount(const std::vector<std::string>& names, const char* kind) {
        std::string text = std::to_string(names.size()) + " " + kind + (names.size() == 1 ? "" : "s") + " (";
        for (std::size_t i = 0; i < names.size() && i < 3; ++i) text += (i ? ", '" : "'") + names[i] + "'";
        if (names.size() > 3) text += ", ...";
        return text + ")";
    }

    static std::string extensionEffect(const std::string& name) {
        static const std::map<std::string, std::string> effects = {
            {"KHR_materials_clearcoat", "clear coat is not rendered: the base layer shows alone"},
            {"KHR_materials_transmission", "transmission is not rendered: the surfaces are opaque"},
            {"KHR_materials_volume", "volumes (thickness, attenuation) are not rendered"},
            {"KHR_materials_sheen", "sheen is not rendered"},
            {"KHR_materials_ior", "the index of refraction is not used: dielectrics reflect 4 % head-on"},
            {"KHR_materials_iridescence", "iridescence is not rendered"},
            {"KHR_materials_anisotropy", "anisotropy is not rendered: highlights are round"},
            {"KHR_materials_dispersion", "dispersion is not rendered"},
            {"KHR_materials_unlit", "unlit materials are lit like the others"},
            {"KHR_materials_variants", "only each primitive's default material is shown"},
            {"KHR_materials_pbrSpecularGlossiness",
             "specular-glossiness materials show their metallic-roughness values (often the defaults)"},
            {"KHR_animation_pointer", "animations are not played"},
        };
        const auto found = effects.find(name);
        return found != effects.end() ? found->second
                                      : "the extension is not read: what it adds is not shown";
    }

    static bool textureInfoUses(const tinygltf::ExtensionMap& extensions, const std::string& name) {
        return extensions.find(name) != extensions.end();
    }

    void collectNotShown() {
        std::vector<NotShown>& out = mScene.notShown;
        const auto& readable = gltfReadableExtensions();
        // Optional extensions (a required one the loader cannot read was refused): who uses them.
        for (const std::string& ext : mModel.extensionsUsed) {
            if (std::find(readable.begin(), readable.end(), ext) != readable.end()) continue;
            // Fallback images stand in for compressed textures: those show.
            if (ext == "KHR_texture_basisu" || ext == "EXT_texture_webp" || ext == "EXT_texture_avif")
                continue;
            std::vector<std::string> materials, nodes;
            for (std::size_t i = 0; i < mModel.materials.size(); ++i) {
                const tinygltf::Material& m = mModel.materials[i];
                const bool uses =
                    m.extensions.count(ext) ||
                    textureInfoUses(m.pbrMetallicRoughness.baseColorTexture.extensions, ext) ||
                    textureInfoUses(m.pbrMetallicRoughness.metallicRoughnessTexture.extensions, ext) ||
                    textureInfoUses(m.normalTexture.extensions, ext) ||
                    textureInfoUses(m.occlusionTexture.extensions, ext) ||
                    textureInfoUses(m.emissiveTexture.extensions, ext);
                if (uses) materials.push_back(nameOr(m.name, "material", static_cast<int>(i)));
            }
            for (std::size_t i = 0; i < mModel.nodes.size(); ++i)
                if (mModel.nodes[i].extensions.count(ext))
                    nodes.push_back(nameOr(mModel.nodes[i].name, "node", static_cast<int>(i)));
            std::string where;
            if (!materials.empty())
                where = namedCount(materials, "material") + ": ";
            else if (!nodes.empty())
                where = namedCount(nodes, "node") + ": ";
            out.push_back({ext, where + extensionEffect(ext)});
        }
        // Core material features the renderer does not read yet.
        struct Feature {
            const char* name;
            const char* effect;
            std::function<bool(const tinygltf::Material&)> uses;
        };
        const Feature features[] = {
            {"texture coordinates",
             "the metallic-roughness, emissive, normal or occlusion texture asks for another UV set or "
             "transform than the base colour texture: all are mapped with the base colour's",
             [](const tinygltf::Material& m) {
                 const UvSource base = uvSource(m.pbrMetallicRoughness.baseColorTexture);
                 auto differs = [&](const UvSource& other) {
                     if (other.index < 0 || base.index < 0) return false;
                     const auto a = base.extensions->find(kTextureTransformExtension);
                     const auto b = other.extensions->find(kTextureTransformExtension);
                     const bool aHas = a != base.extensions->end(), bHas = b != other.extensions->end();
                     return other.texCoord != base.texCoord || aHas != bHas ||
                            (aHas && bHas && !(a->second == b->second));
                 };
                 return differs(uvSource(m.pbrMetallicRoughness.metallicRoughnessTexture)) ||
                        differs(uvSource(m.emissiveTexture)) || differs(uvSource(m.normalTexture)) ||
                        differs(uvSource(m.occlusionTexture));
             }},
            {"alphaMode BLEND",
             "transparency is approximated as a cutout: alpha below 0.5 is cut out, the rest renders opaque",
             [](const tinygltf::Material& m) { return m.alphaMode == "BLEND"; }},
        };
        for (const Feature& f : features) {
            std::vector<std::string> names;
            for (std::size_t i = 0; i < mModel.materials.size(); ++i)
                if (f.uses(mModel.materials[i]))
                    names.push_back(nameOr(mModel.materials[i].name, "material", static_cast<int>(i)));
            if (!names.empty()) out.push_back({f.name, namedCount(names, "material") + ": " + f.effect});
        }
        if (!mModel.animations.empty())
            out.push_back({"animations", std::to_string(mModel.animations.size()) +
                                             " animation(s) are not played: the nodes' rest pose is shown"});
        if (!mModel.skins.empty())
            out.push_back({"skins", std::to_string(mModel.skins.size()) +
                                        " skin(s) are not applied: skinned meshes show in their bind pose"});
        for (const NotShown& n : out) warn("not shown: " + n.feature + ": " + n.detail);
    }

    int defaultMaterial() {
        if (mDefaultMaterial < 0) {
            mScene.materials.push_back(Material{.name = "default"});
            mDefaultMaterial = static_cast<int>(mScene.materials.size()) - 1;
        }
        return mDefaultMaterial;
    }

    /// `srgb`: colour (base colour, emissive); false: linear data (metallic-roughness). One glTF image
    /// used both ways becomes two textures.
    int convertTexture(int textureIndex, const std::string& context, bool srgb = true) {
        if (textureIndex >= static_cast<int>(mModel.textures.size()))
            fail(context + ": texture " + std::to_string(textureIndex) + " does not exist");
        const int source = mModel.textures[static_cast<std::size_t>(textureIndex)].source;
        if (source < 0 || source >= static_cast<int>(mModel.images.size())) {
            warn(context + ": texture " + std::to_string(textureIndex) + " has no usable image; ignored");
            return -1;
        }
        int& cached = (srgb ? mImageTexture : mLinearImageTexture)[static_cast<std::size_t>(source)];
        if (cached == kNotConverted) {
            cached = convertImage(source, context);
            if (cached >= 0) mScene.textures[static_cast<std::size_t>(cached)].srgb = srgb;
        }
        return cached;
    }

    int convertImage(int index, const std::string& context) {
        const tinygltf::Image& img = mModel.images[static_cast<std::size_t>(index)];
        const std::string where = context + ": image " + std::to_string(index);
        if (img.image.empty() || img.width <= 0 || img.height <= 0) {
            warn(where + " was not decoded; texture ignored");
            return -1;
        }
        if (img.bits != 8 && img.bits != 16)
            fail(where + ": unsupported bit depth " + std::to_string(img.bits));
        if (img.component < 1 || img.component > 4)
            fail(where + ": unsupported channel count " + std::to_string(img.component));
        const auto pixels = static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height);
        const auto channels = static_cast<std::size_t>(img.component);
        const std::size_t bytesPerChannel = static_cast<std::size_t>(img.bits) / 8;
        if (img.image.size() < pixels * channels * bytesPerChannel) fail(where + ": pixel data is truncated");
        TextureImage tex{.width = img.width, .height = img.height, .name = nameOr(img.name, "image", index)};
        tex.rgba.resize(pixels * 4);
        for (std::size_t p = 0; p < pixels; ++p) {
            std::uint8_t c[4] = {0, 0, 0, 255};
            for (std::size_t k = 0; k < channels; ++k) {
                const unsigned char* src = img.image.data() + (p * channels + k) * bytesPerChannel;
                // 16-bit samples keep their high byte: the pipeline samples RGBA8 only.
                c[k] = bytesPerChannel == 1
                           ? *src
                           : static_cast<std::uint8_t>(loadUnaligned<std::uint16_t>(src) >> 8);
            }
            std::uint8_t* dst = tex.rgba.data() + p * 4;
            if (channels <= 2) { // grey or grey + alpha
                dst[0] = dst[1] = dst[2] = c[0];
                dst[3] = channels == 2 ? c[1] : 255;
            } else {
                std::copy(c, c + 4, dst);
            }
        }
        mScene.textures.push_back(std::move(tex));
        return static_cast<int>(mScene.textures.size()) - 1;
    }

    // ---- meshes ----------------------------------------------------------------------------------

    /// EXT_mesh_gpu_instancing: the node's mesh placed once per element of its TRANSLATION, ROTATION
    /// and SCALE accessors (each optional, all of one count), each placement the node's world
    /// matrix times T * R * S.
    void addGpuInstances(int nodeIndex, const glm::mat4& world, const tinygltf::Value& ext) {
        const std::string where = "node " + std::to_string(nodeIndex) + ": " + kGpuInstancingExtension;
        if (!ext.IsObject() || !ext.Has("attributes") || !ext.Get("attributes").IsObject())
            fail(where + " needs an 'attributes' object");
        const tinygltf::Value& attributes = ext.Get("attributes");
        const auto accessorOf = [&](const char* name) {
            if (!attributes.Has(name)) return -1;
            const tinygltf::Value& v = attributes.Get(name);
            if (!v.IsNumber()) fail(where + ": attributes." + name + " must be an accessor index");
            return v.GetNumberAsInt();
        };
        const int t = accessorOf("TRANSLATION"), r = accessorOf("ROTATION"), sc = accessorOf("SCALE");
        if (t < 0 && r < 0 && sc < 0) { // the extension needs one; the node alone is what is left
            warn(where + " has no TRANSLATION, ROTATION or SCALE; the mesh is drawn once, at the node");
            mPlacements.push_back({mModel.nodes[static_cast<std::size_t>(nodeIndex)].mesh, world});
            return;
        }
        const std::vector<glm::vec3> translations =
            t >= 0 ? readVectors<3>(t, TINYGLTF_TYPE_VEC3, where + " TRANSLATION") : std::vector<glm::vec3>{};
        const std::vector<glm::vec4> rotations =
            r >= 0 ? readVectors<4>(r, TINYGLTF_TYPE_VEC4, where + " ROTATION") : std::vector<glm::vec4>{};
        const std::vector<glm::vec3> scales =
            sc >= 0 ? readVectors<3>(sc, TINYGLTF_TYPE_VEC3, where + " SCALE") : std::vector<glm::vec3>{};
        const std::size_t count = std::max({translations.size(), rotations.size(), scales.size()});
        if ((t >= 0 && translations.size() != count) || (r >= 0 && rotations.size() != count) ||
            (sc >= 0 && scales.size() != count))
            fail(where + ": TRANSLATION, ROTATION and SCALE have different counts (" +
                 std::to_string(translations.size()) + ", " + std::to_string(rotations.size()) + ", " +
                 std::to_string(scales.size()) + "); the extension needs one count");
        for (std::size_t i = 0; i < count; ++i) {
            glm::mat4 m = world;
            if (t >= 0) m = glm::translate(m, translations[i]);
            if (r >= 0) {
                const glm::vec4 q = rotations[i];
                const float length = glm::length(q);
                // An unnormalised quaternion is normalised; a zero or non-finite one means no rotation.
                if (std::isfinite(length) && length > 1e-12f)
                    m *= glm::mat4_cast(glm::quat(q.w / length, q.x / length, q.y / length, q.z / length));
            }
            if (sc >= 0) m = glm::scale(m, scales[i]);
            mPlacements.push_back({mModel.nodes[static_cast<std::size_t>(nodeIndex)].mesh, m});
        }
    }

    /// What a mesh's attributes and indices hold in memory.
    static std::uint64_t meshBytes(const Mesh& mesh) {
        return mesh.positions.size() * sizeof(glm::vec3) + mesh.normals.size() * sizeof(glm::vec3) +
               mesh.texcoords.size() * sizeof(glm::vec2) + mesh.colors.size() * sizeof(glm::vec4) +
               mesh.tangents.size() * sizeof(glm::vec4) + mesh.indices.size() * sizeof(std::uint32_t);
    }

    /// Whether a placement can be drawn through an instance matrix (Mesh::instances): finite, with a
    /// positive determinant and a finite inverse. Mirrored or collapsed placements are flattened.
    static bool instanceable(const glm::mat4& world) {
        for (int c = 0; c < 4; ++c)
            if (!isFinite(world[c])) return false;
        const float det = glm::determinant(glm::mat3(world));
        if (!std::isfinite(det) || det <= 0.0f) return false;
        const glm::mat3 normalMatrix = glm::inverseTranspose(glm::mat3(world));
        for (int c = 0; c < 3; ++c)
            if (!isFinite(normalMatrix[c])) return false;
        return true;
    }

    /// The meshes of the nodes walked, in walk order. A glTF mesh that two or more nodes place, each
    /// instanceably, is read once in its own space and keeps one matrix per node; any other
    /// placement is flattened to world space.
    void addPlacedMeshes() {
        std::vector<int> uses(mModel.meshes.size(), 0);
        std::vector<bool> flatten(mModel.meshes.size(), false);
        for (const auto& [meshIndex, world] : mPlacements) {
            if (meshIndex >= static_cast<int>(mModel.meshes.size()))
                fail("mesh " + std::to_string(meshIndex) + " does not exist");
            const auto m = static_cast<std::size_t>(meshIndex);
            ++uses[m];
            if (!instanceable(world)) flatten[m] = true;
        }
        // Scene meshes [first, end) read from each instanced glTF mesh; first == -1 until read.
        std::vector<std::pair<int, int>> readAs(mModel.meshes.size(), {-1, -1});
        for (const auto& [meshIndex, world] : mPlacements) {
            const auto m = static_cast<std::size_t>(meshIndex);
            if (uses[m] < 2 || flatten[m]) {
                addMesh(meshIndex, world);
                continue;
            }
            if (readAs[m].first < 0) {
                const int first = static_cast<int>(mScene.meshes.size());
                addMesh(meshIndex, glm::mat4(1.0f));
                readAs[m] = {first, static_cast<int>(mScene.meshes.size())};
            } else {
                mContext.report(SceneLoadProgress::Stage::Meshes,
                                mPrimitivesRead += mModel.meshes[m].primitives.size(), mPrimitivesTotal);
            }
            for (int k = readAs[m].first; k < readAs[m].second; ++k) {
                Mesh& mesh = mScene.meshes[static_cast<std::size_t>(k)];
                // A placement beyond the first is charged as the flattened copy it would have been:
                // the reference's BVH and the effect plan flatten it (flattenInstances), and a small
                // file must not name a mesh a million times past the budget. The first was charged
                // when the mesh was read.
                const std::uint64_t bytes =
                    sizeof(glm::mat4) + (mesh.instances.empty() ? 0 : meshBytes(mesh));
                if (!mContext.spend(bytes, "placement " + std::to_string(mesh.instances.size() + 1) +
                                               " of mesh '" + mesh.name + "'"))
                    fail(mContext.refusal);
                mesh.instances.push_back(world);
            }
        }
    }

    void addMesh(int meshIndex, const glm::mat4& world) {
        const tinygltf::Mesh& mesh = mModel.meshes[static_cast<std::size_t>(meshIndex)];
        for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
            mContext.throwIfCancelled();
            addPrimitive(mesh, meshIndex, static_cast<int>(p), world);
            mContext.report(SceneLoadProgress::Stage::Meshes, ++mPrimitivesRead, mPrimitivesTotal);
        }
    }

    static std::vector<std::uint32_t> toTriangleList(const std::vector<std::uint32_t>& v, int mode) {
        if (mode == TINYGLTF_MODE_TRIANGLES) return v;
        std::vector<std::uint32_t> out;
        for (std::size_t i = 0; i + 2 < v.size(); ++i) {
            if (mode == TINYGLTF_MODE_TRIANGLE_FAN)
                out.insert(out.end(), {v[i + 1], v[i + 2], v[0]});
            else if (i % 2 == 0)
                out.insert(out.end(), {v[i], v[i + 1], v[i + 2]});
            else
                out.insert(out.end(), {v[i + 1], v[i], v[i + 2]}); // keep strips' alternating winding CCW
        }
        return out;
    }

    void addPrimitive(const tinygltf::Mesh& src, int meshIndex, int primIndex, const glm::mat4& world) {
        const tinygltf::Primitive& prim = src.primitives[static_cast<std::size_t>(primIndex)];
        Mesh mesh;
        mesh.name = nameOr(src.name, "mesh", meshIndex);
        if (src.primitives.size() > 1) mesh.name += "#" + std::to_string(primIndex);
        const std::string context = "mesh '" + mesh.name + "' (mesh " + std::to_string(meshIndex) +
                                    ", primitive " + std::to_string(primIndex) + ")";
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode == TINYGLTF_MODE_POINTS || mode == TINYGLTF_MODE_LINE || mode == TINYGLTF_MODE_LINE_LOOP ||
            mode == TINYGLTF_MODE_LINE_STRIP) {
            warn(context + ": points and lines are not rendered; primitive skipped");
            return;
        }
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            mode != TINYGLTF_MODE_TRIANGLE_FAN)
            fail(context + ": unknown primitive mode " + std::to_string(mode));
        const auto attribute = [&](const char* name) {
            const auto it = prim.attributes.find(name);
            return it == prim.attributes.end() ? -1 : it->second;
        };
        const int positionAccessor = attribute("POSITION");
        if (positionAccessor < 0) {
            warn(context + ": no POSITION attribute; primitive skipped");
            return;
        }
        mesh.positions = readVectors<3>(positionAccessor, TINYGLTF_TYPE_VEC3, context + " POSITION");
        if (const int a = attribute("NORMAL"); a >= 0)
            mesh.normals = readVectors<3>(a, TINYGLTF_TYPE_VEC3, context + " NORMAL");
        // The base colour texture is the one the renderer samples: its UV set and its
        // KHR_texture_transform are baked into the mesh's texture coordinates.
        const BaseColorUv uv = baseColorUv(prim.material);
        const std::string uvName = "TEXCOORD_" + std::to_string(uv.set);
        if (const int a = attribute(uvName.c_str()); a >= 0) {
            mesh.texcoords = readVectors<2>(a, TINYGLTF_TYPE_VEC2, context + " " + uvName);
        } else if (const int first = attribute("TEXCOORD_0"); first >= 0) {
            warn(context + ": the base colour texture reads " + uvName +
                 ", which the primitive lacks; TEXCOORD_0 is used");
            mesh.texcoords = readVectors<2>(first, TINYGLTF_TYPE_VEC2, context + " TEXCOORD_0");
        }
        if (uv.transform)
            for (glm::vec2& t : mesh.texcoords) t = glm::vec2(*uv.transform * glm::vec3(t, 1.0f));
        if (const int a = attribute("COLOR_0"); a >= 0) {
            const auto& accessor = mModel.accessors[static_cast<std::size_t>(a)];
            if (accessor.type == TINYGLTF_TYPE_VEC3) {
                for (const glm::vec3& c : readVectors<3>(a, TINYGLTF_TYPE_VEC3, context + " COLOR_0"))
                    mesh.colors.push_back(glm::vec4(c, 1.0f));
            } else {
                mesh.colors = readVectors<4>(a, TINYGLTF_TYPE_VEC4, context + " COLOR_0");
            }
            for (glm::vec4& c : mesh.colors)
                for (int k = 0; k < 4; ++k) c[k] = std::isfinite(c[k]) ? std::clamp(c[k], 0.0f, 1.0f) : 1.0f;
            if (mesh.colors.size() != mesh.positions.size())
                fail(context + ": COLOR_0 has " + std::to_string(mesh.colors.size()) +
                     " elements, POSITION " + std::to_string(mesh.positions.size()));
        }
        // The file's own tangents where its material maps normals: exporters compute them with
        // MikkTSpace, which the tangents generated at load only approximate.
        const bool normalMapped =
            prim.material >= 0 && prim.material < static_cast<int>(mScene.materials.size()) &&
            mScene.materials[static_cast<std::size_t>(prim.material)].normalTexture >= 0;
        if (const int a = attribute("TANGENT"); a >= 0 && normalMapped) {
            mesh.tangents = readVectors<4>(a, TINYGLTF_TYPE_VEC4, context + " TANGENT");
            if (mesh.tangents.size() != mesh.positions.size())
                fail(context + ": TANGENT has " + std::to_string(mesh.tangents.size()) +
                     " elements, POSITION " + std::to_string(mesh.positions.size()));
        }
        if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size())
            fail(context + ": NORMAL has " + std::to_string(mesh.normals.size()) + " elements, POSITION " +
                 std::to_string(mesh.positions.size()));
        if (!mesh.texcoords.empty() && mesh.texcoords.size() != mesh.positions.size())
            fail(context + ": TEXCOORD_0 has " + std::to_string(mesh.texcoords.size()) +
                 " elements, POSITION " + std::to_string(mesh.positions.size()));

        std::vector<std::uint32_t> indices;
        if (prim.indices >= 0) {
            indices = readIndices(prim.indices, context + " indices");
        } else {
            indices.resize(mesh.positions.size());
            std::iota(indices.begin(), indices.end(), 0u);
        }
        mesh.indices = toTriangleList(indices, mode);
        if (mesh.indices.empty()) {
            warn(context + ": no triangles; primitive skipped");
            return;
        }

        // Zero normals are left for finalizeScene, which replaces them with face normals.
        transformMesh(mesh, world);

        if (prim.material >= static_cast<int>(mModel.materials.size()))
            fail(context + ": material " + std::to_string(prim.material) + " does not exist");
        mesh.material = prim.material >= 0 ? prim.material : defaultMaterial();
        if (!mContext.spend(meshBytes(mesh), context)) fail(mContext.refusal);
        mScene.meshes.push_back(std::move(mesh));
    }

    // ---- cameras and lights ----------------------------------------------------------------------

    static glm::vec3 forwardOf(const glm::mat4& world) {
        return safeNormalize(glm::mat3(world) * glm::vec3(0.0f, 0.0f, -1.0f), glm::vec3(0.0f, 0.0f, -1.0f));
    }

    void addCamera(const tinygltf::Node& node, int nodeIndex, const glm::mat4& world) {
        if (node.camera >= static_cast<int>(mModel.cameras.size()))
            fail("node " + std::to_string(nodeIndex) + ": camera " + std::to_string(node.camera) +
                 " does not exist");
        const tinygltf::Camera& src = mModel.cameras[static_cast<std::size_t>(node.camera)];
        const std::string name = !src.name.empty() ? src.name : nameOr(node.name, "camera", node.camera);
        if (src.type != "perspective") {
            warn("camera '" + name + "': only perspective cameras are supported; skipped");
            return;
        }
        Camera cam;
        cam.name = name;
        cam.position = glm::vec3(world[3]);
        cam.target = cam.position + forwardOf(world);
        cam.up = safeNormalize(glm::mat3(world) * glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0.0f, 1.0f, 0.0f));
        cam.yfovRadians = static_cast<float>(src.perspective.yfov);
        cam.znear = static_cast<float>(src.perspective.znear);
        cam.zfar = static_cast<float>(src.perspective.zfar); // 0: infinite, closed once bounds are known
        mScene.cameras.push_back(cam);
    }

    void closeInfiniteFarPlanes() {
        const float reach = mScene.bounds.radius() * 2.0f;
        for (auto& cam : mScene.cameras)
            if (cam.zfar <= 0.0f)
                cam.zfar =
                    std::max(2.0f * cam.znear, glm::distance(cam.position, mScene.bounds.center()) + reach);
    }

    void addNodeLight(const tinygltf::Node& node, int nodeIndex, const glm::mat4& world) {
        const auto ext = node.extensions.find(kLightsExtension);
        if (ext == node.extensions.end()) return;
        const tinygltf::Value& ref = ext->second;
        if (!ref.IsObject() || !ref.Has("light") || !ref.Get("light").IsNumber())
            fail("node " + std::to_string(nodeIndex) + ": KHR_lights_punctual needs a numeric 'light'");
        const int index = ref.Get("light").GetNumberAsInt();
        if (index < 0 || index >= static_cast<int>(mModel.lights.size()))
            fail("node " + std::to_string(nodeIndex) + ": light " + std::to_string(index) +
                 " does not exist");
        const tinygltf::Light& src = mModel.lights[static_cast<std::size_t>(index)];
        Light light;
        light.name = !src.name.empty() ? src.name : nameOr(node.name, "light", index);
        if (src.type == "spot")
            light.type = LightType::Spot;
        else if (src.type == "point")
            light.type = LightType::Point;
        else if (src.type == "directional")
            light.type = LightType::Directional;
        else {
            warn("light '" + light.name + "': unknown type '" + src.type + "'; skipped");
            return;
        }
        if (src.color.size() == 3) light.color = glm::vec3(src.color[0], src.color[1], src.color[2]);
        light.intensity = static_cast<float>(src.intensity);
        light.range = static_cast<float>(src.range);
        light.innerConeAngle = static_cast<float>(src.spot.innerConeAngle);
        light.outerConeAngle = static_cast<float>(src.spot.outerConeAngle);
        light.position = glm::vec3(world[3]);
        // Spot and directional lights point along their node's -Z axis; a node transform that collapses
        // it (a zero scale) or is not finite leaves them no direction, which no fallback should invent.
        const glm::vec3 axis = glm::mat3(world) * glm::vec3(0.0f, 0.0f, -1.0f);
        const float axisLength = glm::length(axis);
        if (light.type != LightType::Point && !(axisLength > 1e-12f && std::isfinite(axisLength)))
            fail("light '" + light.name + "' (node " + std::to_string(nodeIndex) +
                 "): direction is zero or not finite: its node's transform collapses the -Z axis it points "
                 "along (a zero scale?); give the node a non-zero scale");
        light.direction = forwardOf(world);
        mScene.lights.push_back(light);
    }

    const tinygltf::Model& mModel;
    const std::string& mPath;
    LoadContext& mContext;
    Scene mScene;
    std::size_t mPrimitivesTotal = 0, mPrimitivesRead = 0;
    std::vector<int> mImageTexture;       ///< glTF image -> Scene::textures index, kNotConverted, or -1
    std::vector<int> mLinearImageTexture; ///< the same for images read as linear data
    std::vector<bool> mOnPath;            ///< nodes on the current root-to-node path, to reject cycles
    /// (glTF mesh, object -> world) of every node that has a mesh, in walk order (addPlacedMeshes).
    std::vector<std::pair<int, glm::mat4>> mPlacements;
    int mDefaultMaterial = -1;
};

/// A URI's %XX escapes decoded, as tinygltf decodes them before joining the path.
std::string percentDecoded(const std::string& uri) {
    std::string out;
    for (std::size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
            std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
            out += static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

/// tinygltf reports a short GLB only as "Invalid glTF binary."; say what is wrong instead. Returns the
/// JSON chunk for the depth check.
std::string_view glbJsonChunk(const std::string& bytes, const std::string& name) {
    auto u32 = [&](std::size_t at) {
        const auto* b = reinterpret_cast<const unsigned char*>(bytes.data()) + at;
        return std::uint64_t(b[0]) | std::uint64_t(b[1]) << 8 | std::uint64_t(b[2]) << 16 |
               std::uint64_t(b[3]) << 24;
    };
    if (bytes.size() < 20 || bytes.compare(0, 4, "glTF") != 0) return {}; // tinygltf reports it
    const std::uint64_t declared = u32(8);
    if (declared > bytes.size())
        throw InputError(name, "truncated GLB: header declares " + std::to_string(declared) +
                                   " bytes, file has " + std::to_string(bytes.size()));
    const std::uint64_t jsonLength = u32(12);
    if (jsonLength > bytes.size() - 20) return {}; // tinygltf reports it
    return std::string_view(bytes).substr(20, jsonLength);
}

tinygltf::Model parseFile(const std::string& path, LoadContext& context) {
    const std::string& name = context.name;
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw InputError(name, "file not found");
    if (!std::filesystem::is_regular_file(path, ec)) throw InputError(name, "not a regular file");
    const std::string ext = std::filesystem::path(path).extension().string();
    const bool binary = ext.size() == 4 && std::tolower(static_cast<unsigned char>(ext[1])) == 'g' &&
                        std::tolower(static_cast<unsigned char>(ext[2])) == 'l' &&
                        std::tolower(static_cast<unsigned char>(ext[3])) == 'b';
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) throw InputError(name, "cannot read the file");
    if (!context.spend(size, "the file")) throw InputError(name, context.refusal);
    std::string bytes(size, '\0');
    {
        // In chunks, so a big file's read reports how far it got.
        constexpr std::uintmax_t kChunk = 8u << 20;
        context.progress.fileBytes = size;
        std::ifstream in(path, std::ios::binary);
        for (std::uintmax_t at = 0; at < size;) {
            const std::uintmax_t n = std::min(kChunk, size - at);
            if (!in.read(bytes.data() + at, static_cast<std::streamsize>(n)))
                throw InputError(name, "cannot read the file");
            at += n;
            context.progress.bytesRead = at;
            context.report(SceneLoadProgress::Stage::Reading, static_cast<std::size_t>(at),
                           static_cast<std::size_t>(size));
            context.throwIfCancelled();
        }
    }
    // tinygltf walks extras and extensions recursively: a deep document must never reach it.
    const std::string_view json = binary ? glbJsonChunk(bytes, name) : std::string_view(bytes);
    if (auto at = findExcessNesting(json, kMaxGltfJsonDepth))
        throw InputError(name, "malformed JSON: arrays and objects nested deeper than " +
                                   std::to_string(kMaxGltfJsonDepth) + " levels (at byte " +
                                   std::to_string(*at) + " of the JSON)");
    // Draco and meshopt data decoded into plain accessors, which is all tinygltf reads.
    std::string_view checkedJson = json;
    auto spend = [&](std::uint64_t n, const std::string& what) {
        context.throwIfCancelled(); // called per decoded primitive and buffer
        if (!context.spend(n, what)) throw InputError(name, context.refusal);
        return true;
    };
    // External buffers with compressed data, through the same sandbox as tinygltf's reads.
    auto readExternal = [&](const std::string& uri) {
        std::vector<unsigned char> data;
        std::string err;
        if (!sandboxReadFile(&data, &err, context.baseDir + "/" + percentDecoded(uri), &context))
            throw InputError(name, !context.refusal.empty() ? context.refusal
                                   : !err.empty()           ? err
                                                            : "cannot read '" + validUtf8(uri) + "'");
        return std::string(data.begin(), data.end());
    };
    const bool compressed = json.find("KHR_draco_mesh_compression") != std::string_view::npos ||
                            json.find("_meshopt_compression") != std::string_view::npos;
    if (compressed)
        context.report(SceneLoadProgress::Stage::Decompressing, 0, 1);
    else
        context.shares.images = context.shares.decompress;
    const auto decompressed = decompressGltf(bytes, binary, json, name, spend, readExternal);
    if (decompressed) {
        for (const auto& what : decompressed->decoded) logInfo("scene: " + name + ": decoded " + what);
        bytes = decompressed->bytes;
        checkedJson = binary ? glbJsonChunk(bytes, name) : std::string_view(bytes);
    }
    // Version, required extensions and dangling references, said with their JSON path.
    const GltfOutline outline = preflightGltfJson(checkedJson, name);
    // The images stage's share only where there are images to decode.
    if (outline.images == 0) context.shares.meshes = context.shares.images;
    context.imagesTotal = outline.images;
    if (outline.images > 0) context.report(SceneLoadProgress::Stage::Images, 0, outline.images);

    tinygltf::TinyGLTF parser;
    parser.SetFsCallbacks(
        {&sandboxFileExists, &sandboxExpandPath, &sandboxReadFile, &sandboxWriteFile, &context});
    parser.SetImageLoader(&budgetedImageLoader, &context);
    tinygltf::Model model;
    std::string err, warnings;
    const bool ok =
        binary ? parser.LoadBinaryFromMemory(&model, &err, &warnings,
                                             reinterpret_cast<const unsigned char*>(bytes.data()),
                                             static_cast<unsigned int>(bytes.size()), context.baseDir)
               : parser.LoadASCIIFromString(&model, &err, &warnings, bytes.data(),
                                            static_cast<unsigned int>(bytes.size()), context.baseDir);
    // tinygltf's messages name files by the path it joined: show them relative to the file's folder.
    auto relative = [&](std::string text) {
        const std::string prefix = context.baseDir + "/";
        for (std::size_t at; (at = text.find(prefix)) != std::string::npos;) text.erase(at, prefix.size());
        return validUtf8(oneLine(text));
    };
    if (!warnings.empty() && !context.cancelSeen) logWarn("scene: " + name + ": " + relative(warnings));
    context.throwIfCancelled();
    if (!context.refusal.empty()) throw InputError(name, context.refusal);
    if (!ok) {
        // nlohmann's messages ("[json.exception.parse_error.101] ...") do not say what was parsed.
        const std::string reason = relative(err);
        if (reason.starts_with("[json.exception")) throw InputError(name, "malformed JSON: " + reason);
        throw InputError(name, reason.empty() ? "not a valid glTF file" : reason);
    }
    return model;
}

} // namespace

Scene loadGltf(const std::string& path, const SceneLoadOptions& options) {
    LoadContext context;
    context.name = options.displayName.empty() ? path : options.displayName;
    context.allowExternal = options.allowExternalFiles;
    context.budget = options.maxDecodedBytes;
    context.onProgress = options.onProgress;
    context.cancelled = options.cancelled;
    try {
        std::error_code ec;
        const std::filesystem::path absolute = std::filesystem::absolute(path, ec);
        if (ec) throw InputError(context.name, "file not found");
        context.baseDir = absolute.parent_path().string();
        context.root = std::filesystem::weakly_canonical(absolute.parent_path(), ec);
        const tinygltf::Model model = parseFile(absolute.string(), context);
        return GltfReader(model, context).read();
    } catch (const InputError&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw InputError(context.name, "out of memory while loading");
    } catch (const std::exception& e) {
        throw InputError(context.name, std::string("failed to load: ") + validUtf8(e.what()));
    } catch (...) {
        throw InputError(context.name, "failed to load: unknown error");
    }
}

} // namespace gis
