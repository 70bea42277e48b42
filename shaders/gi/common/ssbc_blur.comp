#version 450 core
// SSBC edge-preserving blur (002 §4.4, ssbc_blur) of the summed compensation only, against the
// blocky look of coarse hierarchical samples. 5x5 cross-bilateral kernel: a spatial Gaussian
// (sigma 1.5 px) times the edge weight of ssbc_common.glsl; only covered pixels (area > 0) take part,
// so nothing flows across background pixels or depth and normal edges.
// Energy: the kernel is normalised per source pixel (scatter normalisation): pass 0 divides each
// pixel's compensation by the total weight W_q it sends to its neighbours (itself included, so
// W_q >= 1), pass 1 gathers sum_q w_pq C_q / W_q. The weights are symmetric, so each pixel hands out
// exactly its own compensation: the blur conserves the image's compensation energy (to rounding).
#include "common.glsl"
#include "gi/common/ssbc_common.glsl"

layout(local_size_x = GIS_SSBC_GROUP, local_size_y = GIS_SSBC_GROUP) in;

layout(binding = 0) uniform sampler2D uGeo;    // level 0: xyz position, w area (0: not a receiver)
layout(binding = 1) uniform sampler2D uNormal; // level 0: xyz unit normal
layout(binding = 2) uniform sampler2D uSource; // pass 0: summed compensation; pass 1: C / W

layout(rgba32f, binding = 0) uniform image2D uOut; // pass 0: C / W; pass 1: the indirect radiance (+=)

uniform int uPass;

const int kRadius = 2;
const float kSigma = 1.5;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(gFrame.viewport.xy);
    if (any(greaterThanEqual(p, size))) return;
    vec4 self = texelFetch(uGeo, p, 0);
    if (!(self.w > 0.0)) {
        if (uPass == 0) imageStore(uOut, p, vec4(0.0));
        return;
    }
    vec3 np = texelFetch(uNormal, p, 0).xyz;
    vec3 eye = gFrame.cameraPos.xyz;
    float wsum = 0.0;
    vec3 sum = vec3(0.0);
    for (int dy = -kRadius; dy <= kRadius; ++dy)
        for (int dx = -kRadius; dx <= kRadius; ++dx) {
            ivec2 q = p + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            vec4 g = texelFetch(uGeo, q, 0);
            if (!(g.w > 0.0)) continue;
            float w = exp(-float(dx * dx + dy * dy) / (2.0 * kSigma * kSigma)) *
                      ssbcEdgeWeight(self.xyz, np, g.xyz, texelFetch(uNormal, q, 0).xyz, eye);
            wsum += w;
            if (uPass == 1) sum += w * max(sanitize(texelFetch(uSource, q, 0).rgb), vec3(0.0));
        }
    if (uPass == 0) {
        // The centre term has weight 1, so wsum >= 1; the guard only protects against NaN geometry.
        vec3 c = max(sanitize(texelFetch(uSource, p, 0).rgb), vec3(0.0));
        imageStore(uOut, p, vec4(wsum >= 1.0 ? c / wsum : c, 1.0));
    } else {
        vec4 current = imageLoad(uOut, p);
        imageStore(uOut, p, vec4(max(sanitize(current.rgb), vec3(0.0)) + max(sanitize(sum), vec3(0.0)), current.a));
    }
}
