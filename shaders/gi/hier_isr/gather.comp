#version 450 core
// Hierarchical image-space radiosity gather (001 §3.5, digest S.3 P4 D + P6 lightcut): every eye
// receiver (one invocation per item of the receiver list, as multires_gather) walks the light tree
// itself. It starts from all
// nodes of level uStartLevel and descends, with an explicit stack, wherever 001 Eq. 8 asks for
// refinement, down to uLeafLevel; a node that is not refined (or is a leaf) contributes with the
// disk kernel (001 Eq. 1) at its flux-weighted mean position with its summed flux and area. The
// cut covers every valid texel exactly once, so it carries the RSM's whole flux.
//
// Refinement (HierIsr.h derives it): refine node j on a level of side R_l iff
//   |V_ij|^2 <= T_l |V_j|max^2,   T_l = Omega (1 - tau) / (pi tau R_l^2),
// Omega the light frustum's solid angle, |V_j|max the node's max light distance. uRefineMode
// carries the degenerate taus: tau <= 0 always refines (T = +inf), tau >= 1 never (T <= 0).
#define GIS_EYE_RECEIVER_PASS
#include "common.glsl"
#include "gi/common/eye_receiver_list.glsl"
#include "gi/common/light_tree.glsl"
#include "gi/common/vpl_transport.glsl"

// Traversal statistics: 64-bit sums as (lo, hi) pairs (a full traversal at R = 256 visits 87k
// nodes per receiver, which overflows 32 bits over a frame), and the receivers whose traversal a
// driver's loop limit cut short (the traversal's split, HierIsr.h, keeps llvmpipe's from it), and
// the visits on the leaf level: without them the sum is the work one level coarser would do.
layout(std430, binding = 3) buffer CutStats {
    uint gVisitedLo, gVisitedHi, gVisitedMax, gCutLo, gCutHi, gCutMax, gCutShort, gLeafVisitedLo, gLeafVisitedHi;
};

uniform int uStartLevel;  // level index of the traversal's start (hier_coarsest)
uniform int uLeafLevel;   // finest level visited (<= uStartLevel)
uniform int uRefineMode;  // 0 Eq. 8 test, 1 always refine, 2 never refine
uniform float uTau;       // in (0, 1) when uRefineMode == 0
// The traversal's split (HierIsr.h, traversalSplit): this dispatch descends from the nodes of
// uRootLevel (<= uStartLevel) numbered [uRootFirst, uRootEnd) in row-major order. A root below the
// start level is reached when the test refines each of its ancestors; the first ancestor it does
// not refine contributes once, from its first descendant on uRootLevel, so that every split gives
// the cut the traversal from the start level gives, node for node.
uniform int uRootLevel;
uniform int uRootFirst;
uniform int uRootEnd;

// Depth-first, at most 3 pending siblings per level below the root: 1 + 3 * 11 < 48.
const int kStack = 48;

uint packNode(int level, ivec2 t) { return uint(level) | (uint(t.x) << 4) | (uint(t.y) << 18); }

// Atomics need the buffer variable itself, hence a macro; the carry out of the low word goes high.
#define GIS_ADD64(lo, hi, v) \
    if (atomicAdd(lo, v) + (v) < (v)) atomicAdd(hi, 1u)

// 001 Eq. 8 for a node above the leaf level (HierIsr.h derives `scale`).
bool refines(LightNode node, int level, vec3 pos, float scale) {
    if (uRefineMode == 1) return true;
    if (uRefineMode != 0) return false;
    vec3 v = node.position.xyz - pos;
    float side = float(lightLevelSide(level));
    float dmax = node.hi.w;
    return dot(v, v) * side * side <= scale * dmax * dmax;
}

void main() {
    ivec2 a;
    if (!eyeReceiver(a)) return;
    vec3 pos, n;
    eyeReceiverGeometry(a, pos, n);

    // Omega (1 - tau) / (pi tau); tau is inside (0, 1) whenever the test runs.
    float t = gFrame.rsmInfo.y;
    float omega = 4.0 * asin(clamp(t * t / (1.0 + t * t), 0.0, 1.0));
    float scale = uRefineMode == 0 ? omega * (1.0 - uTau) / (kPi * max(uTau, 1e-30)) : 0.0;

    uint stack[kStack];
    vec3 e = vec3(0.0);
    uint visited = 0u, cut = 0u, leafVisited = 0u;
    int splitLevels = max(uStartLevel - uRootLevel, 0);
    int rootSide = lightLevelSide(uRootLevel);
    int rootBegin = max(uRootFirst, 0);
    int rootEnd = min(uRootEnd, rootSide * rootSide);
    int rootsDone = 0; // roots whose traversal ended: fewer when a loop limit stopped it
    for (int r = rootBegin; r < rootEnd; ++r) {
        ivec2 p = ivec2(r % rootSide, r / rootSide);
        // The ancestors from the start level down: each visited (and counted) by its first
        // descendant's invocation alone, decided by the same test for every descendant.
        bool reached = true;
        for (int up = splitLevels; up >= 1 && reached; --up) {
            int level = uRootLevel + up;
            ivec2 q = p >> up;
            bool first = all(equal(p & ivec2((1 << up) - 1), ivec2(0)));
            LightNode node = lightNodeTexel(lightNodeIndex(level, q));
            if (first) ++visited;
            if (node.position.w < 0.5) {
                reached = false; // empty: no flux below it
            } else if (!refines(node, level, pos, scale)) {
                reached = false;
                if (first) {
                    e += vplIrradianceDisk(pos, n, node.position.xyz, node.normal.xyz, node.flux.rgb,
                                           node.normal.w);
                    ++cut;
                }
            }
        }
        if (!reached) {
            ++rootsDone;
            continue;
        }
        stack[0] = packNode(uRootLevel, p);
        int sp = 1;
        while (sp > 0) {
            uint s = stack[--sp];
            int level = int(s & 15u);
            ivec2 c = ivec2(int((s >> 4) & 0x3FFFu), int(s >> 18));
            LightNode node = lightNodeTexel(lightNodeIndex(level, c));
            ++visited;
            if (level == uLeafLevel) ++leafVisited;
            if (node.position.w < 0.5) continue; // empty: no flux below it
            if (level > uLeafLevel && sp + 4 <= kStack && refines(node, level, pos, scale)) {
                int child = level - 1;
                int childSide = lightLevelSide(child);
                for (int k = 3; k >= 0; --k) {
                    ivec2 cc = c * 2 + ivec2(k & 1, k >> 1);
                    if (cc.x < childSide && cc.y < childSide) stack[sp++] = packNode(child, cc);
                }
            } else {
                e += vplIrradianceDisk(pos, n, node.position.xyz, node.normal.xyz, node.flux.rgb, node.normal.w);
                ++cut;
            }
        }
        if (sp == 0) ++rootsDone;
    }

    GIS_ADD64(gVisitedLo, gVisitedHi, visited);
    atomicMax(gVisitedMax, visited);
    GIS_ADD64(gCutLo, gCutHi, cut);
    atomicMax(gCutMax, cut);
    if (rootsDone < rootEnd - rootBegin) atomicAdd(gCutShort, 1u);
    GIS_ADD64(gLeafVisitedLo, gLeafVisitedHi, leafVisited);
    eyeAddIllumination(a, max(sanitize(e), vec3(0.0)));
}
