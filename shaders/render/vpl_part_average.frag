#version 450 core
// The running mean of refinement's VPL parts (FrameState::VplPart): part k (0-based) enters with
// weight 1/(k+1) through the blend (SRC_ALPHA, ONE_MINUS_SRC_ALPHA), so after part k the target
// holds the mean of parts 0..k; part 0's weight of 1 replaces whatever the target held.
#include "common.glsl"

layout(binding = 0) uniform sampler2D gPart; // one part's indirect radiance, scaled to the whole set
uniform float uWeight;                       // 1 / (k + 1), in (0, 1]

layout(location = 0) out vec4 outMean;

void main() {
    outMean = vec4(max(sanitize(texelFetch(gPart, ivec2(gl_FragCoord.xy), 0).rgb), vec3(0.0)), uWeight);
}
