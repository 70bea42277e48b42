#version 450 core
// 003 §3.5's discontinuity buffer: a covered pixel needs the full-resolution fix-up when any low-res
// texel its bilinear upsampling would use (non-zero weight) is empty or differs from it by
// discontinuity() >= the threshold. Other fragments are discarded, so the stencil marks exactly the
// fix-up pixels and the pass's sample count is their number (no read-back of the buffer itself).
#include "common.glsl"
#include "gi/second_order/second_order.glsl"

layout(binding = 0) uniform sampler2D gPosition;
layout(binding = 1) uniform sampler2D gNormal;
layout(binding = 2) uniform sampler2D gLowPosition;
layout(binding = 3) uniform sampler2D gLowNormal;

uniform int uFactor;
uniform ivec2 uLowSize;
uniform float uThreshold;

layout(location = 0) out vec4 outFlag;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 pos = texelFetch(gPosition, px, 0);
    if (pos.w < 0.5) discard; // background: no indirect light at all
    vec3 n = texelFetch(gNormal, px, 0).xyz;
    ivec2 texel[4];
    float weight[4];
    lowResNeighbours(px, uFactor, uLowSize, texel, weight);
    bool flagged = false;
    for (int k = 0; k < 4; ++k) {
        if (!(weight[k] > 0.0)) continue;
        vec4 q = texelFetch(gLowPosition, texel[k], 0);
        vec3 nq = texelFetch(gLowNormal, texel[k], 0).xyz;
        // !(d < t) also flags a NaN difference, and threshold 0 flags every pixel (digest S.4 case 12).
        if (q.w < 0.5 || !(discontinuity(pos.xyz, n, q.xyz, nq) < uThreshold)) flagged = true;
    }
    if (!flagged) discard;
    outFlag = vec4(1.0);
}
