#version 450 core
// Refinement flags for every texel of every level (000 §3 step 5's ContainsDepth/NormalDiscontinuity,
// evaluated once per texel so both the iterative refinement and the one-pass stencil read the same
// decision). A patch is discontinuous when it is partly background, or its depth or normal statistics
// exceed the thresholds; with the diagonal rule (000 §5.2) a discontinuous diagonal neighbour on the
// same level also forces refinement. Level 0 never refines (one pixel).
#include "gi/common/eye_hierarchy.glsl"


layout(binding = 0) uniform sampler2D uGeoPosition;
layout(binding = 3) uniform sampler2D uDepthInfo;
layout(binding = 4) uniform sampler2D uNormalMin;
layout(binding = 5) uniform sampler2D uNormalMax;

layout(location = 6) out uint outFlags; // drawn over the level column (level 0 never refines)

bool discontinuity(int level, ivec2 t) {
    if (level == 0 || !eyeInLevel(level, t)) return false;
    ivec2 a = eyeAtlas(level, t);
    float count = texelFetch(uGeoPosition, a, 0).w;
    if (count <= 0.0) return false;                          // empty: nothing to refine
    if (count < eyeFootprintPixels(level, t)) return true;   // object / background edge
    vec4 di = texelFetch(uDepthInfo, a, 0);
    int options = gEye.info.w;
    bool depthDisc = (options & GIS_EYE_DEPTH_DERIVATIVE) != 0 ? di.z > gEye.thresholds.y
                                                              : (di.y - di.x) > gEye.thresholds.x * max(di.x, 1e-6);
    bool normalDisc;
    if ((options & GIS_EYE_CURVATURE) != 0) {
        normalDisc = di.w > gEye.thresholds.w;
    } else {
        vec3 range = texelFetch(uNormalMax, a, 0).xyz - texelFetch(uNormalMin, a, 0).xyz;
        normalDisc = any(greaterThan(range, vec3(gEye.thresholds.z)));
    }
    return depthDisc || normalDisc;
}

void main() {
    ivec2 a = ivec2(gl_FragCoord.xy);
    ivec2 t;
    int level = eyeLevelOf(a, t);
    if (level < 0) {
        outFlags = 0u;
        return;
    }
    bool covered = texelFetch(uGeoPosition, a, 0).w > 0.0;
    bool refine = covered && discontinuity(level, t);
    if (covered && !refine && (gEye.info.w & GIS_EYE_DIAGONAL) != 0) {
        refine = discontinuity(level, t + ivec2(1, 1)) || discontinuity(level, t + ivec2(-1, 1)) ||
                 discontinuity(level, t + ivec2(1, -1)) || discontinuity(level, t + ivec2(-1, -1));
    }
    outFlags = (covered ? GIS_EYE_FLAG_COVERED : 0u) | (refine ? GIS_EYE_FLAG_REFINE : 0u);
}
