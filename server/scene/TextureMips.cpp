#include "scene/TextureMips.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/Error.h"

namespace gis {

namespace {

float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}
float linearToSrgb(float c) {
    return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

const std::array<float, 256>& decodeTable() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i)
            t[static_cast<std::size_t>(i)] = srgbToLinear(static_cast<float>(i) / 255.0f);
        return t;
    }();
    return table;
}

// Linear [0, 1] to an sRGB byte: a 4096-step table, each step's value encoded at its centre (the
// coarsest step, 1/4096 of linear light, is finer than a byte of sRGB near 0: 0.0003 of linear at 1).
const std::array<std::uint8_t, 4096>& encodeTable() {
    static const std::array<std::uint8_t, 4096> table = [] {
        std::array<std::uint8_t, 4096> t{};
        for (int i = 0; i < 4096; ++i) {
            const float linear = (static_cast<float>(i) + 0.5f) / 4096.0f;
            t[static_cast<std::size_t>(i)] =
                static_cast<std::uint8_t>(std::lround(std::clamp(linearToSrgb(linear), 0.0f, 1.0f) * 255.0f));
        }
        return t;
    }();
    return table;
}

MipLevel halve(const std::uint8_t* src, int width, int height, bool srgb) {
    MipLevel level;
    level.width = std::max(1, width / 2);
    level.height = std::max(1, height / 2);
    level.rgba.resize(static_cast<std::size_t>(level.width) * static_cast<std::size_t>(level.height) * 4);
    const auto& decode = decodeTable();
    const auto& encode = encodeTable();
    for (int y = 0; y < level.height; ++y) {
        // A side of 1 repeats its texel; otherwise 2y + 1 <= height - 1 (floor halving).
        const int y0 = std::min(2 * y, height - 1), y1 = std::min(2 * y + 1, height - 1);
        for (int x = 0; x < level.width; ++x) {
            const int x0 = std::min(2 * x, width - 1), x1 = std::min(2 * x + 1, width - 1);
            const std::uint8_t* texels[4] = {src + (static_cast<std::size_t>(y0) * width + x0) * 4,
                                             src + (static_cast<std::size_t>(y0) * width + x1) * 4,
                                             src + (static_cast<std::size_t>(y1) * width + x0) * 4,
                                             src + (static_cast<std::size_t>(y1) * width + x1) * 4};
            std::uint8_t* out = level.rgba.data() + (static_cast<std::size_t>(y) * level.width + x) * 4;
            for (int c = 0; c < 4; ++c) {
                if (srgb && c < 3) {
                    float sum = 0.0f;
                    for (const std::uint8_t* t : texels) sum += decode[t[c]];
                    const int step = std::clamp(static_cast<int>(sum * 0.25f * 4096.0f), 0, 4095);
                    out[c] = encode[static_cast<std::size_t>(step)];
                } else {
                    const int sum = texels[0][c] + texels[1][c] + texels[2][c] + texels[3][c];
                    out[c] = static_cast<std::uint8_t>((sum + 2) / 4); // rounded
                }
            }
        }
    }
    return level;
}

} // namespace

int mipLevelCount(int width, int height) {
    int levels = 1;
    for (int side = std::max(width, height); side > 1; side /= 2) ++levels;
    return levels;
}

std::vector<MipLevel> mipChain(const TextureImage& image) {
    GIS_ASSERT(image.width > 0 && image.height > 0 &&
               image.rgba.size() ==
                   static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4);
    std::vector<MipLevel> levels;
    const int count = mipLevelCount(image.width, image.height);
    levels.reserve(static_cast<std::size_t>(count - 1));
    const std::uint8_t* src = image.rgba.data();
    int width = image.width, height = image.height;
    for (int l = 1; l < count; ++l) {
        levels.push_back(halve(src, width, height, image.srgb));
        src = levels.back().rgba.data();
        width = levels.back().width;
        height = levels.back().height;
    }
    return levels;
}

} // namespace gis
