#version 450 core
// Environment probe, step 2 (004 §2.2.2): one level of the prefiltered cube. Every texel is the
// lobe-weighted mean of the source cube over the specular lobe of roughness uRoughness, under the
// split-sum assumption n = v = r (the lobe is centred on the texel's direction), with uSamples
// Hammersley importance samples. Filtered importance sampling (Colbert & Krivanek 2007; Karis 2013):
// each sample reads the box-filtered source mip whose texel solid angle matches the solid angle the
// sample stands for, 1 / (uSamples pdf), so few samples give a smooth, solid-angle-weighted integral
// instead of aliasing. Weights are n.l (Karis). Output sanitised, non-negative.
#include "common.glsl"
#include "render/env_common.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform samplerCube uSource;          // radiance cube, full mip chain
layout(rgba16f, binding = 0) writeonly uniform imageCube uDest; // this level, all six faces

uniform int uSize;            // this level's face size (texels)
uniform float uRoughness;     // perceptual roughness of this level, (0, 1]
uniform int uSamples;         // env_samples, >= 1
uniform int uLobe;            // GIS_LOBE_GGX or GIS_LOBE_PHONG
uniform float uTexelSolidAngle; // solid angle of one source level-0 texel, 4 pi / (6 size0^2) (sr)
uniform float uMaxSourceLod;  // the source's last mip level

void main() {
    ivec3 id = ivec3(gl_GlobalInvocationID);
    if (id.x >= uSize || id.y >= uSize || id.z >= 6) return;
    vec3 n = envCubeDirection(id.xy, id.z, uSize);
    vec3 t, b;
    envFrame(n, t, b);
    float alpha = brdfAlpha(uRoughness);
    float e = phongExponent(alpha);
    uint count = uint(max(uSamples, 1));
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (uint i = 0u; i < count; ++i) {
        vec2 u = envHammersley(i, count);
        vec3 l;
        float pdf; // over directions l (1/sr)
        if (uLobe == GIS_LOBE_GGX) {
            vec3 hl = envSampleGgx(u, alpha);
            vec3 h = t * hl.x + b * hl.y + n * hl.z;
            l = 2.0 * dot(n, h) * h - n;
            // pdf_l = D(h) (n.h) / (4 v.h) with v = n: D(h) / 4.
            pdf = ggxD(hl.z, alpha) * 0.25;
        } else {
            vec3 ll = envSamplePhong(u, e);
            l = t * ll.x + b * ll.y + n * ll.z;
            pdf = (e + 1.0) * 0.5 * kInvPi * pow(max(ll.z, 0.0), e);
        }
        float nl = dot(n, l);
        if (!(nl > 0.0)) continue;
        // Solid angle per sample (sr) over the source texel's: log2 of the ratio is twice the mip
        // offset; +1 biases towards the smoother mip (Karis). pdf floored at 1e-6 /sr.
        float omegaS = 1.0 / (float(count) * max(pdf, 1e-6));
        float lod = clamp(0.5 * log2(max(omegaS / max(uTexelSolidAngle, 1e-12), 1e-12)) + 1.0, 0.0, uMaxSourceLod);
        sum += max(sanitize(textureLod(uSource, l, lod).rgb), vec3(0.0)) * nl;
        weight += nl;
    }
    vec3 c = weight > 0.0 ? sum / weight : max(sanitize(textureLod(uSource, n, 0.0).rgb), vec3(0.0));
    imageStore(uDest, id, vec4(max(sanitize(c), vec3(0.0)), 1.0));
}
