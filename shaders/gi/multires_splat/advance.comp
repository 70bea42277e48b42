#version 450 core
// Between refinement passes (one invocation): the next list becomes the input, and the indirect
// dispatch and draw arguments are updated from the counts, so the CPU never waits for the GPU.
#include "shared/Subsplat.h"

layout(local_size_x = 1) in;
layout(std430, binding = 4) buffer Counters { SubsplatCounters gCounters; };

uniform int uMode;       // 0: after seeding or a pass: input = next list; 1: prepare the draw
uniform uint uCapacity;
uniform uint uInstances; // VPL instances per splat item (geometry refinement) or 1

void main() {
    if (uMode == 0) {
        gCounters.counts.x = min(gCounters.counts.y, uCapacity);
        gCounters.counts.y = 0u;
        // 2D when one dimension cannot hold the groups (per-VPL lists reach millions of items).
        uint groups = (gCounters.counts.x + GIS_SUBSPLAT_GROUP - 1u) / GIS_SUBSPLAT_GROUP;
        uint x = min(groups, GIS_SUBSPLAT_MAX_GROUPS_X);
        uint y = x > 0u ? (groups + x - 1u) / x : 1u;
        gCounters.dispatch = uvec4(x, y, 1u, 0u);
    } else {
        gCounters.draw = uvec4(min(gCounters.counts.z, uCapacity), uInstances, 0u, 0u);
    }
}
