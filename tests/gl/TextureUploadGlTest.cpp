// A scene's textures reach GL with mipmaps built on the CPU (scene/TextureMips.h) and in pieces
// (SceneGpu's staged upload): the levels must be what GL's own mipmap generation makes, and a
// staged upload must draw what a whole one draws.
#include <algorithm>
#include <cstdlib>
#include <vector>

#include <gtest/gtest.h>

#include "GlTestSupport.h"
#include "gl/Objects.h"
#include "render/SceneGpu.h"
#include "scene/TextureMips.h"

namespace gis::test {
namespace {

TextureImage pattern(int width, int height, bool srgb) {
    TextureImage image;
    image.width = width;
    image.height = height;
    image.srgb = srgb;
    image.rgba.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4);
    unsigned state = 12345u;
    for (std::uint8_t& v : image.rgba) {
        state = state * 1103515245u + 12345u;
        v = static_cast<std::uint8_t>(state >> 24);
    }
    return image;
}

std::vector<std::uint8_t> readLevel(const gl::Texture& t, int level, int width, int height) {
    std::vector<std::uint8_t> out(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4);
    glGetTextureImage(t.id(), level, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(out.size()), out.data());
    return out;
}

TEST(TextureUpload, CpuMipmapsMatchGlsOwnGeneration) {
    sharedContext();
    for (const bool srgb : {true, false}) {
        const TextureImage image = pattern(64, 32, srgb);
        const std::vector<MipLevel> cpu = mipChain(image);
        gl::Texture t = gl::Texture::create2D(srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, image.width, image.height,
                                              static_cast<int>(cpu.size()) + 1);
        glTextureSubImage2D(t.id(), 0, 0, 0, image.width, image.height, GL_RGBA, GL_UNSIGNED_BYTE,
                            image.rgba.data());
        glGenerateTextureMipmap(t.id());
        for (std::size_t l = 0; l < cpu.size(); ++l) {
            const std::vector<std::uint8_t> gpu =
                readLevel(t, static_cast<int>(l + 1), cpu[l].width, cpu[l].height);
            int worst = 0;
            for (std::size_t i = 0; i < gpu.size(); ++i)
                worst =
                    std::max(worst, std::abs(static_cast<int>(gpu[i]) - static_cast<int>(cpu[l].rgba[i])));
            // GL's generation rounds through its own float path, and each level is made from the
            // rounded level above on both sides: the first levels agree within 2 codes of a byte,
            // the 2 x 1 and 1 x 1 ends of the chain within 3.
            EXPECT_LE(worst, l + 1 < cpu.size() - 1 ? 2 : 3)
                << (srgb ? "sRGB" : "linear") << " level " << l + 1;
        }
    }
}

TEST(TextureUpload, AStagedUploadInSmallSlicesDrawsWhatAWholeUploadDraws) {
    // The atrium: textures (with alpha cutouts) and enough geometry for many pieces.
    sharedContext();
    auto scene = std::make_shared<const Scene>(loadScene("builtin:atrium"));
    FrameState state = makeFrameState(*scene, "none");
    state.width = 64;
    state.height = 64;
    FrameRenderer& renderer = sharedRenderer();
    renderer.setScene(scene); // whole, at once
    const FrameOutput whole = renderer.render(state, false);

    auto staged = std::make_unique<SceneGpu>(*scene, SceneGpu::prepare(*scene), SceneGpu::Staged{});
    EXPECT_FALSE(staged->complete());
    int slices = 1;
    while (!staged->uploadSome(0.0)) ++slices; // a zero budget: one piece a slice
    EXPECT_GT(slices, 8) << "the atrium's upload is several pieces";
    EXPECT_TRUE(staged->complete());
    EXPECT_EQ(staged->triangleCount(), scene->triangleCount());
    renderer.setScene(scene, std::move(staged));
    const FrameOutput inPieces = renderer.render(state, false);
    EXPECT_EQ(whole.rgba8, inPieces.rgba8);
}

} // namespace
} // namespace gis::test
