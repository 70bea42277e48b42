// The eye-space multiresolution hierarchy every multiresolution technique shares (digest S.3 P3, P5,
// P7): min-max (and derivative / curvature) mipmaps of the G-buffer in one flattened atlas
// (layout in shaders/shared/EyeHierarchy.h), per-texel refinement flags, the receiver set as a
// stencil over the atlas (001 §3.2.1), the illumination atlas the techniques splat or gather into,
// and the coarse-to-fine reconstruction to full resolution (000 §3.5).
//
// Per frame: build() -> [technique fills illumination() at receivers, alpha 1] -> reconstruct().
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/Param.h"
#include "gi/Technique.h"
#include "gi/common/ParamSpecs.h"
#include "gl/Objects.h"
#include "gl/PassTimer.h"
#include "gl/Shader.h"
#include "gl/ShaderShared.h"

namespace gis {

/// coarsest_size, depth_metric, depth_threshold, depth_derivative_threshold, normal_metric,
/// normal_threshold, curvature_threshold, diagonal_refine, detail_alpha.

struct EyeLevel {
    int x = 0, y = 0;          ///< atlas offset (texels)
    int width = 0, height = 0; ///< level size (texels)
};

/// Level sizes ceil(W / 2^l) x ceil(H / 2^l) for l = 0..C, C the first level whose longer side is
/// <= coarsestSize (C = 0 when the image is already that small); level 0 at the atlas origin, the
/// others stacked in a column to its right. Pure, so tests can check it without GL.
std::vector<EyeLevel> eyeLevelLayout(int width, int height, int coarsestSize, int* atlasWidth,
                                     int* atlasHeight);

class EyeHierarchy {
public:
    EyeHierarchy();
    /// (Re)allocates the atlas when the size or coarsest level changes; may throw gis::Error.
    void ensureLayout(int width, int height, int coarsestSize);

    /// Builds the mipmaps and flags ("eye_mipmap"), marks the receivers in the stencil
    /// ("stencil_setup") and clears the illumination atlas.
    void build(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer);
    /// Reads back the receiver count per level (synchronises) and writes the counters
    /// receivers_total, receivers_l<k> and receiver_fraction (receivers / covered pixels).
    void countReceivers(Counters& counters, int coveredPixels = -1);
    /// Reconstructs level 0 ("upsample") and writes the full-resolution indirect radiance.
    /// `irradiance`: one receiver list per frame holding irradiance (bilinear upsampling, albedo / pi
    /// applied per pixel); false: per-VPL lists holding radiance (parent replicated, see eyeCombine).
    void reconstruct(const FrameInputs& in, const ParamSet& params, bool irradiance,
                     const gl::Framebuffer& indirectTarget, gl::PassTimer& timer);

    const std::vector<EyeLevel>& levels() const { return mLevels; }
    int atlasWidth() const { return mAtlasWidth; }
    int atlasHeight() const { return mAtlasHeight; }
    const gl::Texture& illumination() const { return mIllumination; }
    const gl::Texture& geoPosition() const { return mGeoPosition; }
    const gl::Texture& geoNormal() const { return mGeoNormal; }
    const gl::Texture& geoAlbedo() const { return mGeoAlbedo; }
    const gl::Texture& flags() const { return mFlags; }
    /// State every pass that lights receivers shares: the illumination atlas as target, the atlas
    /// geometry at units 0 and 1, the G-buffer (level 0) via bindPixels, an empty VAO, additive rgb
    /// with alpha marking data, and (`stencil`) the receiver stencil test. Undone by
    /// endIlluminationPass().
    void beginIlluminationPass(const FrameInputs& in, bool stencil) const;
    void endIlluminationPass() const;
    /// Binds the hierarchy's uniform block at GIS_UBO_EYE (every pass using eye_hierarchy.glsl).
    void bindUniforms() const;
    /// Binds the G-buffer (level 0) at units 8, 9, 10 as eye_pixel.glsl expects.
    void bindPixels(const FrameInputs& in) const;
    const std::array<unsigned, GIS_MAX_EYE_LEVELS>& lastReceiverCounts() const { return mLastCounts; }

    /// Test hook: the receiver stencil read back as (level, x, y) triples, sorted.
    std::vector<std::array<int, 3>> readReceiverSet() const;

private:
    void uploadUniforms(const ParamSet& params);

    gl::Program mReduceFromPixels, mReduce, mFlagsProgram, mReceivers, mUpsample, mResolve;
    gl::VertexArray mEmptyVao;
    gl::Buffer mUbo, mCounts;
    std::vector<EyeLevel> mLevels;
    int mWidth = 0, mHeight = 0, mCoarsest = 0, mAtlasWidth = 0, mAtlasHeight = 0;
    gl::Texture mGeoPosition, mGeoNormal, mGeoAlbedo, mDepthInfo, mNormalMin, mNormalMax, mFlags, mDiscFlags;
    gl::Texture mIllumination, mStencil, mReconstructed;
    gl::Framebuffer mGeoFbo, mFlagsFbo, mIllumFbo, mReconFbo;
    std::array<unsigned, GIS_MAX_EYE_LEVELS> mLastCounts{};
};

} // namespace gis
