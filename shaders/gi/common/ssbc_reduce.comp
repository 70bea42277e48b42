#version 450 core
// One coarser SSBC mip level (002 §4.2 "hierarchical G-buffer"): summed area, area-weighted means of
// position, normal and illumination, and the discontinuity flag. uMode 0 builds geometry and
// illumination (once per frame), 1 only the illumination (every later step).
// A patch spans a discontinuity (002's discontinuity buffer, as in Nichols et al.) when a child
// does, when it mixes covered and empty pixels of the image, or when a child's mean normal or eye
// distance departs from the patch's: chord |n_c - n| > 0.3 (about 17 degrees) or relative distance
// > 0.1. These mirror the eye hierarchy's defaults (normal 0.25 range, depth 0.1 relative).
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(rgba32f, binding = 0) uniform readonly image2D uGeoIn;
layout(rgba32f, binding = 1) uniform writeonly image2D uGeoOut;
layout(rgba32f, binding = 2) uniform readonly image2D uNormalIn;
layout(rgba32f, binding = 3) uniform writeonly image2D uNormalOut;
layout(rgba32f, binding = 4) uniform readonly image2D uIllumIn;
layout(rgba32f, binding = 5) uniform writeonly image2D uIllumOut;

uniform int uLevel;      // the level written (>= 1)
uniform int uMode;       // 0 geometry + illumination, 1 illumination only
uniform ivec2 uOutSize;  // texels of the level written
uniform ivec2 uChildReal; // image extent of the child level: ceil(W / 2^(l-1)) x ceil(H / 2^(l-1))

const float kNormalChord = 0.3;
const float kRelativeDepth = 0.1;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(t, uOutSize))) return;
    float area = 0.0;
    vec3 pos = vec3(0.0), nrm = vec3(0.0), illum = vec3(0.0), firstNormal = vec3(0.0, 0.0, 1.0);
    bool disc = false, empty = false;
    vec4 g[4];
    vec4 n[4];
    for (int k = 0; k < 4; ++k) {
        ivec2 c = 2 * t + ivec2(k & 1, k >> 1);
        g[k] = imageLoad(uGeoIn, c);
        float a = g[k].w > 0.0 && !isBad(g[k].w) ? g[k].w : 0.0;
        g[k].w = a;
        if (uMode == 0) n[k] = imageLoad(uNormalIn, c);
        if (a <= 0.0) {
            if (all(lessThan(c, uChildReal))) empty = true;
            continue;
        }
        if (area == 0.0 && uMode == 0) firstNormal = n[k].xyz;
        area += a;
        illum += a * max(sanitize(imageLoad(uIllumIn, c).rgb), vec3(0.0));
        if (uMode == 0) {
            pos += a * g[k].xyz;
            nrm += a * n[k].xyz;
            disc = disc || n[k].w > 0.5;
        }
    }
    float inv = area > 0.0 ? 1.0 / area : 0.0;
    imageStore(uIllumOut, t, vec4(max(sanitize(illum * inv), vec3(0.0)), area > 0.0 ? 1.0 : 0.0));
    if (uMode != 0) return;
    pos *= inv;
    float len = length(nrm);
    // Opposing normals can cancel: keep a child's normal rather than normalising ~0.
    vec3 nMean = len > 1e-6 * max(area, 1e-30) && len > 0.0 ? nrm / len : firstNormal;
    float dMean = length(pos - gFrame.cameraPos.xyz);
    if (area > 0.0) {
        disc = disc || empty;
        for (int k = 0; k < 4; ++k) {
            if (g[k].w <= 0.0) continue;
            float dk = length(g[k].xyz - gFrame.cameraPos.xyz);
            disc = disc || length(n[k].xyz - nMean) > kNormalChord ||
                   abs(dk - dMean) > kRelativeDepth * max(dMean, 1e-6);
        }
    }
    imageStore(uGeoOut, t, area > 0.0 ? vec4(sanitize(pos), area) : vec4(0.0));
    imageStore(uNormalOut, t, area > 0.0 ? vec4(sanitize(nMean), disc ? 1.0 : 0.0) : vec4(0.0));
}
