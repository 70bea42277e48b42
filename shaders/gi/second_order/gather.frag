#version 450 core
// Signed irradiance at each receiver (low-res texel or fix-up pixel) from one batch of lights: the
// positive lights (K1) and the negative lights, which are K1 lights of negative flux. Batches are
// accumulated with additive blending; albedo is applied at full resolution in resolve.frag.
#include "common.glsl"
#include "gi/common/vpl_transport.glsl"
#include "gi/common/vpl_batch.glsl"
#define SO_STATS_ACCESS readonly
#include "gi/second_order/second_order.glsl"

layout(binding = 0) uniform sampler2D gPosition;
layout(binding = 1) uniform sampler2D gNormal;

uniform int uVplCount;      // slots in this batch
uniform int uBatchFirst;    // index of the batch's first slot
uniform float uMinDistance; // m

layout(location = 0) out vec4 outIrradiance;

// The batch's light i (K1; a negative light's flux is negative) at a receiver.
vec3 lightIrradiance(vec3 receiverPos, vec3 receiverNormal, int i) {
    Vpl v = batchVpl(i);
    return vplIrradiance(receiverPos, receiverNormal, v.position.xyz, v.normal.xyz, v.flux.rgb, uMinDistance) *
           v.position.w;
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 pos = texelFetch(gPosition, px, 0);
    if (pos.w < 0.5) { // background receives exactly 0 (digest S.4 case 4)
        outIrradiance = vec4(0.0);
        return;
    }
    vec3 n = texelFetch(gNormal, px, 0).xyz;
    // Slots past the lights actually placed hold nothing: skip them.
    int count = clamp(int(gActiveVpls) - uBatchFirst, 0, uVplCount);
    vec3 e = vec3(0.0);
#define LIGHT_TERM(i) lightIrradiance(pos.xyz, n, i)
    GIS_SUM_OVER_BATCH(e, count, LIGHT_TERM)
    outIrradiance = vec4(sanitize(e), 1.0);
}
