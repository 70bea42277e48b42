#include "core/Base64.h"

#include <array>
#include <cstdint>

namespace gis {
namespace {

constexpr std::string_view kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

constexpr std::array<std::int8_t, 256> decodeTable() {
    std::array<std::int8_t, 256> table{};
    for (auto& v : table) v = -1;
    for (std::size_t i = 0; i < kAlphabet.size(); ++i)
        table[static_cast<unsigned char>(kAlphabet[i])] = static_cast<std::int8_t>(i);
    return table;
}

} // namespace

std::string base64Encode(std::string_view bytes) {
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    auto byte = [&](std::size_t i) {
        return static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i]));
    };
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        const std::uint32_t n = byte(i) << 16 | (i + 1 < bytes.size() ? byte(i + 1) << 8 : 0) |
                                (i + 2 < bytes.size() ? byte(i + 2) : 0);
        out += kAlphabet[(n >> 18) & 63];
        out += kAlphabet[(n >> 12) & 63];
        out += i + 1 < bytes.size() ? kAlphabet[(n >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? kAlphabet[n & 63] : '=';
    }
    return out;
}

std::optional<std::string> base64Decode(std::string_view text) {
    static constexpr auto table = decodeTable();
    if (text.size() % 4 != 0) return std::nullopt;
    std::string out;
    out.reserve(text.size() / 4 * 3);
    for (std::size_t i = 0; i < text.size(); i += 4) {
        std::uint32_t n = 0;
        int padding = 0;
        for (std::size_t k = 0; k < 4; ++k) {
            const char c = text[i + k];
            if (c == '=' && i + 4 == text.size() && k >= 2) {
                ++padding;
                n <<= 6;
                continue;
            }
            const std::int8_t v = table[static_cast<unsigned char>(c)];
            if (v < 0 || padding > 0) return std::nullopt; // no data after padding
            n = n << 6 | static_cast<std::uint32_t>(v);
        }
        out += static_cast<char>((n >> 16) & 255);
        if (padding < 2) out += static_cast<char>((n >> 8) & 255);
        if (padding < 1) out += static_cast<char>(n & 255);
    }
    return out;
}

} // namespace gis
