// Text files compiled into the binaries (shaders, protocol schemas) by gis_embed_files().
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace gis {

struct EmbeddedFile {
    std::string_view path;    ///< relative to the embedded directory, '/'-separated
    std::string_view content;
};

namespace embedded {
std::span<const EmbeddedFile> shaders();   ///< shaders/**
std::span<const EmbeddedFile> protocol();  ///< protocol/schema/**.json, protocol/messages.json
std::span<const EmbeddedFile> codecs();    ///< protocol/codecs.json
} // namespace embedded

inline std::optional<std::string_view> findEmbedded(std::span<const EmbeddedFile> files, std::string_view path) {
    for (const auto& f : files)
        if (f.path == path) return f.content;
    return std::nullopt;
}

} // namespace gis
