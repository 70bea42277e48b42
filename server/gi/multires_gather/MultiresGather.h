// Technique `multires_gather`: one-bounce indirect light gathered into a multiresolution buffer
// selected by a one-pass stencil, then reconstructed to full resolution.
//
// Paper: 001 (Nichols, Shopf & Wyman 2009) §3.2; digest S.3 preset multires_gather (VPL set A,
// receivers R3, kernel K2, reconstruction U1).
//
// Pipeline:
//   1. (renderer) RSM and G-buffer
//   2. eye_mipmap: level 0 statistics from the G-buffer, min-max / derivative / curvature mips up
//      to the coarsest level; refine_flags: the refinement flag of every texel (EyeHierarchy)
//   3. stencil_setup: one full-screen draw per level of the flattened buffer sets stencil 1 at
//      receivers, counted by occlusion queries, and appends them to the receiver list
//   4. vpl_extract: vpl_grid^2 VPLs on a regular RSM grid into the compact VPL buffer (the cache);
//      with receiver_share_cap below 1 and more receivers than that share, a coarser grid
//      (capVplsForReceivers, gi/Catalog.h)
//   5. vpl_gather: one compute dispatch per VPL batch over the receiver list; receivers sum the kernel
//   6. upsample: coarse-to-fine reconstruction (000 §3.5), then albedo / pi per pixel
//
// Parameters: vpl_grid [1, 256] (16), kernel point|disk (disk), min_distance [0, 0.5] of the scene's
// size (0.05, point only); receiver_share_cap [0.001, 1] receivers per pixel (1: none; the live view
// sets it, docs/interactive.md); the eye hierarchy's thresholds (EyeHierarchy.h: coarsest_size 16,
// depth 0.1 relative, normal 0.25, diagonal on, detail_alpha 0).
//
// Limits: no indirect visibility; diffuse receivers; a coarse patch is lit at its mean position and
// normal, so light varying inside a flat patch (near a VPL) is averaged: depth_threshold trades this.
#pragma once

#include "gi/Technique.h"
#include "gi/common/IndirectTarget.h"
#include "gi/common/BiasCompensation.h"
#include "gi/common/EyeHierarchy.h"
#include "gi/common/VplGrid.h"

namespace gis {

class MultiresGather final : public Technique {
public:
    MultiresGather();
    void resize(int width, int height) override;
    void execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                 Counters& counters) override;
    const gl::Texture* indirect() const override { return &mIndirect.texture; }
    EyeHierarchy& hierarchy() { return mEye; }

private:
    VplGrid mVpls;
    EyeHierarchy mEye{{.receiverList = true}};
    struct GatherProgram {
        explicit GatherProgram(gl::Program built);
        gl::Program program;
        gl::UniformLocation minDistance, vplCount, vplScale;
        VplTransportHandles transport;
        EyeReceiverPassHandles eye;
    };
    KernelPrograms<GatherProgram> mGather;
    BiasCompensation mSsbc;
    IndirectTarget mIndirect;
};

} // namespace gis
