#version 450 core
// One-pass stencil refinement (001 §3.2.1): one full-screen pass over the flattened multiresolution
// buffer keeps (stencil = 1) exactly the fragments that receive light, and counts them per level.
// Everything else (padding, background, refined patches, patches under a coarser receiver) is
// discarded and keeps stencil 0, so the gather's early stencil test skips it.
#include "common.glsl"
#include "gi/common/eye_hierarchy.glsl"
#include "gi/common/eye_pixel.glsl"

layout(binding = 6) uniform usampler2D uFlags;

layout(std430, binding = 1) buffer ReceiverCounts {
    uint gReceiverCount[GIS_MAX_EYE_LEVELS];
};

void main() {
    ivec2 t;
    int level = eyeLevelOf(ivec2(gl_FragCoord.xy), t);
    if (level < 0 || !eyeIsReceiver(uFlags, level, t, level == 0 && eyePixelCovered(t))) discard;
    atomicAdd(gReceiverCount[level], 1u);
}
