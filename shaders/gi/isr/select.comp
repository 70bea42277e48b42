#version 450 core
// Image-space radiosity light patches (001 §3.4, digest S.3 P4 C): every node of the light tree on
// levels uFinest..uCoarsest decides on its own whether it is a VPL, with the same cut logic as the
// eye hierarchy's receivers (eyeIsReceiver): a node is a VPL iff it holds geometry, has no
// light-space discontinuity, and every ancestor up to the coarsest level has one. Boundary cases:
// the coarsest level has no ancestor; the finest level cannot subdivide, so its nodes are VPLs
// whenever their ancestors all were discontinuous, discontinuous or not. Every valid texel is thus
// under exactly one VPL, and a VPL carries its node's summed flux and area (001: "omega_j set by
// hierarchy level"), so the VPL set conserves the RSM's flux.
//
// Compaction is deterministic (same VPL order every frame, so sums round identically): phase 0
// counts the VPLs of each work group, phase 1 places each group after the ones before it and each
// VPL after the ones before it in its group.
#include "common.glsl"
#include "gi/common/light_tree.glsl"

#define GROUP 256
layout(local_size_x = GROUP) in;

layout(std430, binding = 3) buffer IsrCounts {
    uint gTotal;
    uint gPerLevel[GIS_MAX_LIGHT_LEVELS];
    uint gGroupCount[];
};

layout(std430, binding = 4) writeonly buffer IsrVpls {
    Vpl gVplsOut[];
};

uniform int uPhase;            // 0 count, 1 write
uniform int uFinest;           // level index of the finest patches
uniform int uCoarsest;         // level index of the coarsest patches (>= uFinest)
uniform int uFirst;            // flat index of the first node on uFinest
uniform int uNodeCount;        // nodes on levels uFinest..uCoarsest (contiguous)
uniform int uCapacity;         // VPLs the output buffer holds
uniform float uDepthThreshold; // (max - min) light distance / min distance
uniform float uNormalThreshold; // per-component normal range, [0, 2]

shared uint sScan[GROUP];
shared uint sGroupOffset;

// Light-space discontinuity: partial validity (some texels empty), a light-distance range beyond the
// relative threshold, or a normal component range beyond its threshold.
bool discontinuous(LightNode n, int level, ivec2 t) {
    if (n.flux.w < float(lightFootprintTexels(level, t))) return true;
    if (n.hi.w - n.lo.w > uDepthThreshold * n.lo.w) return true;
    return any(greaterThan(n.hi.xyz - n.lo.xyz, vec3(uNormalThreshold)));
}

bool isVpl(int index, out int level) {
    ivec2 t;
    level = lightLevelOf(index, t);
    if (level < uFinest || level > uCoarsest) return false;
    LightNode n = gLightNodes[index];
    if (n.position.w < 0.5) return false;
    if (level > uFinest && discontinuous(n, level, t)) return false;
    for (int l = level + 1; l <= uCoarsest; ++l) {
        t >>= 1;
        if (!discontinuous(gLightNodes[lightNodeIndex(l, t)], l, t)) return false;
    }
    return true;
}

void main() {
    uint local = gl_LocalInvocationID.x;
    int i = int(gl_GlobalInvocationID.x);
    int level = -1;
    bool vpl = i < uNodeCount && isVpl(uFirst + i, level);

    sScan[local] = vpl ? 1u : 0u;
    barrier();
    // Inclusive Hillis-Steele scan of the group's flags.
    for (uint stride = 1u; stride < uint(GROUP); stride <<= 1) {
        uint add = local >= stride ? sScan[local - stride] : 0u;
        barrier();
        sScan[local] += add;
        barrier();
    }

    if (uPhase == 0) {
        if (local == uint(GROUP - 1)) {
            gGroupCount[gl_WorkGroupID.x] = sScan[local];
            atomicAdd(gTotal, sScan[local]);
        }
        if (vpl) atomicAdd(gPerLevel[level], 1u);
        return;
    }

    if (local == 0u) {
        uint offset = 0u;
        for (uint g = 0u; g < gl_WorkGroupID.x; ++g) offset += gGroupCount[g];
        sGroupOffset = offset;
    }
    barrier();
    if (!vpl) return;
    uint slot = sGroupOffset + sScan[local] - 1u;
    if (slot >= uint(uCapacity)) return; // cannot happen (capacity = nodes on uFinest); guarded
    LightNode n = gLightNodes[uFirst + i];
    Vpl v;
    v.position = vec4(n.position.xyz, 1.0);
    v.normal = n.normal;
    v.flux = n.flux;
    gVplsOut[slot] = v;
}
