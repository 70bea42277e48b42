// Declarations the second_order passes share.

// Per-frame counts, cleared by the CPU before vpl_place. A pass that only reads them defines
// SO_STATS_ACCESS readonly first, so the block gives it no side effects (early stencil stays on).
#ifndef SO_STATS_ACCESS
#define SO_STATS_ACCESS
#endif
layout(std430, binding = 2) SO_STATS_ACCESS buffer SecondOrderStats {
    uint gActiveVpls;     // positive slots + negative lights placed: the gathers' loop bound
    uint gClampedPixels;  // resolve: pixels where direct + indirect - negative < 0 was clamped
    uint gNegativePlaced; // negative lights placed this frame
    uint gPositiveValid;  // positive lights that found a surface in the RSM
};

// Rec. 709 luminance: the scalar weight of an RGB irradiance.
const vec3 kLuma = vec3(0.2126, 0.7152, 0.0722);

// The 2x2 low-res texels whose bilinear interpolation covers full-res pixel `px` (texel centres at
// (q + 0.5) * factor in full-res pixels), clamped to the low-res image, and their weights (sum 1).
void lowResNeighbours(ivec2 px, int factor, ivec2 lowSize, out ivec2 texel[4], out float weight[4]) {
    vec2 lp = (vec2(px) + 0.5) / float(max(factor, 1)) - 0.5;
    vec2 base = floor(lp);
    vec2 f = lp - base;
    ivec2 b = ivec2(base);
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        texel[k] = clamp(b + o, ivec2(0), max(lowSize - 1, ivec2(0)));
        weight[k] = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
    }
}

// 003 §3.5's "difference" between a full-res point (x, n) and a low-res point (xq, nq), chosen
// dimensionless so one threshold serves both: the normal term 1 - n.nq (0 to 2), and the distance
// of xq from x's tangent plane relative to x's distance from the eye (0 on any plane, however
// grazing; large across depth edges). Returns a value >= 0, or NaN when an input was bad.
float discontinuity(vec3 x, vec3 n, vec3 xq, vec3 nq) {
    float eyeDistance = length(gFrame.cameraPos.xyz - x);
    float plane = abs(dot(n, xq - x)) / max(eyeDistance, 1e-6);
    return max(1.0 - dot(n, nq), plane);
}
