#version 450 core
// Planar mirrors, glossy blur (004 §5.1.1, after Bastos et al.; mirror_blur=on): one separable
// Gaussian pass (uDirection (1,0) then (0,1)) over one mirrored view's pixels. The kernel's width
// follows the mirror's roughness and the distance from the mirror point to the reflected point: the
// reflected lobe's angular spread times that distance is the blur radius in metres at the reflected
// point, projected to pixels at the reflected point's (virtual) depth. Unlike Bastos et al.'s
// space-invariant kernel the width varies per pixel. Only pixels of the same view are gathered (no
// bleeding of non-mirror pixels in); each source pixel's kernel is normalised over the view's pixels it
// reaches (scatter normalisation), so the view's total radiance is kept.
#include "common.glsl"
#include "render/brdf.glsl"
#include "render/mirror_region.glsl"

layout(binding = 5) uniform sampler2D gSource;      // radiance to blur (RGBA32F)
layout(binding = 6) uniform sampler2D gMirrorPos;   // the mirror points (parent view): xyz world (m), w = 1
layout(binding = 7) uniform sampler2D gReflectPos;  // the reflected points (this view): xyz world (m), w = 1

uniform ivec2 uDirection;       // (1, 0) or (0, 1)
uniform float uRoughness;       // the mirror's perceptual roughness
uniform mat4 uViewProjChain;    // this view's world -> eye-image clip transform
uniform float uMaxSigmaPx;      // px: this view's widest kernel (PlanarMirrors.cpp bounds it on the CPU)

// Angular standard deviation of the reflected lobe per unit GGX alpha (radians): GGX's half-vector
// density falls to half at tan(theta_h) = 0.64 alpha, the reflected direction turns by twice that,
// and a Gaussian with that half width at half maximum has sigma = 1.1 alpha.
const float kLobeSigmaPerAlpha = 1.1;
const float kMaxLobeSigma = 1.2;  // radians: tan() stays finite
const float kMaxSigmaPx = 8.0;    // px: caps the kernel (3 sigma = 24 taps each side)
const float kMinSigmaPx = 0.25;   // px: below this the pass copies the pixel

layout(location = 0) out vec4 outRadiance;

float sigmaPixels(ivec2 px) {
    vec4 m = texelFetch(gMirrorPos, px, 0);
    vec4 r = texelFetch(gReflectPos, px, 0);
    if (m.w < 0.5) return 0.0;
    // Nothing reflected (the ray left the scene): the environment is infinitely far, the widest blur.
    if (r.w < 0.5) return brdfAlpha(uRoughness) > 0.02 ? uMaxSigmaPx : 0.0;
    float d = length(r.xyz - m.xyz); // m
    float angle = min(kLobeSigmaPerAlpha * brdfAlpha(uRoughness), kMaxLobeSigma);
    float radius = d * tan(angle); // m at the reflected point
    float w = (uViewProjChain * vec4(r.xyz, 1.0)).w; // virtual depth along the eye axis (m)
    vec3 row1 = vec3(gFrame.viewProj[0][1], gFrame.viewProj[1][1], gFrame.viewProj[2][1]);
    float pxPerMetre = 0.5 * gFrame.viewport.y * length(row1) / max(w, 1e-4);
    float s = radius * pxPerMetre;
    return s >= 0.0 ? min(s, min(uMaxSigmaPx, kMaxSigmaPx)) : 0.0; // also maps NaN to 0
}

// Sum of the kernel exp(-k^2 / (2 sigma^2)) over the taps k that land inside the view: dividing a
// source pixel's share by it makes the pass scatter-normalised, so the view's total radiance is kept
// exactly (a plain gather with a per-pixel width is not energy conserving).
float footprintSum(ivec2 src, float sigma, ivec2 size) {
    int taps = int(ceil(3.0 * sigma));
    float inv2s2 = 0.5 / (sigma * sigma);
    float z = 1.0; // k = 0: the source itself is in the view
    for (int k = -taps; k <= taps; ++k) {
        if (k == 0) continue;
        ivec2 q = src + uDirection * k;
        if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size)) || !inRegion(q)) continue;
        z += exp(-float(k * k) * inv2s2);
    }
    return z;
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    if (!inRegion(px)) discard;
    ivec2 size = ivec2(gFrame.viewport.xy);
    // Gather the sources whose kernel reaches this pixel; each kernel is at most 3 uMaxSigmaPx wide.
    int reach = int(ceil(3.0 * clamp(uMaxSigmaPx, 0.0, kMaxSigmaPx)));
    vec3 sum = vec3(0.0);
    for (int i = -reach; i <= reach; ++i) {
        ivec2 q = px + uDirection * i;
        if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size)) || !inRegion(q)) continue;
        float sigma = sigmaPixels(q);
        vec3 l = max(sanitize(texelFetch(gSource, q, 0).rgb), vec3(0.0));
        if (!(sigma >= kMinSigmaPx)) {
            if (i == 0) sum += l; // a sharp source keeps its radiance
            continue;
        }
        if (float(abs(i)) > ceil(3.0 * sigma)) continue;
        float w = exp(-float(i * i) * (0.5 / (sigma * sigma)));
        sum += l * (w / footprintSum(q, sigma, size)); // footprintSum >= 1
    }
    outRadiance = vec4(sum, 1.0);
}
