#version 450 core
// 003 §3.1: positive indirect lights at the RSM texels under the Halton cone points.
//
// Flux: each accepted point stands for an equal share of the cone's solid angle, so the set is a
// quadrature of the reflected radiant intensity J (W/sr), which a texel gives as its flux divided by
// its own solid angle (rsmTexelSolidAngle, the convention rsm.frag used). Light j gets
//     Phi_j = Phi_RSM * J_j / sum_k J_k        (per channel),
// which is J_j times Omega_cone / N with the estimate of the total replaced by the exact total: the
// set carries exactly the RSM's reflected flux (digest S.4 case 7), and points that miss a surface
// (sky, outside the RSM frustum) or a capped sampler with few points lose none of it.
#include "common.glsl"
#include "gi/second_order/second_order.glsl"

layout(local_size_x = 256) in;

layout(binding = 0) uniform sampler2D gRsmPosition;
layout(binding = 1) uniform sampler2D gRsmNormal;
layout(binding = 2) uniform sampler2D gRsmFlux;

layout(std430, binding = 0) buffer VplOut {
    Vpl gVpls[];
};
layout(std430, binding = 1) readonly buffer Samples {
    vec4 gSamples[]; // xy: RSM image coordinates in [0, 1]; z: 1 when the point projects into the RSM
};

uniform int uCount;              // accepted cone points
uniform int uRsmSize;            // texels per side
uniform float uSampleSolidAngle; // sr per point (Omega_cone / uCount): the disk area A = omega d^2

shared vec3 sSum[256];

vec3 workgroupSum(vec3 v) {
    uint tid = gl_LocalInvocationID.x;
    sSum[tid] = v;
    memoryBarrierShared();
    barrier();
    for (uint stride = 128u; stride > 0u; stride >>= 1u) {
        if (tid < stride) sSum[tid] += sSum[tid + stride];
        memoryBarrierShared();
        barrier();
    }
    vec3 total = sSum[0];
    barrier(); // sSum is reused by the next call
    return total;
}

void main() {
    uint tid = gl_LocalInvocationID.x;
    int size = max(uRsmSize, 1);

    vec3 rsmFlux = vec3(0.0);
    for (int i = int(tid); i < size * size; i += 256) {
        ivec2 t = ivec2(i % size, i / size);
        if (texelFetch(gRsmPosition, t, 0).w >= 0.5)
            rsmFlux += max(sanitize(texelFetch(gRsmFlux, t, 0).rgb), 0.0);
    }
    rsmFlux = workgroupSum(rsmFlux);

    vec3 intensitySum = vec3(0.0);
    float valid = 0.0;
    for (int j = int(tid); j < uCount; j += 256) {
        Vpl v;
        v.position = vec4(0.0);
        v.normal = vec4(0.0, 1.0, 0.0, 0.0);
        v.flux = vec4(0.0);
        vec4 s = gSamples[j];
        if (s.z > 0.5) {
            ivec2 t = clamp(ivec2(floor(s.xy * float(size))), ivec2(0), ivec2(size - 1));
            vec4 p = texelFetch(gRsmPosition, t, 0);
            float omega = rsmTexelSolidAngle(vec2(t) + 0.5);
            // A non-finite texel is skipped like an empty one (digest S.4 case 5).
            if (p.w >= 0.5 && omega > 0.0 && !any(isnan(p.xyz)) && !any(isinf(p.xyz))) {
                vec3 intensity = max(sanitize(texelFetch(gRsmFlux, t, 0).rgb / omega), 0.0);
                vec3 toSurface = p.xyz - gFrame.lightPos.xyz;
                v.position = vec4(p.xyz, 1.0);
                float area = uSampleSolidAngle * dot(toSurface, toSurface);
                vec3 n = texelFetch(gRsmNormal, t, 0).xyz;
                if (any(isnan(n)) || any(isinf(n))) n = -normalize(toSurface); // faces the light
                v.normal = vec4(n, area);
                v.flux = vec4(intensity, uSampleSolidAngle / omega); // w: texels this light stands for
                intensitySum += intensity;
                valid += 1.0;
            }
        }
        gVpls[j] = v;
    }
    vec3 sums = workgroupSum(vec3(valid, 0.0, 0.0));
    intensitySum = workgroupSum(intensitySum);

    vec3 scale = vec3(intensitySum.r > 0.0 ? rsmFlux.r / intensitySum.r : 0.0,
                      intensitySum.g > 0.0 ? rsmFlux.g / intensitySum.g : 0.0,
                      intensitySum.b > 0.0 ? rsmFlux.b / intensitySum.b : 0.0);
    for (int j = int(tid); j < uCount; j += 256) gVpls[j].flux.rgb = sanitize(gVpls[j].flux.rgb * scale);

    if (tid == 0u) {
        gActiveVpls = uint(uCount);
        gPositiveValid = uint(sums.x + 0.5);
        gNegativePlaced = 0u;
    }
}
