#include "scene/SceneLoader.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string_view>

#include "core/Error.h"

namespace gis {
namespace {

constexpr std::string_view kBuiltinPrefix = "builtin:";

bool endsWithIgnoreCase(const std::string& s, std::string_view suffix) {
    if (s.size() < suffix.size()) return false;
    return std::equal(suffix.begin(), suffix.end(), s.end() - static_cast<std::ptrdiff_t>(suffix.size()),
                      [](char a, char b) {
                          return std::tolower(static_cast<unsigned char>(a)) ==
                                 std::tolower(static_cast<unsigned char>(b));
                      });
}

std::string joinedBuiltinNames() {
    std::string out;
    for (const auto& n : builtinSceneNames()) out += (out.empty() ? "" : ", ") + n;
    return out;
}

} // namespace

std::string SceneLoadProgress::describe() const {
    auto mib = [](std::uint64_t b) {
        char text[32];
        std::snprintf(text, sizeof text, "%.1f MiB", static_cast<double>(b) / (1024.0 * 1024.0));
        return std::string(text);
    };
    auto of = [&](const char* what) {
        return std::string(what) + ": " + std::to_string(done) + " of " + std::to_string(total);
    };
    switch (stage) {
    case Stage::Reading:
        return "reading the file: " + mib(bytesRead) + " of " + mib(fileBytes);
    case Stage::Decompressing:
        return "decoding compressed meshes";
    case Stage::Images:
        return of("decoding images");
    case Stage::Meshes:
        return of("reading meshes");
    case Stage::Finishing:
        return "normals, tangents and checks";
    }
    return {};
}

Scene loadScene(const std::string& name, const SceneLoadOptions& options) {
    if (name.starts_with(kBuiltinPrefix)) return makeBuiltinScene(name.substr(kBuiltinPrefix.size()));
    if (endsWithIgnoreCase(name, ".gltf") || endsWithIgnoreCase(name, ".glb")) return loadGltf(name, options);
    throw InputError(options.displayName.empty() ? name : options.displayName,
                     "unsupported scene: expected 'builtin:NAME' (NAME one of " + joinedBuiltinNames() +
                         ") or a path to a .gltf or .glb file");
}

} // namespace gis
