#version 450 core
// Full-resolution gather (digest S.3 preset rsm_naive, receivers R0): every covered pixel sums the
// irradiance of every VPL in the current batch. Batches are accumulated with additive blending.
// A VPL part (refinement, FrameInputs::vplPart) is one draw over the whole buffer instead: the VPLs
// uVplPhase, uVplPhase + uVplStride, ... read from the storage block, their sum scaled by uVplStride
// so that the mean of all uVplStride parts is the whole set's light.
// With glossy transport on (uGlossy), each VPL's specular lobe and the pixel's are added
// (gi/common/vpl_glossy.glsl).
#include "common.glsl"
#include "gi/common/vpl_transport.glsl"
#define GIS_VPL_SHADOW_LOOKUP 1
#include "gi/common/vpl_shadow.glsl"
#include "render/brdf.glsl"
#include "gi/common/vpl_glossy.glsl"

layout(binding = 0) uniform sampler2D gPosition;
layout(binding = 1) uniform sampler2D gNormal;
layout(binding = 2) uniform sampler2D gAlbedo;
layout(binding = 3) uniform sampler2D gSpecular; // rgb F0, a roughness

layout(std140, binding = GIS_UBO_VPLS) uniform VplBlock {
    Vpl gVpls[GIS_MAX_VPLS_PER_BATCH];
};

layout(std430, binding = GIS_SSBO_VPLS) readonly buffer VplAll {
    Vpl gAllVpls[];
};

uniform int uVplCount;       // VPLs in this batch (a part: in the buffer)
uniform int uVplFirst;       // index of the batch's first VPL (its shadow map layers); a part: 0
uniform int uVplPhase;       // a part: its first VPL; else 0
uniform int uVplStride;      // a part: the number of parts (> 1); else 1
uniform float uMinDistance;  // m, point kernel only

// VPL `i` of the whole set (uVplFirst <= i < uVplFirst + uVplCount).
Vpl vplAt(int i) { return uVplStride > 1 ? gAllVpls[i] : gVpls[i - uVplFirst]; }

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
        for (int i = uVplFirst + uVplPhase; i < uVplFirst + uVplCount; i += uVplStride) {
            Vpl v = vplAt(i);
            e += vplIrradianceSelected(pos.xyz, n, v, uMinDistance) * vplVisibility(i, v.position.xyz, pos.xyz, n);
        }
        outRadiance = vec4(max(sanitize(albedo * kInvPi * e * float(uVplStride)), vec3(0.0)), 1.0);
        return;
    }
    vec4 spec = texelFetch(gSpecular, px, 0);
    bool glossyReceiver = glossyLobe(spec);
    vec3 toEye = gFrame.cameraPos.xyz - pos.xyz;
    float e2 = dot(toEye, toEye);
    vec3 wo = e2 > 1e-20 ? toEye * inversesqrt(e2) : n;
    vec3 eExtra = vec3(0.0), lGlossy = vec3(0.0);
    for (int i = uVplFirst + uVplPhase; i < uVplFirst + uVplCount; i += uVplStride) {
        Vpl v = vplAt(i);
        float vis = vplVisibility(i, v.position.xyz, pos.xyz, n);
        vec3 ei = vplIrradianceSelected(pos.xyz, n, v, uMinDistance) * vis;
        e += ei;
        vplGlossyAccumulate(v, gVplGlossy[i], ei, vis, uMinDistance, pos.xyz, n, wo, spec, glossyReceiver,
                            eExtra, lGlossy);
    }
    vec3 l = (albedo * kInvPi * (e + eExtra) + lGlossy) * float(uVplStride);
    outRadiance = vec4(max(sanitize(l), vec3(0.0)), 1.0);
}
