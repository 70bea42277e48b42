// Technique `second_order`: one diffuse bounce from Halton-placed indirect lights, approximate
// indirect shadows from negative indirect lights, evaluated at low resolution with a full-resolution
// fix-up at geometric discontinuities.
//
// Paper: 003 ("Second-Order Illumination in Real-Time") §3.1-3.5; digest S.3 preset second_order
// (VPL set B, receivers R1, kernel K1 + K4, reconstruction U2, correction C1).
//
// Pipeline:
//   1. CPU: positive_count split across the lights by their RSMs' reflected flux
//      (splitPositiveSlots); per light, the first Halton (2, 3) points of its type (Halton.h): sphere
//      points inside a spot's cone (in the light's frame, cached per cone and count), the whole
//      sphere of a point light (each on the cube face of its major axis), 2D points over the lit
//      square of a directional light's orthographic view; projected into the RSM layer
//   2. vpl_place: one compute workgroup per light looks its points up in the RSM (invalid texels
//      give empty lights) and scales their flux so the set carries that light's reflected flux
//   3. negative_place: Halton points in the camera's frustum pick candidate pixels; at each, the
//      back-side irradiance from the positive lights (K4) and its luminance-weighted mean direction
//      form S_neg; the first negative_count back-lit candidates become lights of negative flux
//   4. lowres_gbuffer, lowres_gather: positions and normals averaged over lowres_factor^2 blocks,
//      and the signed irradiance of all lights (positive minus negative, K1) at that resolution
//   5. discontinuity: pixels whose low-res neighbours differ beyond discontinuity_threshold are
//      marked in the stencil (and counted); fixup_gather re-evaluates all lights there
//   6. resolve: bilinear upsampling elsewhere, albedo / pi, and the clamp
//      max(indirect - negative, -direct) so that the composited image is >= 0
//
// Parameters:
//   positive_count           indirect lights, [0, 1024], default 256 (003 Table 1: 100-450)
//   negative_count           negative lights, [0, 1024], default 128 (003: half the positive count)
//   discontinuity_threshold  fix-up where max(1 - n.n', |n.(x' - x)| / |x - eye|) >= it for a low-res
//                            neighbour (x', n'), [0, 2], default 0.05 (003 gives no value: on
//                            builtin:cornell at 256^2 it serves 92.5% of the pixels at low resolution
//                            with 0.38% relative RMSE against threshold 0; docs/second_order.md);
//                            0 = every pixel at full resolution (no low-res pass), 2 = no fix-up
//   lowres_factor            pixels per low-res texel side, [1, 8], default 2 (003 §3.5: 2x2)
//   min_distance             K1 falloff clamp max(d^2, (min_distance size)^2), [0, 0.5] of the scene's
//                            size (its longest side), default 0.05 (0.1 m in the 2 m Cornell room)
//                            (003 gives none; the same default as the other point-kernel techniques)
//
// Counters: positive_count (accepted cone points), positive_valid (of those, on a surface),
// halton_draws, cone_capped (1 when the draw cap stopped the sampler early), negative_candidates,
// negative_count (placed), vpl_count, vpl_batches, covered_pixels, fixup_pixels, lowres_fraction
// (share of covered pixels served by the low-res pass, 0-1), negative_clamped_fraction (share of
// covered pixels where the clamp acted, 0-1). The counts read back at the end of the frame wait for
// its last pass (003's discontinuity read-back was a sync point too).
//
// Limits: one bounce, diffuse only; negative lights see only camera-visible surfaces (view-dependent
// shadows, digest 003.5 item 2), ignore visibility themselves and spread the blocked light over a
// cosine lobe, so they can over-darken (clamped); light positions are stable while the scene and
// light are static, but jump when they move; narrow cones return fewer lights (cap Halton.h).
#pragma once

#include <vector>

#include "gi/Technique.h"
#include "gi/common/BiasCompensation.h"
#include "gi/common/VplGrid.h"
#include "gi/second_order/Halton.h"
#include "gl/Shader.h"

namespace gis {

namespace shader {
struct Vpl;
}

/// `slots` positive lights split across lights in proportion to `lightFlux` (largest remainders:
/// the counts sum to `slots`; each light with flux gets one while slots last). Pure.
std::vector<int> splitPositiveSlots(int slots, const std::vector<double>& lightFlux);

class SecondOrder final : public Technique {
public:
    SecondOrder();
    void resize(int width, int height) override;
    void execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                 Counters& counters) override;
    const gl::Texture* indirect() const override { return &mIndirect; }

    /// Test hook: the last frame's positive lights, then its negative lights (synchronises).
    std::vector<shader::Vpl> readVpls(int* positiveCount = nullptr) const;

private:
    struct ConeCache {
        double cosHalfAngle = 2.0; // no cone yet
        int count = -1;
        halton::ConeSamples samples;
    };
    const halton::ConeSamples& cone(ConeCache& cache, double cosHalfAngle, int count);
    int placePositive(const FrameInputs& in, gl::PassTimer& timer, Counters& counters);
    int placeNegative(const FrameInputs& in, const ParamSet& params, int positiveCount, gl::PassTimer& timer,
                      Counters& counters);
    /// The VPL and negative-light gather into the pass's target, with `position` and `normal` as the
    /// receivers (low-resolution or full G-buffer); `sceneSize` (m) scales the distance knobs.
    void gather(gl::Pass& pass, const gl::Texture& position, const gl::Texture& normal,
                const ParamSet& params, float sceneSize, int slots, Counters& counters);

    std::vector<ConeCache> mLightCones; ///< one per light
    ConeCache mCameraCone;
    struct PlacePositiveProgram {
        gl::Program program;
        gl::UniformLocation first, count, light, rsmSize, sampleMeasure;
        gl::TextureUnit position, normal, flux;
        gl::BlockBinding vpls, samples, stats;
    } mPlacePositive;
    struct PlaceNegativeProgram {
        gl::Program program;
        gl::UniformLocation positiveCount, negativeCount, candidateCount, frustumSolidAngle, minDistance,
            minCosView;
        gl::TextureUnit position, normal;
        gl::BlockBinding vpls, candidates, stats;
    } mPlaceNegative;
    struct LowGeometryProgram {
        gl::Program program;
        gl::UniformLocation factor;
        gl::TextureUnit position, normal;
    } mLowGeometry;
    struct GatherProgram {
        gl::Program program;
        gl::UniformLocation minDistance, vplCount, batchFirst;
        gl::TextureUnit position, normal;
        gl::BlockBinding stats;
        VplTransportHandles transport;
    } mGather;
    struct DiscontinuityProgram {
        gl::Program program;
        gl::UniformLocation factor, lowSize, threshold;
        gl::TextureUnit position, normal, lowPosition, lowNormal;
    } mDiscontinuity;
    struct ResolveProgram {
        gl::Program program;
        gl::UniformLocation factor, lowSize, fixup, hasDirect;
        gl::TextureUnit position, albedo, direct, flag, fullIrradiance, lowIrradiance, lowPosition;
        gl::BlockBinding stats;
    } mResolve;
    BiasCompensation mSsbc;
    gl::VertexArray mEmptyVao;
    gl::Buffer mSamples, mCandidates, mVpls, mStats;
    VplBatches mBatches;
    gl::Query mFlaggedQuery, mCoveredQuery;
    int mPositiveSlots = 0, mNegativeSlots = 0;

    // Low-res targets are full size: a frame renders into their lowres_factor-reduced corner, so a
    // factor change allocates nothing on the per-frame path.
    gl::Texture mLowPosition, mLowNormal, mLowIrradiance;
    gl::Texture mFlag, mStencil, mFullIrradiance, mIndirect;
    gl::Framebuffer mLowGeometryFbo, mLowIrradianceFbo, mFlagFbo, mFixupFbo, mResolveFbo;
};

} // namespace gis
