#version 450 core
// One-pass stencil refinement (001 §3.2.1): one full-screen pass over the flattened multiresolution
// buffer keeps (stencil = 1) exactly the fragments that receive light. Everything else (padding,
// background, refined patches, patches under a coarser receiver) is discarded and keeps stencil 0,
// so the gather's early stencil test skips it. Drawn once per level (the viewport covers level
// uLevel only, so no fragment searches for its level); the host counts each level's receivers with
// an occlusion query (discarded fragments do not count), which costs llvmpipe nothing per fragment
// where a per-fragment atomic counter did. With GIS_EYE_RECEIVER_LIST each receiver also appends its
// texel to the receiver list (eye_receiver_list.glsl) for the gathers' compute passes: the atomic
// runs for the receivers only, a few per cent of the fragments.
#include "common.glsl"
#include "gi/common/eye_hierarchy.glsl"
#include "gi/common/eye_pixel.glsl"

layout(binding = 6) uniform usampler2D uFlags;

uniform int uLevel;

// Level 0 (the G-buffer's pixels) and the coarser levels are programs of their own: llvmpipe would
// run the pixel coverage test for every patch and the patch flag fetch for every pixel.
#ifndef GIS_EYE_PIXEL_LEVEL
#define GIS_EYE_PIXEL_LEVEL 0
#endif
#ifndef GIS_EYE_RECEIVER_LIST
#define GIS_EYE_RECEIVER_LIST 0
#endif
#if GIS_EYE_RECEIVER_LIST
#include "gi/common/eye_receiver_list.glsl"
#endif

void main() {
#if GIS_EYE_PIXEL_LEVEL
    ivec2 t = ivec2(gl_FragCoord.xy) - gEye.level[0].xy;
    if (!eyeIsReceiver(uFlags, 0, t, eyePixelCovered(t))) discard;
#else
    ivec2 t = ivec2(gl_FragCoord.xy) - gEye.level[uLevel].xy;
    if (!eyeIsReceiver(uFlags, uLevel, t, false)) discard;
#endif
#if GIS_EYE_RECEIVER_LIST
    eyeAppendReceiver(ivec2(gl_FragCoord.xy));
#endif
}
