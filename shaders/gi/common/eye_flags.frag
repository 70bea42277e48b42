#version 450 core
// Refinement flags for every texel of levels >= 1 (level 0 never refines), read by both the
// iterative refinement and the one-pass stencil so both see the same decision. The reduce pass
// already marked each patch's own discontinuity; with the diagonal rule (000 §5.2) a discontinuous
// diagonal neighbour on the same level also forces refinement. Drawn from the coarsest level down,
// each level also marks the patches whose whole ancestor chain refines (GIS_EYE_FLAG_SUBDIVIDED) from
// its parent's finished flags, so the receiver test reads one parent instead of walking the chain.
#include "gi/common/eye_hierarchy.glsl"

layout(binding = 7) uniform usampler2D uDiscFlags; // covered | discontinuous, per atlas texel
layout(binding = 6) uniform usampler2D uFlags;     // the target itself: level uLevel + 1 is finished
                                                   // (glTextureBarrier between levels)

layout(location = 0) out uint outFlags; // drawn once per level >= 1, the viewport covering it

uniform int uLevel;

// Clamped into the level and selected out beyond it: no branch (llvmpipe runs both sides anyway).
bool discontinuous(ivec2 t) {
    ivec2 q = clamp(t, ivec2(0), eyeLevelSize(uLevel) - 1);
    return eyeInLevel(uLevel, t) && (texelFetch(uDiscFlags, eyeAtlas(uLevel, q), 0).r & GIS_EYE_FLAG_DISCONTINUOUS) != 0u;
}

void main() {
    ivec2 a = ivec2(gl_FragCoord.xy);
    ivec2 t = a - gEye.level[uLevel].xy;
    uint own = texelFetch(uDiscFlags, a, 0).r;
    bool covered = (own & GIS_EYE_FLAG_COVERED) != 0u;
    bool diagonal = discontinuous(t + ivec2(1, 1)) || discontinuous(t + ivec2(-1, 1)) ||
                    discontinuous(t + ivec2(1, -1)) || discontinuous(t + ivec2(-1, -1));
    bool refine = covered && ((own & GIS_EYE_FLAG_DISCONTINUOUS) != 0u ||
                              ((gEye.info.w & GIS_EYE_DIAGONAL) != 0 && diagonal));
    bool coarsest = uLevel + 1 >= eyeLevelCount();
    uint parent = texelFetch(uFlags, eyeAtlas(min(uLevel + 1, eyeLevelCount() - 1), coarsest ? ivec2(0) : t >> 1), 0).r;
    bool subdivided = refine && (coarsest || (parent & GIS_EYE_FLAG_SUBDIVIDED) != 0u);
    outFlags = (covered ? GIS_EYE_FLAG_COVERED : 0u) | (refine ? GIS_EYE_FLAG_REFINE : 0u) |
               (subdivided ? GIS_EYE_FLAG_SUBDIVIDED : 0u);
}
