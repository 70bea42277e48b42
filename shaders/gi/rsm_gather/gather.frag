#version 450 core
// Full-resolution gather (digest S.3 preset rsm_naive, receivers R0): every covered pixel sums the
// irradiance of every VPL in the current batch. Batches are accumulated with additive blending.
// A VPL part (refinement, FrameInputs::vplPart) gathers the batches of its own VPLs (every
// uVplStride-th of the set, from uVplPhase on, laid out contiguously by vpl_interleave.comp), its
// light scaled by uVplStride so that the mean of all parts is the whole set's.
// With glossy transport on (uGlossy), each VPL's specular lobe and the pixel's are added
// (gi/common/vpl_glossy.glsl).
#include "common.glsl"
#include "gi/common/vpl_transport.glsl"
#include "gi/common/vpl_batch.glsl"
// VPL visibility is a program of its own (GIS_VPL_SHADOWED, RsmGather): llvmpipe runs both sides of
// a branch even on a uniform, and the lookup behind `uVplShadows` cost 195 of the gather's 441 ms
// with the shadows off (cornell, 512^2, 256 VPLs; docs/multires.md).
#ifndef GIS_VPL_SHADOWED
#define GIS_VPL_SHADOWED 1
#endif
#if GIS_VPL_SHADOWED
#define GIS_VPL_SHADOW_LOOKUP 1
#endif
#include "gi/common/vpl_shadow.glsl"
#if !GIS_VPL_SHADOWED
float vplVisibility(int index, vec3 vplPos, vec3 receiverPos, vec3 receiverNormal) { return 1.0; }
#endif
#include "render/brdf.glsl"
#include "gi/common/vpl_glossy.glsl"

layout(binding = 0) uniform sampler2D gPosition;
layout(binding = 1) uniform sampler2D gNormal;
layout(binding = 2) uniform sampler2D gAlbedo;
layout(binding = 3) uniform sampler2D gSpecular; // rgb F0, a roughness

uniform int uVplCount;       // VPLs in this batch
uniform int uVplFirst;       // index of the batch's first VPL (in its part's sequence)
uniform int uVplPhase;       // the part (0 without parts)
uniform int uVplStride = 1;  // the number of parts (1 without parts, and when not set)
uniform float uMinDistance;  // m, point kernel only

// The set's index of the batch's VPL i: its shadow map layers and glossy data.
int setIndex(int i) { return uVplPhase + (uVplFirst + i) * uVplStride; }

// The batch's VPL i at a receiver, through its visibility.
vec3 shadedIrradiance(vec3 receiverPos, vec3 receiverNormal, int i) {
    Vpl v = batchVpl(i);
    return vplIrradianceSelected(receiverPos, receiverNormal, v, uMinDistance) *
           vplVisibility(setIndex(i), v.position.xyz, receiverPos, receiverNormal);
}

layout(location = 0) out vec4 outRadiance;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 pos = texelFetch(gPosition, px, 0);
    if (pos.w < 0.5) { // background receives exactly 0 (digest S.4 case 4)
        outRadiance = vec4(0.0);
        return;
    }
    vec3 n = texelFetch(gNormal, px, 0).xyz;
    vec3 e = vec3(0.0);
    vec3 albedo = texelFetch(gAlbedo, px, 0).rgb;
    if (uGlossy == 0) {
#define SHADED_TERM(i) shadedIrradiance(pos.xyz, n, i)
        GIS_SUM_OVER_BATCH(e, uVplCount, SHADED_TERM)
        outRadiance = vec4(max(sanitize(albedo * kInvPi * e * float(uVplStride)), vec3(0.0)), 1.0);
        return;
    }
    vec4 spec = texelFetch(gSpecular, px, 0);
    bool glossyReceiver = glossyLobe(spec);
    vec3 toEye = gFrame.cameraPos.xyz - pos.xyz;
    float e2 = dot(toEye, toEye);
    vec3 wo = e2 > 1e-20 ? toEye * inversesqrt(e2) : n;
    vec3 eExtra = vec3(0.0), lGlossy = vec3(0.0);
    for (int i = 0; i < uVplCount; ++i) {
        Vpl v = batchVpl(i);
        float vis = vplVisibility(setIndex(i), v.position.xyz, pos.xyz, n);
        vec3 ei = vplIrradianceSelected(pos.xyz, n, v, uMinDistance) * vis;
        e += ei;
        vplGlossyAccumulate(v, gVplGlossy[setIndex(i)], ei, vis, uMinDistance, pos.xyz, n, wo, spec, glossyReceiver,
                            eExtra, lGlossy);
    }
    vec3 l = (albedo * kInvPi * (e + eExtra) + lGlossy) * float(uVplStride);
    outRadiance = vec4(max(sanitize(l), vec3(0.0)), 1.0);
}
