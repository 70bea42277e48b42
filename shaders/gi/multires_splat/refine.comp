#version 450 core
// One refinement pass of the subsplat list (000 §3 step 5, §3.3.1), level uLevel -> uLevel - 1.
// An item whose patch must be subdivided is replaced by its covered children in the next list;
// any other item goes to the splat list at its own level. Level 0 never subdivides.
//   geometry refinement: subdivide where the eye hierarchy's refine flag is set (the flag the
//     one-pass stencil reads too, so both build the same receiver set).
//   per-VPL refinement: subdivide where the VPL's radiance at the children's centres differs by
//     more than uIllumThreshold in any channel (000 §3.3.1), or the patch is partly background.
// The lists have a fixed capacity: an item whose children do not fit is splatted unrefined and
// counted (counts.w), so a subsplat explosion degrades resolution instead of overrunning memory.
#include "common.glsl"
#include "gi/common/eye_hierarchy.glsl"
#include "gi/common/eye_pixel.glsl"
#include "gi/common/eye_patch.glsl"
#include "gi/multires_splat/splat_common.glsl"
#include "shared/Subsplat.h"

layout(local_size_x = GIS_SUBSPLAT_GROUP) in;

layout(binding = 6) uniform usampler2D uFlags;
layout(std430, binding = 2) readonly buffer InList { uvec2 gIn[]; };
layout(std430, binding = 3) writeonly buffer NextList { uvec2 gNext[]; };
layout(std430, binding = 5) writeonly buffer SplatList { uvec2 gSplat[]; };
layout(std430, binding = 4) buffer Counters { SubsplatCounters gCounters; };

uniform int uLevel;
uniform uint uCapacity;
uniform float uIllumThreshold; // radiance units (per-VPL refinement)

bool childCovered(int level, ivec2 c) {
    if (!eyeInLevel(level, c)) return false;
    if (level == 0) return eyePixelCovered(c);
    return (texelFetch(uFlags, eyeAtlas(level, c), 0).r & GIS_EYE_FLAG_COVERED) != 0u;
}

// 000 §3.3.1 compares the radiance at the 4 quadrant samples; the patch's own sample (what is
// splatted when the test passes) joins the comparison, so a patch whose children happen to agree
// (e.g. all unlit) but whose mean geometry straddles an edge is still refined.
bool illuminationDiffers(uint vpl, ivec2 t) {
    vec3 own = splatContribution(vpl, eyePatch(uLevel, t));
    vec3 lo = own, hi = own;
    int children = 0;
    float footprint = 0.0, covered = 0.0;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            ivec2 c = 2 * t + ivec2(i, j);
            if (!eyeInLevel(uLevel - 1, c)) continue;
            footprint += eyeFootprintPixels(uLevel - 1, c);
            EyePatch p = eyePatch(uLevel - 1, c);
            covered += p.covered;
            if (p.covered <= 0.0) continue;
            vec3 l = splatContribution(vpl, p);
            lo = min(lo, l);
            hi = max(hi, l);
            ++children;
        }
    if (covered < footprint) return true; // object / background edge: never light the background
    if (children > 0 && all(equal(hi, vec3(0.0)))) {
        // Every sample receives exactly 0. That is a cutoff (the VPL's tangent plane, or the
        // receiver's facing), conclusive for the whole patch only when the patch is one continuous
        // surface (the eye hierarchy's geometric refine flag is clear: mean normals of a patch across
        // a crease may face away while one side is lit) and its mean lies farther behind either plane
        // than the patch's extent (generously 4 x its width, for slanted views). Otherwise refine:
        // zero-sampled patches held 1.4% of the light at T -> 0 (digest S.4 case 13).
        if ((texelFetch(uFlags, eyeAtlas(uLevel, t), 0).r & GIS_EYE_FLAG_REFINE) != 0u) return true;
        EyePatch self = eyePatch(uLevel, t);
        Vpl v = gVpls[vpl];
        float extent = 4.0 * float(1 << uLevel) * eyePixelFootprint(self.position);
        float behindVpl = -dot(v.normal.xyz, self.position - v.position.xyz);
        float behindReceiver = -dot(self.normal, v.position.xyz - self.position);
        return !(behindVpl > extent || behindReceiver > extent);
    }
    return children > 0 && any(greaterThan(hi - lo, vec3(uIllumThreshold)));
}

void splat(uvec2 item) {
    uint slot = atomicAdd(gCounters.counts.z, 1u);
    if (slot >= uCapacity) {
        atomicAdd(gCounters.counts.w, 1u);
        return;
    }
    gSplat[slot] = item;
    atomicAdd(gCounters.perLevel[uLevel / 4][uLevel % 4], 1u);
}

void main() {
    uint index = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * GIS_SUBSPLAT_GROUP +
                 gl_LocalInvocationID.x; // 2D dispatches of long lists (see advance.comp)
    if (index >= min(gCounters.counts.x, uCapacity)) return;
    uvec2 item = gIn[index];
    ivec2 t = patchTexel(item.y);
    bool refine = false;
    // The next list is already full (a subsplat explosion, e.g. 128^2 VPLs with per-VPL lists): no
    // child would fit, so skip the refinement test and splat the item as capped. A racy read of a
    // counter that only shrinks by the hand-back below: at worst an item is tested needlessly.
    if (uLevel > 0 && gCounters.counts.y + 4u > uCapacity) {
        splat(item);
        atomicAdd(gCounters.counts.w, 1u);
        return;
    }
    if (uLevel > 0) {
        if (uPerVpl != 0) refine = illuminationDiffers(item.x, t);
        else refine = (texelFetch(uFlags, eyeAtlas(uLevel, t), 0).r & GIS_EYE_FLAG_REFINE) != 0u;
    }
    if (!refine) {
        splat(item);
        return;
    }
    uvec2 children[4];
    uint count = 0u;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            ivec2 c = 2 * t + ivec2(i, j);
            if (childCovered(uLevel - 1, c)) children[count++] = uvec2(item.x, packPatch(uLevel - 1, c));
        }
    uint slot = atomicAdd(gCounters.counts.y, count);
    if (slot + count > uCapacity) {
        atomicAdd(gCounters.counts.y, -count); // hand the slots back: other items may still fit
        splat(item);
        atomicAdd(gCounters.counts.w, 1u);
        return;
    }
    for (uint k = 0u; k < count; ++k) gNext[slot + k] = children[k];
}
