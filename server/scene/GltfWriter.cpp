#include "scene/GltfWriter.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <limits>

#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>
#include <stb_image_write.h>

#include "core/Error.h"

namespace gis {
namespace {

constexpr int kFloat = 5126, kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

/// The binary chunk and the JSON's bufferViews and accessors, built side by side.
class Binary {
public:
    explicit Binary(nlohmann::json& doc) : mDoc(doc) {}

    int view(const void* data, std::size_t bytes, int target = 0) {
        while (mBytes.size() % 4 != 0) mBytes.push_back(0);
        nlohmann::json v = {{"buffer", 0}, {"byteOffset", mBytes.size()}, {"byteLength", bytes}};
        if (target != 0) v["target"] = target;
        const auto* p = static_cast<const std::uint8_t*>(data);
        mBytes.insert(mBytes.end(), p, p + bytes);
        mDoc["bufferViews"].push_back(v);
        return static_cast<int>(mDoc["bufferViews"].size()) - 1;
    }

    template <typename Vec> int floats(const std::vector<Vec>& values, const char* type) {
        const int v = view(values.data(), values.size() * sizeof(Vec), kArrayBuffer);
        return accessor(
            {{"bufferView", v}, {"componentType", kFloat}, {"count", values.size()}, {"type", type}});
    }

    /// POSITION, with the min and max glTF requires of it.
    int positions(const std::vector<glm::vec3>& values) {
        const int a = floats(values, "VEC3");
        glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
        for (const glm::vec3& p : values) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        mDoc["accessors"][static_cast<std::size_t>(a)]["min"] = {lo.x, lo.y, lo.z};
        mDoc["accessors"][static_cast<std::size_t>(a)]["max"] = {hi.x, hi.y, hi.z};
        return a;
    }

    int indices(const std::vector<std::uint32_t>& values) {
        const int v = view(values.data(), values.size() * sizeof(std::uint32_t), kElementArrayBuffer);
        return accessor({{"bufferView", v},
                         {"componentType", kUnsignedInt},
                         {"count", values.size()},
                         {"type", "SCALAR"}});
    }

    const std::vector<std::uint8_t>& bytes() const { return mBytes; }

private:
    int accessor(nlohmann::json a) {
        mDoc["accessors"].push_back(std::move(a));
        return static_cast<int>(mDoc["accessors"].size()) - 1;
    }
    nlohmann::json& mDoc;
    std::vector<std::uint8_t> mBytes;
};

void appendPng(void* context, void* data, int size) {
    auto* out = static_cast<std::vector<std::uint8_t>*>(context);
    const auto* p = static_cast<const std::uint8_t*>(data);
    out->insert(out->end(), p, p + size);
}

/// A node's rotation that turns its -Z axis to `forward` (glTF lights and cameras look along -Z).
nlohmann::json rotationTowards(const glm::vec3& forward, const glm::vec3& upHint) {
    const glm::vec3 f = glm::normalize(forward);
    const glm::vec3 up = std::abs(glm::dot(f, glm::normalize(upHint))) > 0.999f ? glm::vec3(1, 0, 0) : upHint;
    const glm::quat q = glm::quatLookAtRH(f, up);
    return {q.x, q.y, q.z, q.w};
}

void writeLittleEndian(std::ofstream& out, std::uint32_t v) {
    const char b[4] = {static_cast<char>(v & 0xff), static_cast<char>((v >> 8) & 0xff),
                       static_cast<char>((v >> 16) & 0xff), static_cast<char>((v >> 24) & 0xff)};
    out.write(b, 4);
}

} // namespace

void writeGlb(const Scene& scene, const std::string& path) {
    nlohmann::json doc = {{"asset", {{"version", "2.0"}, {"generator", "gi-render --export"}}},
                          {"scene", 0},
                          {"scenes", {{{"nodes", nlohmann::json::array()}}}},
                          {"nodes", nlohmann::json::array()},
                          {"meshes", nlohmann::json::array()},
                          {"accessors", nlohmann::json::array()},
                          {"bufferViews", nlohmann::json::array()}};
    Binary bin(doc);
    auto addNode = [&](nlohmann::json node) {
        doc["nodes"].push_back(std::move(node));
        doc["scenes"][0]["nodes"].push_back(doc["nodes"].size() - 1);
    };

    // Images as PNG, one texture and one repeating, trilinear sampler for each.
    for (const TextureImage& t : scene.textures) {
        std::vector<std::uint8_t> png;
        if (t.width <= 0 || t.height <= 0 ||
            t.rgba.size() != static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height) * 4 ||
            stbi_write_png_to_func(appendPng, &png, t.width, t.height, 4, t.rgba.data(), t.width * 4) == 0)
            throw Error("export: texture '" + t.name + "' could not be encoded as PNG");
        const int v = bin.view(png.data(), png.size());
        doc["images"].push_back({{"bufferView", v}, {"mimeType", "image/png"}, {"name", t.name}});
        doc["textures"].push_back({{"source", doc["images"].size() - 1}, {"sampler", 0}});
    }
    if (!scene.textures.empty())
        doc["samplers"] = {{{"magFilter", 9729}, {"minFilter", 9987}, {"wrapS", 10497}, {"wrapT", 10497}}};

    std::vector<std::string> extensionsUsed;
    auto use = [&](const std::string& e) {
        if (std::find(extensionsUsed.begin(), extensionsUsed.end(), e) == extensionsUsed.end())
            extensionsUsed.push_back(e);
    };
    for (const Material& m : scene.materials) {
        nlohmann::json pbr = {
            {"baseColorFactor", {m.baseColor.r, m.baseColor.g, m.baseColor.b, m.baseColor.a}},
            {"metallicFactor", m.metallic},
            {"roughnessFactor", m.roughness}};
        if (m.baseColorTexture >= 0) pbr["baseColorTexture"] = {{"index", m.baseColorTexture}};
        if (m.metallicRoughnessTexture >= 0)
            pbr["metallicRoughnessTexture"] = {{"index", m.metallicRoughnessTexture}};
        nlohmann::json mat = {
            {"name", m.name}, {"pbrMetallicRoughness", pbr}, {"doubleSided", m.doubleSided}};
        // glTF's emissiveFactor is at most 1: a brighter emitter carries the rest as its strength.
        const float strength = std::max({m.emissive.r, m.emissive.g, m.emissive.b, 1.0f});
        const glm::vec3 factor = m.emissive / strength;
        if (m.emissive != glm::vec3(0.0f)) mat["emissiveFactor"] = {factor.r, factor.g, factor.b};
        if (strength > 1.0f) {
            mat["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", strength}};
            use("KHR_materials_emissive_strength");
        }
        if (m.emissiveTexture >= 0) mat["emissiveTexture"] = {{"index", m.emissiveTexture}};
        if (m.normalTexture >= 0)
            mat["normalTexture"] = {{"index", m.normalTexture}, {"scale", m.normalScale}};
        if (m.occlusionTexture >= 0)
            mat["occlusionTexture"] = {{"index", m.occlusionTexture}, {"strength", m.occlusionStrength}};
        if (m.alphaMode == Material::Alpha::Mask) {
            mat["alphaMode"] = "MASK";
            mat["alphaCutoff"] = m.alphaCutoff;
        } else if (m.alphaMode == Material::Alpha::Blend) {
            mat["alphaMode"] = "BLEND";
        }
        if (m.specular > 0.0f) {
            mat["extensions"]["KHR_materials_specular"] = {{"specularFactor", m.specular}};
            use("KHR_materials_specular");
        }
        doc["materials"].push_back(std::move(mat));
    }

    for (const Mesh& mesh : scene.meshes) {
        if (mesh.indices.empty() || mesh.positions.empty()) continue;
        nlohmann::json attributes = {{"POSITION", bin.positions(mesh.positions)}};
        if (mesh.normals.size() == mesh.positions.size())
            attributes["NORMAL"] = bin.floats(mesh.normals, "VEC3");
        if (mesh.texcoords.size() == mesh.positions.size())
            attributes["TEXCOORD_0"] = bin.floats(mesh.texcoords, "VEC2");
        if (mesh.colors.size() == mesh.positions.size())
            attributes["COLOR_0"] = bin.floats(mesh.colors, "VEC4");
        nlohmann::json primitive = {
            {"attributes", attributes}, {"indices", bin.indices(mesh.indices)}, {"mode", 4}};
        if (mesh.material >= 0 && mesh.material < static_cast<int>(scene.materials.size()))
            primitive["material"] = mesh.material;
        doc["meshes"].push_back({{"name", mesh.name}, {"primitives", {primitive}}});
        if (!mesh.instanced()) {
            addNode({{"name", mesh.name}, {"mesh", doc["meshes"].size() - 1}});
            continue;
        }
        // One node per placement, all naming the same mesh: the file keeps the instancing.
        for (std::size_t k = 0; k < mesh.instances.size(); ++k) {
            nlohmann::json matrix = nlohmann::json::array();
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) matrix.push_back(mesh.instances[k][c][r]);
            addNode({{"name", mesh.name + "@" + std::to_string(k)},
                     {"mesh", doc["meshes"].size() - 1},
                     {"matrix", matrix}});
        }
    }

    for (const Light& l : scene.lights) {
        nlohmann::json light = {
            {"name", l.name}, {"color", {l.color.r, l.color.g, l.color.b}}, {"intensity", l.intensity}};
        if (l.type == LightType::Directional) {
            light["type"] = "directional";
        } else {
            light["type"] = l.type == LightType::Spot ? "spot" : "point";
            if (l.range > 0.0f) light["range"] = l.range;
            if (l.type == LightType::Spot)
                light["spot"] = {{"innerConeAngle", l.innerConeAngle}, {"outerConeAngle", l.outerConeAngle}};
        }
        doc["extensions"]["KHR_lights_punctual"]["lights"].push_back(light);
        use("KHR_lights_punctual");
        addNode({{"name", l.name},
                 {"translation", {l.position.x, l.position.y, l.position.z}},
                 {"rotation", rotationTowards(l.direction, glm::vec3(0, 1, 0))},
                 {"extensions",
                  {{"KHR_lights_punctual",
                    {{"light", doc["extensions"]["KHR_lights_punctual"]["lights"].size() - 1}}}}}});
    }
    for (const Camera& c : scene.cameras) {
        doc["cameras"].push_back(
            {{"name", c.name},
             {"type", "perspective"},
             {"perspective", {{"yfov", c.yfovRadians}, {"znear", c.znear}, {"zfar", c.zfar}}}});
        addNode({{"name", c.name},
                 {"camera", doc["cameras"].size() - 1},
                 {"translation", {c.position.x, c.position.y, c.position.z}},
                 {"rotation", rotationTowards(c.target - c.position, c.up)}});
    }
    if (!extensionsUsed.empty()) doc["extensionsUsed"] = extensionsUsed;
    doc["buffers"] = {{{"byteLength", bin.bytes().size()}}};

    std::string json = doc.dump();
    while (json.size() % 4 != 0) json.push_back(' ');
    std::vector<std::uint8_t> data = bin.bytes();
    while (data.size() % 4 != 0) data.push_back(0);
    const std::size_t total = 12 + 8 + json.size() + 8 + data.size();
    if (total > std::numeric_limits<std::uint32_t>::max())
        throw Error("export: the scene needs " + std::to_string(total) +
                    " bytes, more than a .glb holds (4 GiB)");

    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) throw Error("export: cannot write '" + path + "'");
    writeLittleEndian(out, 0x46546C67u); // "glTF"
    writeLittleEndian(out, 2);
    writeLittleEndian(out, static_cast<std::uint32_t>(total));
    writeLittleEndian(out, static_cast<std::uint32_t>(json.size()));
    writeLittleEndian(out, 0x4E4F534Au); // "JSON"
    out.write(json.data(), static_cast<std::streamsize>(json.size()));
    writeLittleEndian(out, static_cast<std::uint32_t>(data.size()));
    writeLittleEndian(out, 0x004E4942u); // "BIN\0"
    out.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size()));
    if (!out) throw Error("export: writing '" + path + "' failed (disk full?)");
}

} // namespace gis
