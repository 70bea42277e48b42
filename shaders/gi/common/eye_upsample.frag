#version 450 core
// Coarse-to-fine reconstruction of the multiresolution illumination buffer (000 §3.5, digest S.3 U1),
// one level per draw from the coarsest down to level 1 (eye_resolve.frag does level 0 in the
// same way while writing the final radiance). A texel that received light on its own
// level keeps its value unchanged (so thresholds of 0 reproduce the full-resolution result exactly).
// A texel under a coarser receiver interpolates the finished coarser level (eyeInterpolateCoarse).
#include "gi/common/eye_hierarchy.glsl"


layout(binding = 0) uniform sampler2D uRendered;      // splat/gather result, alpha 1 at receivers
layout(binding = 1) uniform sampler2D uReconstructed; // the render target itself: level+1 is read,
                                                      // this level written (glTextureBarrier between)
layout(location = 0) out vec4 outReconstructed;

uniform int uLevel;

void main() {
    ivec2 a = ivec2(gl_FragCoord.xy);
    ivec2 t = a - gEye.level[uLevel].xy;
    vec4 rendered = texelFetch(uRendered, a, 0);
    if (rendered.a > 0.0) {
        outReconstructed = vec4(rendered.rgb, 1.0);
        return;
    }
    vec4 result = eyeInterpolateCoarse(uReconstructed, uLevel + 1, t);
    outReconstructed = result;
}
