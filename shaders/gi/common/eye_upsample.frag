#version 450 core
// Coarse-to-fine reconstruction of the multiresolution illumination buffer (000 §3.5, digest S.3 U1),
// one level per draw from the coarsest down to level 1 (eye_resolve.frag does level 0 in the same
// way while writing the final radiance). See eyeCombine.
#include "common.glsl"
#include "gi/common/eye_hierarchy.glsl"


layout(binding = 0) uniform sampler2D uRendered;      // splat/gather result, alpha 1 at receivers
layout(binding = 1) uniform sampler2D uReconstructed; // the render target itself: level+1 is read,
                                                      // this level written (glTextureBarrier between)
layout(binding = 11) uniform sampler2D uAtlasPosition; // xyz mean position (m); w covered pixels
layout(binding = 12) uniform sampler2D uAtlasNormal;   // xyz mean unit normal
uniform int uInterpolate; // 0: replicate the parent (per-VPL lists)
layout(location = 0) out vec4 outReconstructed;

uniform int uLevel;

void main() {
    ivec2 a = ivec2(gl_FragCoord.xy);
    EyeGeometry fine;
    fine.position = texelFetch(uAtlasPosition, a, 0);
    fine.normal = texelFetch(uAtlasNormal, a, 0).xyz;
    outReconstructed = eyeCombine(texelFetch(uRendered, a, 0), uReconstructed, uAtlasPosition, uAtlasNormal, uLevel,
                                  a - gEye.level[uLevel].xy, uInterpolate != 0, fine);
}
