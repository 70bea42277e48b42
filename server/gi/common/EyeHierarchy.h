// The eye-space multiresolution hierarchy every multiresolution technique shares (digest S.3 P3, P5,
// P7): min-max (and derivative / curvature) mipmaps of the G-buffer in one flattened atlas
// (layout in shaders/shared/EyeHierarchy.h), per-texel refinement flags, the receiver set as a
// stencil over the atlas (001 §3.2.1), the illumination atlas the techniques splat or gather into,
// and the coarse-to-fine reconstruction to full resolution (000 §3.5).
//
// Per frame: build() -> [technique fills illumination() at receivers, alpha 1] -> reconstruct().
// The gathers fill it with compute passes over the receiver list (receiverList: beginReceiverPass,
// dispatchReceivers), one invocation per receiver; multires_splat splats into it with fragments.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/Param.h"
#include "gi/Technique.h"
#include "gi/common/ParamSpecs.h"
#include "gl/Objects.h"
#include "gl/Pass.h"
#include "gl/PassTimer.h"
#include "gl/RecentTargets.h"
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

/// The hierarchy's textures a receiving program samples, by the names the shared includes give them:
/// the atlas means of a gather (uGeoPosition, uGeoNormal), level 0's G-buffer pixels
/// (eye_pixel.glsl: gPosition, gNormal, gAlbedo) and the coarse patches (eye_patch.glsl:
/// uAtlasPosition, uAtlasNormal, uAtlasAlbedo). Names the program does not declare stay unbound.
struct EyeInputHandles {
    EyeInputHandles() = default;
    explicit EyeInputHandles(const gl::Program& program);
    gl::TextureUnit geoPosition{gl::kNoUnit}, geoNormal{gl::kNoUnit};
    gl::TextureUnit pixelPosition{gl::kNoUnit}, pixelNormal{gl::kNoUnit}, pixelAlbedo{gl::kNoUnit};
    gl::TextureUnit atlasPosition{gl::kNoUnit}, atlasNormal{gl::kNoUnit}, atlasAlbedo{gl::kNoUnit};
};

/// What a receiver pass (a compute program including gi/common/eye_receiver_list.glsl with
/// GIS_EYE_RECEIVER_PASS defined) binds: the hierarchy's inputs, the list and the illumination image.
struct EyeReceiverPassHandles {
    EyeReceiverPassHandles() = default;
    explicit EyeReceiverPassHandles(const gl::Program& program);
    EyeInputHandles inputs;
    gl::BlockBinding list;
    gl::ImageUnit illumination;
    gl::UniformLocation groupBase; ///< uEyeReceiverGroupBase
};

struct EyeHierarchyOptions {
    /// The mipmap also averages the albedo (uAtlasAlbedo, eye_patch.glsl), which only multires_splat's
    /// patches read; the others leave it out (GIS_EYE_ALBEDO in eye_mip_reduce.frag).
    bool patchAlbedo = false;
    /// The stencil pass also lists the receivers (eye_receiver_list.glsl) for receiver passes.
    bool receiverList = false;
};

class EyeHierarchy {
public:
    explicit EyeHierarchy(EyeHierarchyOptions options = {});
    /// (Re)allocates the atlas when the size or coarsest level changes; may throw gis::Error.
    void ensureLayout(int width, int height, int coarsestSize);

    /// Builds the mipmaps and flags ("eye_mipmap"), marks the receivers in the stencil
    /// ("stencil_setup"), lists them (receiverList) and clears the illumination atlas.
    /// A later VPL part of the same image (FrameInputs::sameImageAsLastPart) keeps the mipmaps and
    /// flags of the part before.
    void build(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer);
    /// Reads back the receiver count per level (synchronises) and writes the counters
    /// receivers_total, receivers_l<k> and receiver_fraction (receivers / covered pixels).
    void countReceivers(Counters& counters, int coveredPixels = -1);
    /// The receivers the last build() listed (receiverList only): reads the list's header back, which
    /// waits for the stencil pass. What a frame's work cap needs before its gather is dispatched.
    long listedReceivers() const;
    /// The receiver work cap (receiver_share_cap, capVplsForReceivers in gi/Catalog.h) on the frame
    /// the last build() was for (receiverList only): with a cap below 1, reads the receivers back and,
    /// over the cap's share of the frame's pixels, lowers `params`' VPL knob through info.limitVpls and
    /// writes the counter receiver_share_capped_vpls = vpls(params). `vpls`: the technique's VPL count
    /// under a parameter set; the exponent is the frame's (FrameInputs::receiverCapExponent). Returns
    /// whether it cut; a frame without a cap waits for nothing.
    bool capVplsToReceivers(const FrameInputs& in, const TechniqueInfo& info, ParamSet& params,
                            const std::function<long(const ParamSet&)>& vpls, Counters& counters) const;
    /// Reconstructs level 0 ("upsample") and writes the full-resolution indirect radiance.
    /// `irradiance`: one receiver list per frame holding irradiance (bilinear upsampling, albedo / pi
    /// applied per pixel); false: per-VPL lists holding radiance (parent replicated, see eyeCombine).
    void reconstruct(const FrameInputs& in, const ParamSet& params, bool irradiance,
                     const gl::Framebuffer& indirectTarget, gl::PassTimer& timer);

    const std::vector<EyeLevel>& levels() const { return mLevels; }
    int atlasWidth() const { return mAtlasWidth; }
    int atlasHeight() const { return mAtlasHeight; }
    const gl::Texture& illumination() const { return mTargets.illumination; }
    const gl::Texture& geoPosition() const { return mTargets.geoPosition; }
    const gl::Texture& geoNormal() const { return mTargets.geoNormal; }
    const gl::Texture& geoAlbedo() const { return mTargets.geoAlbedo; }
    const gl::Texture& flags() const { return mTargets.flags; }
    /// State a fragment pass that lights receivers needs, set on `pass` (its program in use): the
    /// illumination atlas as target, the hierarchy's textures the program reads (bindInputs),
    /// additive rgb with alpha marking data (multires_splat's splats, whose list items are the
    /// receivers). The pass undoes it at its end.
    void beginIlluminationPass(gl::Pass& pass, const EyeInputHandles& handles, const FrameInputs& in) const;
    /// State a receiver pass needs, set on `pass` (its compute program in use; receiverList only): the
    /// hierarchy's textures the program reads, the receiver list, the illumination atlas as image.
    void beginReceiverPass(gl::Pass& pass, const EyeReceiverPassHandles& handles,
                           const FrameInputs& in) const;
    /// The receivers the stencil pass listed (at most the list's capacity), read back: this waits
    /// for the stencil pass.
    unsigned readReceiverCount() const;
    /// Clears what receiver passes added to the illumination atlas since build() (a gather that
    /// starts again).
    void clearIllumination() const;
    /// Runs the receiver program in use once per receiver (indirect, from the count the stencil pass
    /// appended); each dispatch sees the illumination the ones before it added. With `stop` and more
    /// than one `chunks` (refinement: gatherCut) it reads the count back and runs the list in that
    /// many chunks instead, `stop` asked after each but the last: at its first true
    /// the rest is left and false is returned, so that input waits for one chunk rather than the whole
    /// pass. Each receiver is lit exactly as by one dispatch.
    bool dispatchReceivers(gl::Pass& pass, const EyeReceiverPassHandles& handles,
                           const std::function<bool()>& stop = {}, int chunks = 1) const;
    /// Binds the hierarchy's uniform block at GIS_UBO_EYE (every pass using eye_hierarchy.glsl).
    void bindUniforms() const;
    /// Binds the hierarchy's textures and the G-buffer (level 0) where `handles` name them.
    void bindInputs(gl::Pass& pass, const EyeInputHandles& handles, const FrameInputs& in) const;
    const gl::VertexArray& emptyVao() const { return mEmptyVao; }
    const std::array<unsigned, GIS_MAX_EYE_LEVELS>& lastReceiverCounts() const { return mLastCounts; }

    /// Test hook: the receiver stencil read back as (level, x, y) triples, sorted.
    std::vector<std::array<int, 3>> readReceiverSet() const;
    /// Test hook (receiverList): the receiver list read back like readReceiverSet(), duplicates kept,
    /// and its header.
    std::vector<std::array<int, 3>> readReceiverList(shader::EyeReceiverListHeader* header = nullptr) const;

private:
    /// The geometry mipmaps and the refinement flags over the G-buffer ("eye_mipmap", "refine_flags").
    void buildGeometryLevels(const FrameInputs& in, gl::PassTimer& timer);
    void uploadUniforms(const ParamSet& params);

    struct ReduceProgram {
        explicit ReduceProgram(gl::Program built);
        gl::Program program;
        gl::UniformLocation level;
        std::array<gl::TextureUnit, 6> geo; ///< position, normal, albedo, depth info, normal min, max
        EyeInputHandles inputs;
    };
    struct FlagsProgram {
        gl::Program program;
        gl::UniformLocation level;
        gl::TextureUnit discFlags, flags;
    };
    struct ReceiversProgram {
        gl::Program program;
        gl::UniformLocation level;
        gl::TextureUnit flags;
        EyeInputHandles inputs;
        gl::BlockBinding list; ///< receiverList only
    };
    struct ReceiverDispatchProgram {
        gl::Program program;
        gl::BlockBinding list;
    };
    struct UpsampleProgram {
        gl::Program program;
        gl::UniformLocation interpolate, level;
        gl::TextureUnit rendered, reconstructed, atlasPosition, atlasNormal;
    };
    struct ResolveProgram {
        gl::Program program;
        gl::UniformLocation irradiance, interpolate, detailAlpha;
        gl::TextureUnit position, normal, albedo, reconstructed, rendered, atlasPosition, atlasNormal;
    };
    /// Level 1 from the G-buffer, without and with the per-pixel neighbour metrics (derivative,
    /// curvature: a program variant, see eye_mip_reduce.frag); the coarser levels.
    std::array<std::unique_ptr<ReduceProgram>, 2> mReduceFromPixels;
    std::unique_ptr<ReduceProgram> mReduce;
    bool mPixelMetrics = false;   ///< the depth or normal metric reads the pixels' neighbours
    EyeHierarchyOptions mOptions; ///< patchAlbedo: the mipmap writes mTargets.geoAlbedo (its last attachment)
    FlagsProgram mFlagsProgram;
    /// The stencil's receiver test on level 0 (the G-buffer's pixels) and on the coarser levels
    /// (GIS_EYE_PIXEL_LEVEL in eye_receivers.frag).
    ReceiversProgram mPixelReceivers, mPatchReceivers;
    ReceiverDispatchProgram mReceiverDispatch; ///< receiverList only
    UpsampleProgram mUpsample;
    ResolveProgram mResolve;
    gl::VertexArray mEmptyVao;
    gl::Buffer mUbo;
    std::array<gl::Query, GIS_MAX_EYE_LEVELS> mReceiverQueries; ///< samples passed per level's stencil draw
    std::vector<EyeLevel> mLevels;
    int mWidth = 0, mHeight = 0, mCoarsest = 0, mAtlasWidth = 0, mAtlasHeight = 0;
    bool mBuilt = false; ///< the mipmaps and flags were built for the current layout
    /// What is sized to the atlas of one layout (width, height, coarsest level).
    struct LayoutTargets {
        gl::Texture geoPosition, geoNormal, geoAlbedo, depthInfo, normalMin, normalMax, flags, discFlags;
        gl::Texture illumination, stencil, reconstructed;
        gl::Framebuffer geoFbo, flagsFbo, illumFbo, reconFbo;
        gl::Buffer receiverList; ///< shader::EyeReceiverListHeader, then one item per atlas texel
    };
    LayoutTargets createTargets(int atlasWidth, int atlasHeight) const;
    LayoutTargets mTargets;
    /// The targets of the last few other layouts (gl/RecentTargets.h): at most 4, 768k atlas texels.
    gl::RecentTargets<std::array<int, 3>, LayoutTargets> mRecentLayouts{4, 768.0 * 1024.0};
    std::array<unsigned, GIS_MAX_EYE_LEVELS> mLastCounts{};
};

} // namespace gis
