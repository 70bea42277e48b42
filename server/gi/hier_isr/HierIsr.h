// Technique `hier_isr`: hierarchical image-space radiosity. Every eye receiver selects its own cut
// through the light tree (a lightcut-like traversal with a conservative bound), so the light-space
// resolution adapts per receiver: fine patches near the receiver, coarse ones far away.
//
// Paper: 001 (Nichols, Shopf & Wyman 2009) §3.5, Eqs. 6-8; digest S.3 preset hier_isr (VPL set D,
// receivers R3, kernel K2 with a per-receiver lightcut, reconstruction U1).
//
// Pipeline:
//   1. (renderer) RSM and G-buffer
//   2. light_tree: the RSM's implicit mip pyramid with sums, means and min-max (LightTree.h)
//   3. eye_mipmap, refine_flags, stencil_setup: the eye hierarchy and its receiver list (EyeHierarchy.h)
//   4. vpl_gather: compute dispatches over the receiver list; each receiver starts from all
//      nodes of the hier_coarsest level and descends with an explicit stack while Eq. 8 asks for
//      refinement, down to the max_depth level; every node it stops at contributes with the disk
//      kernel (001 Eq. 1) with the node's summed flux and area. The cut covers each valid texel once,
//      so every receiver sees the RSM's whole flux. The traversal is split into ranges of roots
//      (below hier_coarsest's when need be) so that no invocation passes a driver's loop limit
//      (traversalSplit below); every split gives the same cut.
//   5. upsample: coarse-to-fine reconstruction, albedo / pi per pixel
//
// Refinement test (001 Eq. 8), with the conventions 001 leaves open (digest S.5 item 3): solid angles
// in steradians, tau relative to the light intensity (I = 1), RSM_res the resolution R_l of the level
// the node lives on. A node j of level side R_l covers omega_j = Omega / R_l^2 of the light frustum's
// solid angle Omega = 4 asin(t^2 / (1 + t^2)) (t = tan of the half field of view, the equal-solid-angle
// split of 001 Eq. 4), so its disk has area A_j = omega_j |V_j|^2 (Eq. 3). With both cosines and the
// albedos at most 1 and I_j <= I, the disk kernel bounds its contribution relative to I (Eqs. 6-7) by
//   B_rel = omega_j |V_j|^2 / (pi r^2 + omega_j |V_j|^2),   r = |V_ij| (receiver to node).
// B_rel <= tau  <=>  (1 - tau) omega_j |V_j|^2 <= tau pi r^2  <=>  r^2 >= T_l |V_j|^2 with
//   T_l = Omega (1 - tau) / (pi tau R_l^2),
// so the node is refined iff |V_ij|^2 <= T_l |V_j|^2_max. For a 90 degree frustum (t = 1)
// Omega = 2 pi / 3 and T_l = 2 (1 - tau) / (3 tau R_l^2): 001 Eq. 8 with I = 1. |V_j|_max is the
// node's maximum light distance from the min-max statistics (001 §3.5: a point sample under-refines
// obliquely lit patches). tau <= 0 always refines (full traversal to max_depth, no division by zero);
// tau >= 1 never refines (the cut is the hier_coarsest level).
//
// Parameters:
//   tau            error bound, fraction of the light intensity I, [0, 1], default 0.01. 001 gives no
//                  value; builtin:cornell at 256^2 against the 256^2-VPL full gather (16 s on
//                  llvmpipe): tau 0.002 -> 2.4% relative RMSE, 0.01 -> 3.0%, 0.02 -> 3.7%,
//                  0.05 -> 4.8%, 0.1 -> 5.5% (the eye hierarchy alone: 2.2%); 0.01 stays well
//                  inside 5% at about 1/100 of the full gather's time (cornell-dense: 3.7%)
//   hier_coarsest  roots: the tree level with at most this many patches per side, [1, 256], default 16
//                  (001 §3.5 "16^2 coarsest light patches"); clamped to max_depth
//   max_depth      finest level visited, patches per side, [1, 1024], default 256, clamped to rsm_size
//                  (001's "maximal traversal depth"; 256 = the full RSM at the default rsm_size)
//   receiver_share_cap  receivers per pixel, [0.001, 1], default 1 (none): above it, max_depth is
//                  lowered, leaves by the cost exponent's root (capVplsForReceivers, gi/Catalog.h).
//                  The live view sets it
//   Eye hierarchy: coarsest_size, depth/normal metrics and thresholds, diagonal_refine, detail_alpha
//   (EyeHierarchy.h).
//
// Counters: nodes_visited_mean / _max, nodes_visited_leaf_mean (the visits on the max_depth level:
// without them, the work a level coarser would do; Info.cpp's localVplCostExponent) and
// cut_size_mean / _max (per receiver; the maxima per range
// when the traversal goes in traversal_ranges ranges of roots), traversal_split_levels (its roots
// that many levels below hier_coarsest's, when split so), traversal_cut_short (receivers a driver's
// loop limit stopped: 0 unless the split fell short) and traversal_cut_short_whole (those of a whole
// traversal by the test, gathered again split), vpl_tree_levels,
// vpl_tree_nodes (and vpl_tree_reused when the last frame's tree served: its light views were
// reused), and the eye hierarchy's receiver counts.
//
// Limits: no indirect visibility; diffuse only; the bound ignores the node's actual flux (001's
// choice), so dark patches refine as much as bright ones; cost per receiver grows as the receiver
// approaches lit surfaces (corners) and with 1/tau; divergent traversals run at the pace of the
// slowest fragment of a SIMD group.
#pragma once

#include <array>
#include <vector>

#include <glm/glm.hpp>

#include "gi/Technique.h"
#include "gi/common/IndirectTarget.h"
#include "gi/common/BiasCompensation.h"
#include "gi/common/EyeHierarchy.h"
#include "gi/common/LightTree.h"
#include "gi/common/VplGrid.h"

namespace gis {

enum class LightRefine { Test = 0, Always = 1, Never = 2 }; ///< values match uRefineMode in gather.comp

struct LightCutSettings {
    int startLevel = 0; ///< level index of the roots (hier_coarsest)
    int leafLevel = 0;  ///< finest level index visited (max_depth)
    LightRefine mode = LightRefine::Test;
    float tau = 0.0f;
};

/// The traversal's levels and refinement mode from the parameters (shared by the GPU pass and the
/// CPU mirror below).
LightCutSettings lightCutSettings(const std::vector<LightLevel>& levels, int coarsestResolution,
                                  int maxDepthResolution, double tau);
/// llvmpipe stops a shader invocation's loops after 65,535 iterations in all (gallivm's loop
/// limiter: one count per SIMD group over every loop of the invocation), silently: a full
/// traversal (tau 0) of 256 roots four levels deep visits 67,848 nodes of cornell's tree, and a
/// single dispatch left out the last 4 % (its last roots' light); tau 0.00003 cut receivers short
/// the same way. traversalSplit splits a traversal so that it stays within kTraversalLoopBudget
/// iterations an invocation whatever the test decides: its roots are taken at most
/// kFullTraversalMaxDepth levels above the leaves (21,845 nodes a root), below the start level when
/// need be (the test still decides the ancestors, once: the same cut, node for node), and go in
/// ranges, each range a dispatch over every receiver. A full traversal (and one that never refines)
/// goes so from the start. A traversal by the test goes whole first (its worst case is far above
/// its usual work); when a loop limit stopped receivers short (gather.comp counts them exactly:
/// traversal_cut_short_whole), it is gathered again split, and split from the start while its
/// settings stay. traversal_cut_short counts the receivers stopped short in the frame's gather (0).
constexpr double kTraversalLoopBudget = 60000.0;
constexpr int kFullTraversalMaxDepth = 7;
struct TraversalSplit {
    int rootLevel = 0; ///< level index of the dispatches' roots (<= LightCutSettings::startLevel)
    int roots = 1;     ///< nodes on that level
    int ranges = 1;    ///< dispatches, each over every receiver and a range of the roots
};
/// The split of a traversal with settings `s` over the tree `levels` that keeps every invocation
/// within `loopBudget` loop iterations at worst (every node refined, except with LightRefine::Never):
/// the deepest subtrees that fit (at most kFullTraversalMaxDepth levels), in as few ranges as fit,
/// at most one root a range. Pure.
TraversalSplit traversalSplit(const std::vector<LightLevel>& levels, const LightCutSettings& s,
                              double loopBudget = kTraversalLoopBudget);
/// Refinement's cut of a full traversal (tau 0: every receiver visits every node down to the leaf
/// level). Receiver chunks cannot shorten it: one group of 64 receivers over 65,536 leaves is about
/// 44 ms of one of llvmpipe's threads. So the roots go in ranges instead, each range a dispatch over
/// every receiver (both threads busy), input's check asked between them: about
/// kTraversalPairsPerRange receiver-leaf pairs a range (about 5 ms on two cores: 0.19 million pairs
/// a ms), at least kGatherPieces ranges, at most kMaxTraversalRanges and one root a range. Pure.
constexpr double kTraversalPairsPerRange = 1048576.0;
constexpr int kMaxTraversalRanges = 64;
int traversalRanges(double receivers, double leavesPerReceiver, int roots);
/// Refinement's pieces of a full traversal over `roots` roots: its ranges (traversalRanges, at least
/// `minRanges`, the loop budget's) and, where the roots are too few for the pieces its work asks
/// (balanced's hier_coarsest 1 over 256 leaves has one root: one dispatch, up to 37 ms between two
/// checks of a tile), each range's receivers in chunks for the rest. Few roots mean few leaves, or
/// ranges already as large as a root's subtree, so a chunk's group stays short there. Pure.
struct TraversalPieces {
    int ranges = 1; ///< dispatches over the roots
    int chunks = 1; ///< receiver chunks in each (EyeHierarchy::dispatchReceivers)
};
TraversalPieces fullTraversalPieces(double receivers, double leavesPerReceiver, int roots, int minRanges);
/// CPU mirror of gather.comp's traversal for one receiver at `receiver`: the flat indices of the
/// nodes that contribute (its cut). `tanHalfFov` is gFrame.rsmInfo.y. For tests.
std::vector<int> lightCutCpu(const std::vector<shader::LightNode>& nodes,
                             const std::vector<LightLevel>& levels, const LightCutSettings& settings,
                             float tanHalfFov, glm::vec3 receiver);

class HierIsr final : public Technique {
public:
    HierIsr();
    void resize(int width, int height) override;
    void execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                 Counters& counters) override;
    const gl::Texture* indirect() const override { return &mIndirect.texture; }

    /// Test hook: the light tree of the last frame.
    const LightTree& tree() const { return mTree; }
    /// Test hook: LightTree::setKeptBytes.
    void setKeptTreeBytes(long long bytes) { mTree.setKeptBytes(bytes); }
    /// Test hook: split traversals for this loop budget instead of kTraversalLoopBudget (a small
    /// one splits a cheap traversal as a costly one would be, to compare it with the whole).
    void setLoopBudget(double iterations) {
        mLoopBudget = iterations;
        mLoopBudgetSet = true;
    }

private:
    LightTree mTree;
    EyeHierarchy mEye{{.receiverList = true}};
    BiasCompensation mSsbc;
    struct GatherProgram {
        gl::Program program;
        gl::UniformLocation startLevel, leafLevel, refineMode, tau, rootLevel, rootFirst, rootEnd;
        gl::BlockBinding stats;
        VplTransportHandles transport;
        EyeReceiverPassHandles eye;
    } mGather;
    gl::Buffer mStats;
    IndirectTarget mIndirect;
    double mLoopBudget = kTraversalLoopBudget;
    bool mLoopBudgetSet = false; ///< a test's budget: every traversal split for it from the start
    /// The settings (tau, start and leaf levels, tree levels) of the last traversal by the test that a
    /// loop limit stopped short when whole: split from the start while they stay.
    std::array<double, 4> mSplitSettings{-1.0, -1.0, -1.0, -1.0};
};

} // namespace gis
