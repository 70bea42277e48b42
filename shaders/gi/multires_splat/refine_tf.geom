#version 450 core
// One refinement pass in a geometry shader with transform feedback, the form 000 §3 step 5
// describes: a subsplat that must be subdivided emits its covered children on stream 0 (the next
// pass's input); any other covered subsplat goes to stream 1 (this level's splat list). Kept as a
// measured alternative to the compute append lists of refine.comp (same flags, same lists).
#include "common.glsl"
#include "gi/common/eye_hierarchy.glsl"
#include "gi/common/eye_pixel.glsl"

layout(points) in;
layout(points, max_vertices = 4) out;

flat in uvec2 vItem[];
layout(stream = 0) out uvec2 gNext;
layout(stream = 1) out uvec2 gSplat;

layout(binding = 6) uniform usampler2D uFlags;
uniform int uLevel;

uint packPatch(int level, ivec2 t) { return (uint(level) << 28) | (uint(t.y) << 14) | uint(t.x); }

bool covered(int level, ivec2 t) {
    if (!eyeInLevel(level, t)) return false;
    if (level == 0) return eyePixelCovered(t);
    return (texelFetch(uFlags, eyeAtlas(level, t), 0).r & GIS_EYE_FLAG_COVERED) != 0u;
}

void main() {
    uvec2 item = vItem[0];
    ivec2 t = ivec2(int(item.y & 0x3FFFu), int((item.y >> 14) & 0x3FFFu));
    if (!covered(uLevel, t)) return; // the seed holds every coarsest texel
    bool refine = uLevel > 0 && (texelFetch(uFlags, eyeAtlas(uLevel, t), 0).r & GIS_EYE_FLAG_REFINE) != 0u;
    if (!refine) {
        gSplat = item;
        EmitStreamVertex(1);
        EndStreamPrimitive(1);
        return;
    }
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            ivec2 c = 2 * t + ivec2(i, j);
            if (!covered(uLevel - 1, c)) continue;
            gNext = uvec2(item.x, packPatch(uLevel - 1, c));
            EmitStreamVertex(0);
            EndStreamPrimitive(0);
        }
}
