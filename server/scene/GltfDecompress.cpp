#include "scene/GltfDecompress.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <memory>

#include <draco/compression/decode.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include "core/Base64.h"
#include "core/Error.h"

namespace gis {
namespace {

using Json = nlohmann::json;

constexpr const char* kDraco = "KHR_draco_mesh_compression";
constexpr const char* kMeshoptExt = "EXT_meshopt_compression";
constexpr const char* kMeshoptKhr = "KHR_meshopt_compression";
constexpr std::uint32_t kBinChunk = 0x004E4942; // "BIN\0"
constexpr int kFloat = 5126;
constexpr int kUnsignedInt = 5125;
// A data URI a fallback buffer gets once nothing reads it (tinygltf wants every buffer loadable).
constexpr const char* kEmptyDataUri = "data:application/octet-stream;base64,AAAA";

std::uint32_t readU32(const std::string& bytes, std::size_t at) {
    const auto* b = reinterpret_cast<const unsigned char*>(bytes.data()) + at;
    return std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 | std::uint32_t(b[2]) << 16 |
           std::uint32_t(b[3]) << 24;
}

void appendU32(std::string& out, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out += static_cast<char>((v >> (8 * i)) & 255);
}

int componentsOf(const std::string& type) {
    if (type == "SCALAR") return 1;
    if (type == "VEC2") return 2;
    if (type == "VEC3") return 3;
    if (type == "VEC4" || type == "MAT2") return 4;
    if (type == "MAT3") return 9;
    if (type == "MAT4") return 16;
    return 0;
}

/// The largest value of a normalized integer component type (glTF 2.0 section 3.11), 0 for others.
double normalizedMax(int componentType) {
    switch (componentType) {
    case 5120:
        return 127.0;
    case 5121:
        return 255.0;
    case 5122:
        return 32767.0;
    case 5123:
        return 65535.0;
    default:
        return 0.0;
    }
}

bool isIntegerDracoType(draco::DataType type) {
    return type != draco::DT_FLOAT32 && type != draco::DT_FLOAT64 && type != draco::DT_INVALID;
}

std::string countText(std::size_t n, const char* what) {
    return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
}

class Decompressor {
public:
    Decompressor(const std::string& bytes, bool binary, std::string_view json, const std::string& fileName,
                 const std::function<bool(std::uint64_t, const std::string&)>& spend,
                 const std::function<std::string(const std::string&)>& readExternal)
        : mBytes(bytes), mBinary(binary), mFile(fileName), mSpend(spend), mReadExternal(readExternal) {
        mDoc = Json::parse(json.begin(), json.end(), nullptr, false);
        if (binary) findBinChunk(json.size());
    }

    std::optional<DecompressedGltf> run() {
        if (mDoc.is_discarded() || !mDoc.is_object() || !usesCompression()) return std::nullopt;
        Json& buffers = arrayAt(mDoc, "buffers");
        mIntoBin = mHasBin && !buffers.empty() && buffers[0].is_object() && !buffers[0].contains("uri");
        mOutBuffer = mIntoBin ? 0 : static_cast<int>(buffers.size());
        mOutBase = mIntoBin ? alignUp(mBin.size()) : 0;

        DecompressedGltf result;
        if (const std::size_t views = decodeMeshopt(); views > 0)
            result.decoded.push_back("meshopt: " + countText(views, "buffer view"));
        std::size_t points = 0;
        if (const std::size_t primitives = decodeDraco(points); primitives > 0)
            result.decoded.push_back("Draco: " + countText(primitives, "primitive") + ", " +
                                     countText(points, "point"));
        for (const char* list : {"extensionsUsed", "extensionsRequired"}) {
            const auto found = mDoc.find(list);
            if (found == mDoc.end() || !found->is_array()) continue;
            Json kept = Json::array();
            for (const Json& name : *found)
                if (!(name.is_string() && (name == kDraco || name == kMeshoptExt || name == kMeshoptKhr)))
                    kept.push_back(name);
            *found = std::move(kept);
        }
        result.bytes = assemble();
        return result;
    }

private:
    [[noreturn]] void fail(const std::string& message) const { throw InputError(mFile, message); }

    static std::size_t alignUp(std::size_t n) { return (n + 3) / 4 * 4; }

    void spend(std::uint64_t bytes, const std::string& what) const {
        if (!mSpend(bytes, what)) fail(what + " would exceed this server's memory budget for a scene");
    }

    void findBinChunk(std::size_t jsonLength) {
        const std::size_t at = 20 + jsonLength;
        if (mBytes.size() < at + 8) return;
        const std::uint32_t length = readU32(mBytes, at);
        if (readU32(mBytes, at + 4) != kBinChunk || length > mBytes.size() - at - 8) return;
        mBin = std::string_view(mBytes).substr(at + 8, length);
        mHasBin = true;
    }

    static Json& arrayAt(Json& object, const char* key) {
        Json& value = object[key];
        if (!value.is_array()) value = Json::array();
        return value;
    }

    static const Json* extensionOf(const Json& object, const char* name) {
        if (!object.is_object()) return nullptr;
        const auto extensions = object.find("extensions");
        if (extensions == object.end() || !extensions->is_object()) return nullptr;
        const auto found = extensions->find(name);
        return found == extensions->end() ? nullptr : &*found;
    }

    static void eraseExtension(Json& object, const char* name) {
        auto extensions = object.find("extensions");
        if (extensions == object.end() || !extensions->is_object()) return;
        extensions->erase(name);
        if (extensions->empty()) object.erase("extensions");
    }

    // Listed, or used without being listed (a Draco primitive must be decoded either way).
    bool usesCompression() const {
        for (const char* list : {"extensionsUsed", "extensionsRequired"})
            if (const auto found = mDoc.find(list); found != mDoc.end() && found->is_array())
                for (const Json& name : *found)
                    if (name == kDraco || name == kMeshoptExt || name == kMeshoptKhr) return true;
        if (const auto views = mDoc.find("bufferViews"); views != mDoc.end() && views->is_array())
            for (const Json& view : *views)
                if (extensionOf(view, kMeshoptExt) || extensionOf(view, kMeshoptKhr)) return true;
        if (const auto meshes = mDoc.find("meshes"); meshes != mDoc.end() && meshes->is_array())
            for (const Json& mesh : *meshes)
                if (const auto primitives = mesh.find("primitives");
                    mesh.is_object() && primitives != mesh.end() && primitives->is_array())
                    for (const Json& primitive : *primitives)
                        if (extensionOf(primitive, kDraco)) return true;
        return false;
    }

    static long long integerAt(const Json& object, const char* key, long long fallback,
                               bool* present = nullptr) {
        const auto found = object.find(key);
        if (present) *present = found != object.end();
        if (found == object.end()) return fallback;
        return found->is_number_integer() ? found->get<long long>() : -1;
    }

    /// The bytes of buffer `index`: the GLB's binary chunk or a data URI; external files are refused.
    std::string_view bufferBytes(long long index, const std::string& path) {
        const Json& buffers = mDoc["buffers"];
        if (index < 0 || index >= static_cast<long long>(buffers.size()))
            fail(path + ": buffer " + std::to_string(index) + " does not exist");
        const Json& buffer = buffers[static_cast<std::size_t>(index)];
        const auto uri = buffer.find("uri");
        if (uri == buffer.end()) {
            if (mBinary && index == 0 && mHasBin) return mBin;
            fail(path + ": buffer " + std::to_string(index) +
                 " has no data (no uri, and it is not a GLB's binary chunk)");
        }
        const std::string text = uri->is_string() ? uri->get<std::string>() : std::string();
        auto cached = mDataUris.find(index);
        if (cached != mDataUris.end()) return cached->second;
        const auto comma = text.find(";base64,");
        if (!text.starts_with("data:")) return mDataUris.emplace(index, mReadExternal(text)).first->second;
        if (comma == std::string::npos)
            fail(path + ": buffer " + std::to_string(index) + "'s data URI is not base64");
        auto decoded = base64Decode(std::string_view(text).substr(comma + 8));
        if (!decoded) fail(path + ": buffer " + std::to_string(index) + "'s data URI is not valid base64");
        return mDataUris.emplace(index, std::move(*decoded)).first->second;
    }

    std::string_view slice(std::string_view data, long long offset, long long length,
                           const std::string& path) const {
        if (offset < 0 || length < 0 || static_cast<std::uint64_t>(offset) > data.size() ||
            static_cast<std::uint64_t>(length) > data.size() - static_cast<std::uint64_t>(offset))
            fail(path + ": bytes " + std::to_string(offset) + " + " + std::to_string(length) +
                 " lie outside their buffer of " + std::to_string(data.size()) + " bytes");
        return data.substr(static_cast<std::size_t>(offset), static_cast<std::size_t>(length));
    }

    std::string_view viewBytes(long long viewIndex, const std::string& path) {
        const Json& views = mDoc["bufferViews"];
        if (viewIndex < 0 || viewIndex >= static_cast<long long>(views.size()))
            fail(path + ": buffer view " + std::to_string(viewIndex) + " does not exist");
        const Json& view = views[static_cast<std::size_t>(viewIndex)];
        const std::string where = "bufferViews[" + std::to_string(viewIndex) + "]";
        if (integerAt(view, "buffer", -1) == mOutBuffer && mOutBuffer >= 0 && view.value("decoded", false))
            return slice(mOut, integerAt(view, "byteOffset", 0) - static_cast<long long>(mOutBase),
                         integerAt(view, "byteLength", -1), where);
        return slice(bufferBytes(integerAt(view, "buffer", -1), where), integerAt(view, "byteOffset", 0),
                     integerAt(view, "byteLength", -1), where);
    }

    /// Appends decoded bytes; returns their offset in the output buffer.
    std::size_t append(const void* data, std::size_t size) {
        mOut.resize(alignUp(mOut.size()), '\0');
        const std::size_t offset = mOut.size();
        mOut.append(static_cast<const char*>(data), size);
        return mOutBase + offset;
    }

    int addView(std::size_t offset, std::size_t length) {
        Json& views = arrayAt(mDoc, "bufferViews");
        views.push_back({{"buffer", mOutBuffer}, {"byteOffset", offset}, {"byteLength", length}});
        return static_cast<int>(views.size()) - 1;
    }

    // ---- meshopt -------------------------------------------------------------------------------

    std::size_t decodeMeshopt() {
        std::size_t decoded = 0;
        Json& views = arrayAt(mDoc, "bufferViews");
        for (std::size_t i = 0; i < views.size(); ++i) {
            const char* name = extensionOf(views[i], kMeshoptExt) ? kMeshoptExt : kMeshoptKhr;
            const Json* ext = extensionOf(views[i], name);
            if (!ext || !ext->is_object()) continue;
            const std::string path = "bufferViews[" + std::to_string(i) + "].extensions." + name;
            const long long count = integerAt(*ext, "count", -1);
            const long long stride = integerAt(*ext, "byteStride", -1);
            const std::string mode = ext->value("mode", std::string());
            const std::string filter = ext->value("filter", std::string("NONE"));
            if (count < 0 || stride <= 0 || stride > 256)
                fail(path + ": count and byteStride (1 to 256) are required");
            const std::string_view source =
                slice(bufferBytes(integerAt(*ext, "buffer", -1), path), integerAt(*ext, "byteOffset", 0),
                      integerAt(*ext, "byteLength", -1), path);
            const auto size = static_cast<std::uint64_t>(count) * static_cast<std::uint64_t>(stride);
            spend(size, "meshopt-compressed " + path);
            std::string out(static_cast<std::size_t>(size), '\0');
            const auto* src = reinterpret_cast<const unsigned char*>(source.data());
            const auto n = static_cast<std::size_t>(count);
            const auto s = static_cast<std::size_t>(stride);
            int rc = -1;
            if (mode == "ATTRIBUTES") {
                if (s % 4 != 0) fail(path + ": ATTRIBUTES need a byteStride that is a multiple of 4");
                rc = meshopt_decodeVertexBuffer(out.data(), n, s, src, source.size());
            } else if (mode == "TRIANGLES" || mode == "INDICES") {
                if (s != 2 && s != 4) fail(path + ": " + mode + " need a byteStride of 2 or 4");
                if (mode == "TRIANGLES" && n % 3 != 0) fail(path + ": TRIANGLES need a count divisible by 3");
                rc = mode == "TRIANGLES" ? meshopt_decodeIndexBuffer(out.data(), n, s, src, source.size())
                                         : meshopt_decodeIndexSequence(out.data(), n, s, src, source.size());
            } else {
                fail(path + ": unknown mode '" + mode + "' (ATTRIBUTES, TRIANGLES or INDICES)");
            }
            if (rc != 0)
                fail(path + ": the meshopt data does not decode (error " + std::to_string(rc) +
                     "): the file is damaged");
            if (filter == "OCTAHEDRAL") {
                if (s != 4 && s != 8) fail(path + ": the OCTAHEDRAL filter needs a byteStride of 4 or 8");
                meshopt_decodeFilterOct(out.data(), n, s);
            } else if (filter == "QUATERNION") {
                if (s != 8) fail(path + ": the QUATERNION filter needs a byteStride of 8");
                meshopt_decodeFilterQuat(out.data(), n, s);
            } else if (filter == "EXPONENTIAL") {
                if (s % 4 != 0)
                    fail(path + ": the EXPONENTIAL filter needs a byteStride that is a multiple of 4");
                meshopt_decodeFilterExp(out.data(), n, s);
            } else if (filter != "NONE") {
                fail(path + ": unknown filter '" + filter + "'");
            }
            Json& view = views[i];
            view["buffer"] = mOutBuffer;
            view["byteOffset"] = append(out.data(), out.size());
            view["byteLength"] = out.size();
            view["decoded"] = true; // read back by viewBytes; removed before the document is written
            eraseExtension(view, name);
            ++decoded;
        }
        // Fallback buffers hold nothing once every compressed view is decoded.
        for (Json& buffer : arrayAt(mDoc, "buffers")) {
            const Json* ext = extensionOf(buffer, kMeshoptExt);
            if (!ext) ext = extensionOf(buffer, kMeshoptKhr);
            if (!ext || !ext->is_object() || !ext->value("fallback", false)) continue;
            eraseExtension(buffer, kMeshoptExt);
            eraseExtension(buffer, kMeshoptKhr);
            if (!buffer.contains("uri")) {
                buffer["uri"] = kEmptyDataUri;
                buffer["byteLength"] = 3;
            }
        }
        return decoded;
    }

    // ---- Draco ---------------------------------------------------------------------------------

    Json& accessorAt(long long index, const std::string& path) {
        Json& accessors = arrayAt(mDoc, "accessors");
        if (index < 0 || index >= static_cast<long long>(accessors.size()))
            fail(path + ": accessor " + std::to_string(index) + " does not exist");
        return accessors[static_cast<std::size_t>(index)];
    }

    std::size_t decodeDraco(std::size_t& points) {
        std::size_t decoded = 0;
        Json& meshes = arrayAt(mDoc, "meshes");
        for (std::size_t m = 0; m < meshes.size(); ++m) {
            if (!meshes[m].is_object() || !meshes[m].contains("primitives") ||
                !meshes[m]["primitives"].is_array())
                continue;
            Json& primitives = meshes[m]["primitives"];
            for (std::size_t p = 0; p < primitives.size(); ++p) {
                const Json* ext = extensionOf(primitives[p], kDraco);
                if (!ext || !ext->is_object()) continue;
                const std::string path = "meshes[" + std::to_string(m) + "].primitives[" + std::to_string(p) +
                                         "].extensions." + kDraco;
                points += decodeDracoPrimitive(primitives[p], *ext, path);
                eraseExtension(primitives[p], kDraco);
                ++decoded;
            }
        }
        return decoded;
    }

    std::size_t decodeDracoPrimitive(Json& primitive, const Json& ext, const std::string& path) {
        const std::string_view data = viewBytes(integerAt(ext, "bufferView", -1), path);
        const Json attributes = ext.value("attributes", Json::object());
        if (!attributes.is_object()) fail(path + ".attributes must be an object");
        draco::DecoderBuffer buffer;
        buffer.Init(data.data(), data.size());
        draco::Decoder decoder;
        auto status = decoder.DecodeMeshFromBuffer(&buffer);
        if (!status.ok())
            fail(path + ": the Draco data does not decode (" + status.status().error_msg_string() +
                 "): the file is damaged");
        const std::unique_ptr<draco::Mesh> mesh = std::move(status).value();
        if (!mesh) fail(path + ": the Draco data holds no mesh");
        const std::size_t pointCount = mesh->num_points();
        const std::size_t faceCount = mesh->num_faces();

        // Indices: uint32, three a face.
        spend(std::uint64_t(faceCount) * 12, path + "'s indices");
        std::vector<std::uint32_t> indices(faceCount * 3);
        for (std::size_t f = 0; f < faceCount; ++f) {
            const draco::Mesh::Face& face = mesh->face(draco::FaceIndex(static_cast<std::uint32_t>(f)));
            for (int k = 0; k < 3; ++k) indices[f * 3 + k] = face[k].value();
        }
        const int indexView = addView(append(indices.data(), indices.size() * 4), indices.size() * 4);
        Json indexAccessor = {{"bufferView", indexView},
                              {"componentType", kUnsignedInt},
                              {"count", indices.size()},
                              {"type", "SCALAR"}};
        if (primitive.contains("indices")) {
            Json& accessor = accessorAt(integerAt(primitive, "indices", -1), path);
            accessor = indexAccessor;
        } else {
            Json& accessors = arrayAt(mDoc, "accessors");
            accessors.push_back(indexAccessor);
            primitive["indices"] = accessors.size() - 1;
        }

        // Attributes: float, as many components as the accessor says.
        const Json& primitiveAttributes =
            primitive.contains("attributes") ? primitive["attributes"] : Json::object();
        for (const auto& [semantic, id] : attributes.items()) {
            const auto target = primitiveAttributes.find(semantic);
            if (target == primitiveAttributes.end() || !target->is_number_integer()) continue;
            const std::string where = path + ".attributes." + semantic;
            if (!id.is_number_unsigned()) fail(where + " must be a Draco attribute id");
            const draco::PointAttribute* attribute = mesh->GetAttributeByUniqueId(id.get<std::uint32_t>());
            if (!attribute) fail(where + ": the Draco data has no attribute " + id.dump());
            Json& accessor = accessorAt(target->get<long long>(), where);
            const int components = componentsOf(accessor.value("type", std::string()));
            if (components == 0) fail(where + ": its accessor has no valid type");
            spend(std::uint64_t(pointCount) * components * 4, where);
            std::vector<float> values(pointCount * static_cast<std::size_t>(components));
            for (std::size_t i = 0; i < pointCount; ++i) {
                const auto point = draco::PointIndex(static_cast<std::uint32_t>(i));
                if (!attribute->ConvertValue<float>(attribute->mapped_index(point),
                                                    static_cast<std::int8_t>(components),
                                                    &values[i * static_cast<std::size_t>(components)]))
                    fail(where + ": the Draco attribute cannot be read as " + std::to_string(components) +
                         " floats");
            }
            // Normalized integers that Draco did not mark as such: scale as the accessor says.
            const double max = normalizedMax(accessor.value("componentType", 0));
            if (accessor.value("normalized", false) && max > 0.0 &&
                isIntegerDracoType(attribute->data_type()) && !attribute->normalized())
                for (float& v : values) v = std::max(-1.0f, static_cast<float>(v / max));
            const std::size_t bytes = values.size() * sizeof(float);
            const int view = addView(append(values.data(), bytes), bytes);
            Json updated = {{"bufferView", view},
                            {"componentType", kFloat},
                            {"count", pointCount},
                            {"type", accessor.value("type", std::string())}};
            for (const char* keep : {"min", "max", "name"})
                if (accessor.contains(keep) &&
                    (std::strcmp(keep, "name") == 0 || accessor.value("componentType", 0) == kFloat))
                    updated[keep] = accessor[keep];
            accessor = std::move(updated);
        }
        return pointCount;
    }

    // ---- output --------------------------------------------------------------------------------

    std::string assemble() {
        for (Json& view : arrayAt(mDoc, "bufferViews"))
            if (view.is_object()) view.erase("decoded");
        Json& buffers = arrayAt(mDoc, "buffers");
        std::string bin;
        if (!mOut.empty()) {
            if (mIntoBin) {
                bin.assign(mBin);
                bin.resize(mOutBase, '\0');
                bin += mOut;
                buffers[0]["byteLength"] = bin.size();
            } else {
                buffers.push_back({{"byteLength", mOut.size()},
                                   {"uri", "data:application/octet-stream;base64," + base64Encode(mOut)}});
            }
        } else if (mHasBin) {
            bin.assign(mBin);
        }
        std::string json = mDoc.dump();
        if (!mBinary) return json;
        while (json.size() % 4 != 0) json += ' ';
        const bool withBin = mHasBin;
        bin.resize(alignUp(bin.size()), '\0');
        std::string out = "glTF";
        appendU32(out, 2);
        appendU32(out, static_cast<std::uint32_t>(12 + 8 + json.size() + (withBin ? 8 + bin.size() : 0)));
        appendU32(out, static_cast<std::uint32_t>(json.size()));
        appendU32(out, 0x4E4F534A); // "JSON"
        out += json;
        if (withBin) {
            appendU32(out, static_cast<std::uint32_t>(bin.size()));
            appendU32(out, kBinChunk);
            out += bin;
        }
        return out;
    }

    const std::string& mBytes;
    bool mBinary;
    const std::string& mFile;
    const std::function<bool(std::uint64_t, const std::string&)>& mSpend;
    const std::function<std::string(const std::string&)>& mReadExternal;
    Json mDoc;
    std::string_view mBin;
    bool mHasBin = false;
    std::map<long long, std::string> mDataUris; ///< data-URI and external buffers, read once
    std::string mOut;                           ///< decoded bytes, appended to buffer mOutBuffer
    int mOutBuffer = -1;
    bool mIntoBin = false;    ///< mOut extends the GLB's binary chunk (buffer 0)
    std::size_t mOutBase = 0; ///< where mOut starts in that buffer
};

} // namespace

const std::vector<std::string>& gltfDecodedExtensions() {
    static const std::vector<std::string> names = {kDraco, kMeshoptExt, kMeshoptKhr};
    return names;
}

std::optional<DecompressedGltf>
decompressGltf(const std::string& bytes, bool binary, std::string_view json, const std::string& fileName,
               const std::function<bool(std::uint64_t, const std::string&)>& spend,
               const std::function<std::string(const std::string& uri)>& readExternal) {
    return Decompressor(bytes, binary, json, fileName, spend, readExternal).run();
}

} // namespace gis
