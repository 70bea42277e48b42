// Technique `isr`: image-space radiosity. Per frame, the light tree is cut into light patches that
// are large where the lit surfaces are smooth in light space and small around light-space
// discontinuities; each patch is one VPL, gathered with the disk kernel at the eye hierarchy's
// receivers (its receiver list).
//
// Paper: 001 (Nichols, Shopf & Wyman 2009) §3.4; digest S.3 preset isr (VPL set C, receivers R3,
// kernel K2, reconstruction U1).
//
// Pipeline:
//   1. (renderer) RSM and G-buffer
//   2. light_tree: the RSM's implicit mip pyramid with sums, means and min-max (LightTree.h)
//   3. isr_select: two compute passes pick the patches between isr_coarsest and isr_finest (a node
//      is a VPL iff it is valid, continuous, and all its ancestors were discontinuous; the finest
//      level takes what is left) and append them, in a deterministic order, to the VPL cache; each
//      VPL carries its patch's summed flux and area, so the set conserves the RSM's flux
//   4. eye_mipmap, refine_flags, stencil_setup: the eye hierarchy and its receiver list (EyeHierarchy.h)
//   5. vpl_gather: multires_gather's gather over the receiver list (disk kernel), a dispatch per VPL batch;
//      the VPL count is read back first (a small sync; it also feeds the counters)
//   6. upsample: coarse-to-fine reconstruction, albedo / pi per pixel
//
// Parameters:
//   isr_coarsest           coarsest light patches, patches per side, [1, 256], default 16 (001 Fig. 7)
//   isr_finest             finest light patches per side, [1, 256], default 64 (001 Fig. 10's
//                          "maximum VPL subdivision 64^2"); both name the finest tree level whose side
//                          does not exceed them and are clamped to rsm_size; coarsest >= finest
//   light_depth_threshold  refine where (max - min) light distance > threshold * min, [0, 1],
//                          default 0.2 (001 gives no value. builtin:cornell at 256^2: 0.1 -> 1151 VPLs,
//                          4.42% relative RMSE against the 256^2-VPL full gather; 0.2 -> 731 VPLs,
//                          4.46%; 0 -> 3194 VPLs, 3.81%: the error is dominated by the 64^2 limit
//                          and the eye hierarchy, so the cheaper setting is the default)
//   light_normal_threshold refine where any normal component's range exceeds it, [0, 2], default 0.25
//                          (the eye hierarchy's quality setting, 000 Figs. 11-12)
//   receiver_share_cap     receivers per pixel, [0.001, 1], default 1 (none): above it, isr_finest is
//                          lowered as the frame budget would (capVplsForReceivers, gi/Catalog.h); the
//                          selection runs after the eye hierarchy for it. The live view sets it
//   partial validity (a patch with empty texels) always refines.
//   Eye hierarchy: coarsest_size, depth/normal metrics and thresholds, diagonal_refine, detail_alpha
//   (EyeHierarchy.h).
//
// Counters: vpl_count, vpls_r<side> (VPLs on the level of that many patches per side),
// vpl_tree_levels, vpl_tree_nodes, vpl_batches, and the eye hierarchy's receiver counts.
//
// Limits: no indirect visibility; diffuse only; a patch is one disk at its flux-weighted mean, so a
// large flat patch close to a receiver is approximated by one disk (the disk kernel bounds it; 001
// accepts this); the VPL count follows light-space complexity, so cost varies as the light moves
// (001 §5).
#pragma once

#include "gi/Technique.h"
#include "gi/common/IndirectTarget.h"
#include "gi/common/BiasCompensation.h"
#include "gi/common/EyeHierarchy.h"
#include "gi/common/LightTree.h"
#include "gi/common/VplGrid.h"

namespace gis {

class Isr final : public Technique {
public:
    Isr();
    void resize(int width, int height) override;
    void execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                 Counters& counters) override;
    const gl::Texture* indirect() const override { return &mIndirect.texture; }

    /// Test hooks: the light tree, and the VPLs of the last frame read back (synchronises).
    const LightTree& tree() const { return mTree; }
    std::vector<shader::Vpl> readVpls() const;

private:
    int select(const ParamSet& params, gl::PassTimer& timer, Counters& counters);

    LightTree mTree;
    EyeHierarchy mEye{{.receiverList = true}};
    BiasCompensation mSsbc;
    struct SelectProgram {
        gl::Program program;
        gl::UniformLocation phase, finest, coarsest, first, nodeCount, capacity, depthThreshold,
            normalThreshold;
        gl::BlockBinding counts, vpls;
    } mSelect;
    struct GatherProgram {
        gl::Program program;
        gl::UniformLocation vplCount, vplScale; ///< scale 1: isr renders no VPL parts
        VplTransportHandles transport;
        EyeReceiverPassHandles eye;
    } mGather;
    gl::Buffer mVpls, mCounts;
    VplBatches mBatches;
    int mVplCount = 0;
    IndirectTarget mIndirect;
};

} // namespace gis
