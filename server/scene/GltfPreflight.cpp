#include "scene/GltfPreflight.h"

#include <algorithm>

#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "scene/GltfDecompress.h"

namespace gis {
namespace {

using Json = nlohmann::json;

// What to do about an extension the loader cannot read, for the ones users meet most.
std::string adviceFor(const std::string& extension) {
    if (extension == "KHR_texture_basisu")
        return "its textures are KTX2/Basis Universal, which this service does not decode: export it with "
               "PNG or JPEG textures";
    if (extension == "EXT_texture_webp" || extension == "EXT_texture_avif")
        return "its textures need " + extension +
               ", which this service does not decode: export it with PNG or JPEG textures";
    std::string readable, decoded;
    for (const auto& name : gltfReadableExtensions()) readable += (readable.empty() ? "" : ", ") + name;
    for (const auto& name : gltfDecodedExtensions()) decoded += (decoded.empty() ? "" : ", ") + name;
    return "this service does not read it (it reads " + readable + " and decodes " + decoded +
           "): export the file without it, or as a plain glTF 2.0 file";
}

class Preflight {
public:
    Preflight(const Json& doc, const std::string& fileName) : mDoc(doc), mFile(fileName) {}

    void run() {
        checkVersion();
        checkRequiredExtensions();
        checkReferences();
    }

private:
    [[noreturn]] void fail(const std::string& message) const { throw InputError(mFile, message); }

    void checkVersion() const {
        const auto asset = mDoc.find("asset");
        if (asset == mDoc.end() || !asset->is_object() || !asset->contains("version"))
            fail("asset.version is missing: a glTF 2.0 file says \"asset\": {\"version\": \"2.0\"}; "
                 "export the file again as glTF 2.0");
        const Json& version = asset->at("version");
        if (!version.is_string()) fail("asset.version must be a string such as \"2.0\"");
        const std::string text = version.get<std::string>();
        if (majorOf(text) != "2")
            fail("asset.version is \"" + text +
                 "\": this service reads glTF 2.x only; export the file as glTF 2.0" +
                 (majorOf(text) == "1" ? " (glTF 1.0 files can be converted with a glTF 1-to-2 converter)"
                                       : ""));
        const auto minVersion = asset->find("minVersion");
        if (minVersion != asset->end()) {
            const std::string min =
                minVersion->is_string() ? minVersion->get<std::string>() : std::string("?");
            if (min != "2.0")
                fail("asset.minVersion is \"" + min +
                     "\": the file needs a newer glTF than 2.0, which this service reads; export it as glTF "
                     "2.0");
        }
    }

    static std::string majorOf(const std::string& version) {
        const auto dot = version.find('.');
        const std::string major = version.substr(0, dot);
        const bool digits = !major.empty() && std::all_of(major.begin(), major.end(),
                                                          [](char c) { return c >= '0' && c <= '9'; });
        return dot == std::string::npos || !digits ? std::string("?") : major;
    }

    void checkRequiredExtensions() const {
        const auto required = mDoc.find("extensionsRequired");
        if (required == mDoc.end()) return;
        if (!required->is_array()) fail("extensionsRequired must be an array of extension names");
        const auto& readable = gltfReadableExtensions();
        for (std::size_t i = 0; i < required->size(); ++i) {
            const Json& name = (*required)[i];
            if (!name.is_string()) fail("extensionsRequired[" + std::to_string(i) + "] must be a string");
            const std::string ext = name.get<std::string>();
            if (std::find(readable.begin(), readable.end(), ext) == readable.end())
                fail("unsupported required extension '" + ext + "': " + adviceFor(ext));
        }
    }

    // ---- references ------------------------------------------------------------------------------

    const Json* member(const Json& object, const char* key) const {
        if (!object.is_object()) return nullptr;
        const auto it = object.find(key);
        return it == object.end() ? nullptr : &*it;
    }

    /// The top-level array `key`, nullptr when absent; fails when it is not an array.
    const Json* array(const char* key) const {
        const Json* found = member(mDoc, key);
        if (found && !found->is_array()) fail(std::string(key) + " must be an array");
        return found;
    }

    std::size_t count(const Json* targets) const { return targets ? targets->size() : 0; }

    /// `value` at `path` must index `targets` (a top-level array named `kind` for messages).
    void ref(const Json& value, const std::string& path, const Json* targets, const std::string& kind) const {
        if (!value.is_number_integer()) fail(path + " must be an index into " + kind + "s");
        const auto index = value.get<long long>();
        const std::size_t n = count(targets);
        if (index < 0 || index >= static_cast<long long>(n))
            fail(path + ": " + kind + " " + std::to_string(index) + " does not exist (the file has " +
                 (n == 0 ? std::string("none") : std::to_string(n)) +
                 "): the file is damaged or was edited by hand; export it again from the tool that made it");
    }

    /// `object[key]`, when present, must index `targets`.
    void refIn(const Json& object, const char* key, const std::string& path, const Json* targets,
               const std::string& kind) const {
        if (const Json* value = member(object, key))
            ref(*value, path.empty() ? std::string(key) : path + "." + key, targets, kind);
    }

    /// Every element of `object[key]`, when present, must index `targets`.
    void refsIn(const Json& object, const char* key, const std::string& path, const Json* targets,
                const std::string& kind) const {
        const Json* values = member(object, key);
        if (!values) return;
        if (!values->is_array()) fail(path + "." + key + " must be an array of indices");
        for (std::size_t i = 0; i < values->size(); ++i)
            ref((*values)[i], path + "." + key + "[" + std::to_string(i) + "]", targets, kind);
    }

    /// A textureInfo (`{"index": ...}`) at object[key], when present.
    void textureIn(const Json& object, const char* key, const std::string& path, const Json* textures) const {
        if (const Json* info = member(object, key)) {
            if (!info->is_object()) fail(path + "." + key + " must be an object with an index");
            if (!info->contains("index")) fail(path + "." + key + ".index is missing");
            ref(info->at("index"), path + "." + key + ".index", textures, "texture");
        }
    }

    static std::string at(const char* array, std::size_t i) {
        return std::string(array) + "[" + std::to_string(i) + "]";
    }

    void checkReferences() const {
        const Json* scenes = array("scenes");
        const Json* nodes = array("nodes");
        const Json* meshes = array("meshes");
        const Json* cameras = array("cameras");
        const Json* skins = array("skins");
        const Json* materials = array("materials");
        const Json* textures = array("textures");
        const Json* images = array("images");
        const Json* samplers = array("samplers");
        const Json* accessors = array("accessors");
        const Json* bufferViews = array("bufferViews");
        const Json* buffers = array("buffers");
        const Json* lights = nullptr;
        if (const Json* ext = member(mDoc, "extensions"))
            if (const Json* punctual = member(*ext, "KHR_lights_punctual"))
                lights = member(*punctual, "lights");
        if (lights && !lights->is_array()) fail("extensions.KHR_lights_punctual.lights must be an array");

        refIn(mDoc, "scene", "", scenes, "scene");
        for (std::size_t i = 0; i < count(scenes); ++i)
            refsIn((*scenes)[i], "nodes", at("scenes", i), nodes, "node");
        for (std::size_t i = 0; i < count(nodes); ++i) {
            const Json& node = (*nodes)[i];
            const std::string path = at("nodes", i);
            refsIn(node, "children", path, nodes, "node");
            refIn(node, "mesh", path, meshes, "mesh");
            refIn(node, "camera", path, cameras, "camera");
            refIn(node, "skin", path, skins, "skin");
            if (const Json* ext = member(node, "extensions"))
                if (const Json* light = member(*ext, "KHR_lights_punctual"))
                    refIn(*light, "light", path + ".extensions.KHR_lights_punctual", lights, "light");
        }
        for (std::size_t i = 0; i < count(meshes); ++i) {
            const Json* primitives = member((*meshes)[i], "primitives");
            if (!primitives) continue;
            if (!primitives->is_array()) fail(at("meshes", i) + ".primitives must be an array");
            for (std::size_t p = 0; p < primitives->size(); ++p) {
                const Json& primitive = (*primitives)[p];
                const std::string path = at("meshes", i) + "." + at("primitives", p);
                if (const Json* attributes = member(primitive, "attributes")) {
                    if (!attributes->is_object()) fail(path + ".attributes must be an object");
                    for (const auto& [semantic, index] : attributes->items())
                        ref(index, path + ".attributes." + semantic, accessors, "accessor");
                }
                refIn(primitive, "indices", path, accessors, "accessor");
                refIn(primitive, "material", path, materials, "material");
                if (const Json* targets = member(primitive, "targets"); targets && targets->is_array())
                    for (std::size_t t = 0; t < targets->size(); ++t)
                        if ((*targets)[t].is_object())
                            for (const auto& [semantic, index] : (*targets)[t].items())
                                ref(index, path + "." + at("targets", t) + "." + semantic, accessors,
                                    "accessor");
            }
        }
        for (std::size_t i = 0; i < count(materials); ++i) {
            const Json& material = (*materials)[i];
            const std::string path = at("materials", i);
            if (const Json* pbr = member(material, "pbrMetallicRoughness")) {
                textureIn(*pbr, "baseColorTexture", path + ".pbrMetallicRoughness", textures);
                textureIn(*pbr, "metallicRoughnessTexture", path + ".pbrMetallicRoughness", textures);
            }
            textureIn(material, "normalTexture", path, textures);
            textureIn(material, "occlusionTexture", path, textures);
            textureIn(material, "emissiveTexture", path, textures);
            if (const Json* ext = member(material, "extensions"))
                if (const Json* specular = member(*ext, "KHR_materials_specular")) {
                    const std::string where = path + ".extensions.KHR_materials_specular";
                    textureIn(*specular, "specularTexture", where, textures);
                    textureIn(*specular, "specularColorTexture", where, textures);
                }
        }
        for (std::size_t i = 0; i < count(textures); ++i) {
            refIn((*textures)[i], "source", at("textures", i), images, "image");
            refIn((*textures)[i], "sampler", at("textures", i), samplers, "sampler");
        }
        for (std::size_t i = 0; i < count(images); ++i)
            refIn((*images)[i], "bufferView", at("images", i), bufferViews, "buffer view");
        for (std::size_t i = 0; i < count(accessors); ++i) {
            const Json& accessor = (*accessors)[i];
            refIn(accessor, "bufferView", at("accessors", i), bufferViews, "buffer view");
            if (const Json* sparse = member(accessor, "sparse")) {
                if (const Json* indices = member(*sparse, "indices"))
                    refIn(*indices, "bufferView", at("accessors", i) + ".sparse.indices", bufferViews,
                          "buffer view");
                if (const Json* values = member(*sparse, "values"))
                    refIn(*values, "bufferView", at("accessors", i) + ".sparse.values", bufferViews,
                          "buffer view");
            }
        }
        for (std::size_t i = 0; i < count(bufferViews); ++i)
            refIn((*bufferViews)[i], "buffer", at("bufferViews", i), buffers, "buffer");
        for (std::size_t i = 0; i < count(skins); ++i) {
            refsIn((*skins)[i], "joints", at("skins", i), nodes, "node");
            refIn((*skins)[i], "skeleton", at("skins", i), nodes, "node");
            refIn((*skins)[i], "inverseBindMatrices", at("skins", i), accessors, "accessor");
        }
    }

    const Json& mDoc;
    const std::string& mFile;
};

} // namespace

const std::vector<std::string>& gltfReadableExtensions() {
    // KHR_mesh_quantization: quantized attributes are non-float component types, which the accessor
    // reader handles.
    // KHR_texture_transform: applied to the base colour texture, the one the renderer samples.
    // EXT_mesh_gpu_instancing: each instance is a placement of the node's mesh (Mesh::instances).
    static const std::vector<std::string> names = {
        "KHR_lights_punctual",   "KHR_materials_emissive_strength", "KHR_materials_specular",
        "KHR_mesh_quantization", "KHR_texture_transform",           "EXT_mesh_gpu_instancing"};
    return names;
}

GltfOutline preflightGltfJson(std::string_view json, const std::string& fileName) {
    // The caller has bounded the nesting depth; a parse error is the parser's to report (it says where).
    Json doc = Json::parse(json.begin(), json.end(), nullptr, false);
    if (doc.is_discarded() || !doc.is_object()) return {};
    Preflight(doc, fileName).run();
    GltfOutline outline;
    if (const auto images = doc.find("images"); images != doc.end() && images->is_array())
        outline.images = images->size();
    return outline;
}

} // namespace gis
