// Base64 (RFC 4648, standard alphabet with padding): API replies carry images in it and glTF data URIs
// carry buffers in it.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace gis {

std::string base64Encode(std::string_view bytes);
/// Decodes `text`; whitespace is not allowed. nullopt when it is not base64.
std::optional<std::string> base64Decode(std::string_view text);

} // namespace gis
