#version 450 core
// Initial subsplat list (000 §3 step 5): every covered texel of the coarsest level, once per frame
// (geometry refinement) or once per VPL (per-VPL refinement: VPL-major items).
#include "common.glsl"
#include "gi/common/eye_hierarchy.glsl"
#include "gi/common/eye_pixel.glsl"
#include "shared/Subsplat.h"

layout(local_size_x = GIS_SUBSPLAT_GROUP) in;

layout(binding = 6) uniform usampler2D uFlags;
layout(std430, binding = 3) writeonly buffer NextList { uvec2 gOut[]; }; // the first pass's input
layout(std430, binding = 4) buffer Counters { SubsplatCounters gCounters; };

uniform int uItems;     // coarsest texels x VPLs (1 VPL for geometry refinement)
uniform uint uCapacity; // list capacity (items)

uint packPatch(int level, ivec2 t) { return (uint(level) << 28) | (uint(t.y) << 14) | uint(t.x); }

void main() {
    // 2D dispatch when the items need more than GIS_SUBSPLAT_MAX_GROUPS_X groups (128^2 VPLs).
    uint linearIndex = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * GIS_SUBSPLAT_GROUP + gl_LocalInvocationID.x;
    if (linearIndex >= uint(uItems)) return;
    int index = int(linearIndex);
    int coarsest = eyeLevelCount() - 1;
    ivec2 size = eyeLevelSize(coarsest);
    int texels = size.x * size.y;
    int texel = index % texels;
    ivec2 t = ivec2(texel % size.x, texel / size.x);
    bool covered;
    if (coarsest == 0) covered = eyePixelCovered(t); // the image is no larger than one coarse patch
    else covered = (texelFetch(uFlags, eyeAtlas(coarsest, t), 0).r & GIS_EYE_FLAG_COVERED) != 0u;
    if (!covered) return;
    uint slot = atomicAdd(gCounters.counts.y, 1u);
    if (slot < uCapacity) gOut[slot] = uvec2(uint(index / texels), packPatch(coarsest, t));
    else atomicAdd(gCounters.counts.w, 1u); // dropped: reported, never written out of bounds
}
