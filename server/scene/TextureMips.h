// The mipmap chain of a texture, built on the CPU so that a scene's load thread, not the render
// thread, pays for it (glGenerateTextureMipmap runs on the render thread: docs/scenes.md, "Loading").
#pragma once

#include <cstdint>
#include <vector>

#include "scene/Scene.h"

namespace gis {

struct MipLevel {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgba; ///< width * height * 4 bytes
};

/// Levels 1..n of `image` (level 0 is the image itself), as GL sizes them: each max(1, floor(size /
/// 2)) of the level above, down to 1 x 1. Each texel is the mean of the 2 x 2 texels above it (the
/// last row or column of an odd size is left out, one texel of a size-1 side repeats): in linear
/// light for sRGB images (decoded, averaged, encoded), alpha and linear data as stored. Pure.
std::vector<MipLevel> mipChain(const TextureImage& image);

/// Mip levels including level 0 for a width x height image: 1 + floor(log2(max(width, height))).
int mipLevelCount(int width, int height);

} // namespace gis
