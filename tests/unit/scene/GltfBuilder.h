// Builds small glTF assets in code for the loader tests, so no binary fixtures live in the repo, and
// writes them as .gltf (buffer as a base64 data URI) or .glb (JSON chunk + BIN chunk).
#pragma once

#include <atomic>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace gis::test {

constexpr int kByte = 5120;
constexpr int kUnsignedByte = 5121;
constexpr int kShort = 5122;
constexpr int kUnsignedShort = 5123;
constexpr int kUnsignedInt = 5125;
constexpr int kFloat = 5126;

inline std::string base64(const std::vector<std::uint8_t>& data) {
    static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < data.size(); i += 3) {
        const std::uint32_t b0 = data[i];
        const std::uint32_t b1 = i + 1 < data.size() ? data[i + 1] : 0;
        const std::uint32_t b2 = i + 2 < data.size() ? data[i + 2] : 0;
        const std::uint32_t v = (b0 << 16) | (b1 << 8) | b2;
        out += kAlphabet[(v >> 18) & 63];
        out += kAlphabet[(v >> 12) & 63];
        out += i + 1 < data.size() ? kAlphabet[(v >> 6) & 63] : '=';
        out += i + 2 < data.size() ? kAlphabet[v & 63] : '=';
    }
    return out;
}

inline void writeBytes(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes) {
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

inline void writeText(const std::filesystem::path& path, const std::string& text) {
    std::ofstream f(path, std::ios::binary);
    f << text;
}

/// A fresh directory under the system temp dir, removed with everything in it on destruction.
class TempDir {
public:
    TempDir() {
        static std::atomic<int> counter{0};
        mPath = std::filesystem::temp_directory_path() /
                ("gis_scene_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        std::filesystem::create_directories(mPath);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(mPath, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    std::string file(const std::string& name) const { return (mPath / name).string(); }

private:
    std::filesystem::path mPath;
};

class GltfBuilder {
public:
    nlohmann::json doc = {{"asset", {{"version", "2.0"}}}};
    std::vector<std::uint8_t> bin;

    /// Appends raw bytes (4-byte aligned) as a new bufferView; returns its index.
    int addView(const void* data, std::size_t size, int stride = 0) {
        while (bin.size() % 4 != 0) bin.push_back(0);
        const std::size_t offset = bin.size();
        const auto* bytes = static_cast<const std::uint8_t*>(data);
        bin.insert(bin.end(), bytes, bytes + size);
        nlohmann::json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", size}};
        if (stride != 0) view["byteStride"] = stride;
        return push("bufferViews", view);
    }
    template <typename T> int addView(const std::vector<T>& values, int stride = 0) {
        return addView(values.data(), values.size() * sizeof(T), stride);
    }

    int addAccessor(int view, int componentType, std::size_t count, const std::string& type,
                    const nlohmann::json& extra = nlohmann::json::object()) {
        nlohmann::json acc = {
            {"bufferView", view}, {"componentType", componentType}, {"count", count}, {"type", type}};
        acc.update(extra);
        return push("accessors", acc);
    }

    int addVec3s(const std::vector<glm::vec3>& v) {
        return addAccessor(addView(v), kFloat, v.size(), "VEC3");
    }
    template <typename T> int addIndices(const std::vector<T>& v, int componentType) {
        return addAccessor(addView(v), componentType, v.size(), "SCALAR");
    }

    /// A mesh with one primitive; returns the mesh index.
    int addMesh(const std::string& name, const nlohmann::json& primitive) {
        return push("meshes", {{"name", name}, {"primitives", nlohmann::json::array({primitive})}});
    }
    int addNode(const nlohmann::json& node) { return push("nodes", node); }
    void setScene(const std::vector<int>& roots) {
        doc["scenes"] = nlohmann::json::array({{{"nodes", roots}}});
        doc["scene"] = 0;
    }

    /// One node holding a one-triangle mesh in the y = 0 plane, facing +y; returns the node index.
    int addTriangleNode(const std::string& name = "tri") {
        const int pos = addVec3s({{0, 0, 0}, {1, 0, 0}, {0, 0, -1}});
        const int idx = addIndices(std::vector<std::uint16_t>{0, 1, 2}, kUnsignedShort);
        const int mesh = addMesh(name, {{"attributes", {{"POSITION", pos}}}, {"indices", idx}});
        return addNode({{"mesh", mesh}});
    }

    std::string writeGltf(const TempDir& dir, const std::string& name) {
        nlohmann::json d = doc;
        d["buffers"] = nlohmann::json::array(
            {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
        const std::string path = dir.file(name);
        writeText(path, d.dump());
        return path;
    }

    std::vector<std::uint8_t> glbBytes() const {
        nlohmann::json d = doc;
        d["buffers"] = nlohmann::json::array({{{"byteLength", bin.size()}}});
        std::string json = d.dump();
        while (json.size() % 4 != 0) json += ' ';
        std::vector<std::uint8_t> body = bin;
        while (body.size() % 4 != 0) body.push_back(0);
        std::vector<std::uint8_t> out;
        const auto u32 = [&out](std::uint32_t v) {
            for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
        };
        u32(0x46546C67); // "glTF"
        u32(2);
        u32(static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + body.size()));
        u32(static_cast<std::uint32_t>(json.size()));
        u32(0x4E4F534A); // "JSON"
        out.insert(out.end(), json.begin(), json.end());
        u32(static_cast<std::uint32_t>(body.size()));
        u32(0x004E4942); // "BIN\0"
        out.insert(out.end(), body.begin(), body.end());
        return out;
    }

    std::string writeGlb(const TempDir& dir, const std::string& name) const {
        const std::string path = dir.file(name);
        writeBytes(path, glbBytes());
        return path;
    }

private:
    int push(const char* key, const nlohmann::json& value) {
        auto& arr = doc[key];
        if (arr.is_null()) arr = nlohmann::json::array();
        arr.push_back(value);
        return static_cast<int>(arr.size()) - 1;
    }
};

} // namespace gis::test
