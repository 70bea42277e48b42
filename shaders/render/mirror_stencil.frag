#version 450 core
// Planar mirrors, step 1 (004 §5.1, Diefenbach): marks one mirrored view's pixels in the stencil
// buffer (the pass sets stencil = the view's id with GL_REPLACE); every other pixel is discarded, so
// an occlusion query on this draw tells whether the view shows anything.
#include "render/mirror_region.glsl"

layout(location = 0) out vec4 outUnused; // no colour buffer is attached

void main() {
    if (!inRegion(ivec2(gl_FragCoord.xy))) discard;
    outUnused = vec4(0.0);
}
