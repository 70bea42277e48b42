#version 450 core
// Refinement flags for every texel of levels >= 1 (level 0 never refines), read by both the
// iterative refinement and the one-pass stencil so both see the same decision. The reduce pass
// already marked each patch's own discontinuity; with the diagonal rule (000 §5.2) a discontinuous
// diagonal neighbour on the same level also forces refinement.
#include "gi/common/eye_hierarchy.glsl"

layout(binding = 7) uniform usampler2D uDiscFlags; // covered | discontinuous, per atlas texel

layout(location = 0) out uint outFlags; // drawn over the level column

bool discontinuous(int level, ivec2 t) {
    return eyeInLevel(level, t) && (texelFetch(uDiscFlags, eyeAtlas(level, t), 0).r & GIS_EYE_FLAG_DISCONTINUOUS) != 0u;
}

void main() {
    ivec2 a = ivec2(gl_FragCoord.xy);
    ivec2 t;
    int level = eyeLevelOf(a, t);
    if (level < 0) {
        outFlags = 0u;
        return;
    }
    uint own = texelFetch(uDiscFlags, a, 0).r;
    bool covered = (own & GIS_EYE_FLAG_COVERED) != 0u;
    bool refine = covered && (own & GIS_EYE_FLAG_DISCONTINUOUS) != 0u;
    if (covered && !refine && (gEye.info.w & GIS_EYE_DIAGONAL) != 0) {
        refine = discontinuous(level, t + ivec2(1, 1)) || discontinuous(level, t + ivec2(-1, 1)) ||
                 discontinuous(level, t + ivec2(1, -1)) || discontinuous(level, t + ivec2(-1, -1));
    }
    outFlags = (covered ? GIS_EYE_FLAG_COVERED : 0u) | (refine ? GIS_EYE_FLAG_REFINE : 0u);
}
