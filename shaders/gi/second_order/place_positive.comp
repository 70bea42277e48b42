#version 450 core
// 003 §3.1: positive indirect lights at the RSM texels under one light's Halton points (one dispatch
// per light: the sphere for a point light, the cone for a spot, the lit square for a directional one).
//
// Flux: each accepted point stands for an equal share of the sampled measure (solid angle, or area
// perpendicular to a directional light), so the set is a quadrature of the reflected flux density
// J (W/sr, or W/m^2), which a texel gives as its flux divided by its own measure (rsmTexelMeasure,
// the convention rsm.frag used). Indirect light j gets
//     Phi_j = Phi_RSM * J_j / sum_k J_k        (per channel, over this light's points),
// which is J_j times measure / N with the estimate of the total replaced by the exact total of this
// light's RSM views: the set carries exactly each light's reflected flux (digest S.4 case 7), and
// points that miss a surface (sky, outside the RSM) or a capped sampler with few points lose none.
#include "common.glsl"
#include "gi/second_order/second_order.glsl"

layout(local_size_x = 256) in;

layout(binding = 0) uniform sampler2DArray gRsmPosition;
layout(binding = 1) uniform sampler2DArray gRsmNormal;
layout(binding = 2) uniform sampler2DArray gRsmFlux;

layout(std430, binding = 0) buffer VplOut {
    Vpl gVpls[];
};
layout(std430, binding = 1) readonly buffer Samples {
    vec4 gSamples[]; // xy: RSM image coordinates in [0, 1]; z: 1 when the point projects into the RSM; w: its view
};

uniform int uFirst;           // this light's first slot
uniform int uCount;           // this light's accepted points
uniform int uLight;           // the light
uniform int uRsmSize;         // texels per side of each view
uniform float uSampleMeasure; // sr per point (perspective views: disk area A = measure d^2), or m^2 per point (orthographic)

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
    int firstView = int(gLights.lights[uLight].info.z + 0.5);
    int views = int(gLights.lights[uLight].info.w + 0.5);

    vec3 rsmFlux = vec3(0.0);
    for (int i = int(tid); i < size * size * views; i += 256) {
        ivec3 t = ivec3(i % size, (i / size) % size, firstView + i / (size * size));
        if (texelFetch(gRsmPosition, t, 0).w >= 0.5)
            rsmFlux += max(sanitize(texelFetch(gRsmFlux, t, 0).rgb), 0.0);
    }
    rsmFlux = workgroupSum(rsmFlux);

    vec3 densitySum = vec3(0.0);
    float valid = 0.0;
    for (int j = int(tid); j < uCount; j += 256) {
        Vpl v;
        v.position = vec4(0.0);
        v.normal = vec4(0.0, 1.0, 0.0, 0.0);
        v.flux = vec4(0.0);
        vec4 s = gSamples[uFirst + j];
        if (s.z > 0.5) {
            int view = int(s.w + 0.5);
            ivec3 t = ivec3(clamp(ivec2(floor(s.xy * float(size))), ivec2(0), ivec2(size - 1)), view);
            vec4 p = texelFetch(gRsmPosition, t, 0);
            float measure = rsmTexelMeasure(view, vec2(t.xy) + 0.5);
            // A non-finite texel is skipped like an empty one (digest S.4 case 5).
            if (p.w >= 0.5 && measure > 0.0 && !any(isnan(p.xyz)) && !any(isinf(p.xyz))) {
                vec3 density = max(sanitize(texelFetch(gRsmFlux, t, 0).rgb / measure), 0.0);
                bool ortho = gLights.views[view].info.x > 0.5;
                float d = lightViewDistance(view, p.xyz);
                v.position = vec4(p.xyz, 1.0);
                float area = ortho ? uSampleMeasure : uSampleMeasure * d * d;
                vec3 n = texelFetch(gRsmNormal, t, 0).xyz;
                if (any(isnan(n)) || any(isinf(n))) n = directionToLight(uLight, p.xyz); // faces the light
                v.normal = vec4(n, area);
                v.flux = vec4(density, uSampleMeasure / measure); // w: texels this light stands for
                densitySum += density;
                valid += 1.0;
            }
        }
        gVpls[uFirst + j] = v;
    }
    vec3 sums = workgroupSum(vec3(valid, 0.0, 0.0));
    densitySum = workgroupSum(densitySum);

    vec3 scale = vec3(densitySum.r > 0.0 ? rsmFlux.r / densitySum.r : 0.0,
                      densitySum.g > 0.0 ? rsmFlux.g / densitySum.g : 0.0,
                      densitySum.b > 0.0 ? rsmFlux.b / densitySum.b : 0.0);
    for (int j = int(tid); j < uCount; j += 256)
        gVpls[uFirst + j].flux.rgb = sanitize(gVpls[uFirst + j].flux.rgb * scale);

    // Dispatches run in light order, each after the previous one's writes (barrier on the CPU side).
    if (tid == 0u) {
        gActiveVpls = uint(uFirst + uCount);
        gPositiveValid = (uFirst == 0 ? 0u : gPositiveValid) + uint(sums.x + 0.5);
        gNegativePlaced = 0u;
    }
}
