// Screen-space bias compensation (paper 002 "SSBC"; digest 002.2, S.3 correction C2), shared by every
// VPL technique as a post-pass on its clamped indirect radiance.
//
// Theory (002 Eq. 3): with the VPL kernel clamped to G_b = min(G, b) (kernel K3, vpl_transport.glsl),
// L = L_e + sum_i T_r^i (T L_e + T_b L^), T_r the residual operator with G_r = max(G - b, 0). Step 0
// is the image the technique already made, X_0 = direct + clamped indirect; step k applies T_r to the
// previous step's compensation only (digest 002.2 item 9: not to the running total, which would count
// terms twice): C_1 = T_r X_0, C_k = T_r C_{k-1}. The technique's indirect output becomes
// indirect + C_1 + ... + C_N, so the renderer composites direct + indirect + compensation.
//
// T_r in screen space: G_r > 0 only closer than r = 1/sqrt(b) (both cosines <= 1), so each pixel y
// integrates (albedo_y / pi) sum_i G_r(y, z_i) L(z_i) A_i over a mip chain of the G-buffer (area-
// weighted mean position, normal and illumination, summed world area A_i, discontinuity flags), from
// the coarsest level's texels under the disc of screen radius r_s = r / (tan(fov/2) |x - y|) * H/2
// px, refining a sample while its solid angle A cos_z / d^2 exceeds ssbc_solid_angle, or exceeds
// ssbc_discontinuity_angle where the sample spans a discontinuity. Engineering choices (002 leaves
// them open, digest S.5 item 4):
//   - "projected solid angle" = A_i cos+(theta_z) / d^2, the solid angle the sample subtends at y;
//   - A_i is the pixel footprint, Omega_px |x - z|^2 / cos(theta_view) with Omega_px = (2 tan(fov/2) /
//     H)^2 cos^3(off-axis angle): exact for a planar pixel, unlike screen-space derivatives, which
//     break at every depth edge;
//   - grazing fade (002 §4.3): beyond ssbc_grazing_angle (80 deg) the footprint area is multiplied by
//     (cos(theta_view) / cos(80 deg))^2, quadratic in the cosine, 1 at 80 deg (continuous) and 0 at
//     90 deg, so the faded area ~ cos(theta_view) stays bounded where A_i ~ 1/cos diverges (S.4 case 2);
//     the fade is applied per pixel before the mips, so coarse means and sums see it too;
//   - G_r is not linear in the sample's mean, so a sample wider than r/4 whose nearest point may
//     reach G > b is refined too: the image then does not depend on the start level (measured equal
//     to 6 digits for 5 to 10 levels), only on the two solid-angle thresholds;
//   - a sample contributes with the disk form G = cos_y cos_z / (d^2 + A/pi): equal to the point form
//     for small samples, bounded by pi/A for a neighbour pixel (digest 002.6 item 5); the pixel itself
//     (d = 0) is skipped, and coarse samples that contain it are always refined;
//   - visibility inside r is ignored (as in 002); only on-screen surfaces contribute (002.6 item 1).
//
// Parameters (every VPL technique; biasCompensationParamSpecs):
//   clamp_b                    K3 bound on G, [0, 4e4] 1/size^2 (size: the scene's longest side, so
//                              b = clamp_b / size^2 in 1/m^2); 0 = off (the technique's own kernel)
//   ssbc_iterations            N in [0, 3]; 0 = off (default); needs clamp_b > 0
//   ssbc_solid_angle           refinement threshold, [0, 4] sr, default 0.08 sr (002 §4.2)
//   ssbc_discontinuity_angle   refine discontinuous samples above this, [0, 4] sr, default 0.04
//   ssbc_grazing_angle         fade starts here, [1, 90] deg, default 80 (90: no fade)
//   ssbc_input                 illumination (002: X_0 = direct + clamped indirect) | direct (X_0 =
//                              direct only: with the single-bounce VPLs of this renderer, step 1 is
//                              then exactly the clamped one-bounce residual T_r D; 002's VPLs carry
//                              every bounce, so its X_0 holds the indirect light too)
//   ssbc_levels                mip levels incl. the full resolution, [1, 12], default 7 (16^2
//                              coarsest at 1024^2; 002 §4.2 starts at 64^2, measured 2.6x slower
//                              here because every pixel loops over the coarse texels in its disc)
//   ssbc_blur                  false (default) | true: 002 §4.4's edge-preserving blur of the summed
//                              compensation (not of the indirect light): the steps add into an
//                              accumulator, a 5x5 cross-bilateral kernel (spatial Gaussian sigma
//                              1.5 px x normal-chord and relative-distance falloffs, covered pixels
//                              only) blurs it with per-source normalisation (energy conserved), then
//                              it is added to the indirect radiance
//   ssbc_half_resolution       false (default) | true: 002 §5: each step integrates one receiver per
//                              2x2 block (its level-1 mean position and normal) and a bilateral
//                              upsampling (4 nearest blocks, bilinear x the same edge falloffs, each
//                              pixel's own albedo) brings it to full resolution; where every weight
//                              vanishes the pixel takes its own block's value (nearest sample), not a
//                              full-resolution recomputation. Needs ssbc_levels >= 2 (else full res)
//
// Passes: ssbc_mips (level 0 from the G-buffer and X_0, then the reductions), ssbc_integrate_k and
// ssbc_mips_k (k >= 2, the previous compensation's mips); ssbc_upsample_k (half resolution),
// ssbc_blur. Counters: ssbc_samples_mean (samples
// visited per covered pixel and step), ssbc_samples_max, ssbc_energy_added (sum over pixels of the
// mean RGB compensation, radiance x pixels), ssbc_energy_step<k>, ssbc_clamped_energy (the same sum
// of the technique's clamped indirect), ssbc_energy_ratio (added / clamped), ssbc_levels; with half
// resolution ssbc_half_resolution (1 when it ran) and ssbc_upsample_fallback (pixels and steps that
// took the nearest block), the sample counts then being per half-resolution receiver.
#pragma once

#include <vector>

#include "core/Param.h"
#include "gi/Technique.h"
#include "gi/common/ParamSpecs.h"
#include "gl/Objects.h"
#include "gl/Pass.h"
#include "gl/PassTimer.h"
#include "gl/Shader.h"

namespace gis {

/// clamp_b, ssbc_iterations, ssbc_solid_angle, ssbc_discontinuity_angle, ssbc_grazing_angle,
/// ssbc_input, ssbc_levels, ssbc_blur, ssbc_half_resolution; `defaultClampB` and `defaultIterations` let a
/// preset (`ssbc`) turn them on.

class BiasCompensation {
public:
    BiasCompensation();
    /// Adds C_1 + ... + C_N to `indirect` (RGBA32F, in.width x in.height) when clamp_b > 0 and
    /// ssbc_iterations > 0; otherwise does nothing. Never throws; the result stays finite and >= 0.
    void apply(const FrameInputs& in, const ParamSet& params, const gl::Texture& indirect,
               gl::PassTimer& timer, Counters& counters);

private:
    void ensure(int width, int height, int levels);
    void reduce(gl::Pass& pass, int mode, int illumIndex);

    struct BaseProgram {
        gl::Program program;
        gl::UniformLocation tanHalfFov, forward, cosGrazing, withIndirect;
        gl::TextureUnit position, normal, direct, indirect;
        gl::ImageUnit geoOut, normalOut, illumOut;
        gl::BlockBinding sums;
    } mBase;
    struct ReduceProgram {
        gl::Program program;
        gl::UniformLocation level, mode, outSize, childReal;
        gl::ImageUnit geoIn, geoOut, normalIn, normalOut, illumIn, illumOut;
    } mReduce;
    struct IntegrateProgram {
        gl::Program program;
        gl::UniformLocation b, r, tanHalfFov, levels, solidAngle, discAngle, maxVisited, slot, receiverLevel;
        gl::TextureUnit geo, normal, illum, albedo;
        gl::ImageUnit indirect, nextIllum, halfOut;
        gl::BlockBinding sums;
    } mIntegrate;
    struct UpsampleProgram {
        gl::Program program;
        gl::UniformLocation slot;
        gl::TextureUnit geo, normal, half, albedo;
        gl::ImageUnit target, nextIllum;
        gl::BlockBinding sums;
    } mUpsample;
    struct BlurProgram {
        gl::Program program;
        gl::UniformLocation pass;
        gl::TextureUnit geo, normal, source;
        gl::ImageUnit out;
        gl::BlockBinding sums;
    } mBlur;
    gl::Texture mGeo, mNormal, mIllum[2];
    gl::Texture mAccum, mBlurTmp; // ssbc_blur: summed compensation, and it over its kernel weight
    gl::Texture mHalf;            // ssbc_half_resolution: one step's compensation per 2x2 block
    gl::Buffer mSums, mHalfSums;  // per-group counter sums (full- and half-resolution dispatches)
    int mWidth = 0, mHeight = 0, mLevels = 0, mPadW = 0, mPadH = 0;
};

} // namespace gis
