#version 450 core
// Environment probe: the split-sum environment BRDF (Karis 2013), computed once. Texel (i, j) holds,
// for n.v = (i + 0.5) / N and roughness = (j + 0.5) / N, the directional albedo of the specular lobe
// split into the F0 and F90 parts of Schlick's Fresnel:
//     integral f_spec(l, v) (n.l) dl = F0 A + F90 B,  A = E[(1 - Fc) w], B = E[Fc w], Fc = (1 - v.h)^5
// rg: GGX (height-correlated Smith, render/brdf.glsl), importance-sampled by D(h)(n.h):
//     w = V(n.l, n.v) 4 (v.h) (n.l) / (n.h);
// ba: the normalised Phong lobe of the same alpha (e = 2 / alpha^2 - 2), sampled by cos^e about the
//     mirror direction: w = (e + 2) / (e + 1) (n.l).
// Samples below the horizon (n.l <= 0) contribute 0, like the BRDF itself.
#include "common.glsl"
#include "render/env_common.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) writeonly uniform image2D uLut;
uniform int uSize;    // N, texels per side
uniform int uSamples; // samples per texel

void main() {
    ivec2 id = ivec2(gl_GlobalInvocationID.xy);
    if (id.x >= uSize || id.y >= uSize) return;
    float nv = (float(id.x) + 0.5) / float(uSize);
    float roughness = (float(id.y) + 0.5) / float(uSize);
    float alpha = brdfAlpha(roughness);
    float e = phongExponent(alpha);
    vec3 v = vec3(sqrt(max(1.0 - nv * nv, 0.0)), 0.0, nv); // n = +z
    vec3 r = vec3(-v.x, 0.0, v.z);                         // mirror direction of v
    vec3 rt, rb;
    envFrame(r, rt, rb);
    uint count = uint(max(uSamples, 1));
    vec4 acc = vec4(0.0);
    for (uint i = 0u; i < count; ++i) {
        vec2 u = envHammersley(i, count);
        // GGX
        vec3 h = envSampleGgx(u, alpha);
        vec3 l = 2.0 * dot(v, h) * h - v;
        float nl = l.z, nh = h.z, vh = dot(v, h);
        if (nl > 0.0 && nh > 0.0 && vh > 0.0) {
            float w = ggxV(nl, nv, alpha) * 4.0 * vh * nl / nh;
            float fc = pow(1.0 - clamp(vh, 0.0, 1.0), 5.0);
            acc.xy += vec2(1.0 - fc, fc) * w;
        }
        // Phong
        vec3 lp = envSamplePhong(u, e);
        l = rt * lp.x + rb * lp.y + r * lp.z;
        nl = l.z;
        if (nl > 0.0) {
            vec3 hp = l + v;
            float hl = dot(hp, hp);
            float c = hl > 1e-20 ? clamp(dot(v, hp) * inversesqrt(hl), 0.0, 1.0) : 0.0;
            float fc = pow(1.0 - c, 5.0);
            float w = (e + 2.0) / (e + 1.0) * nl;
            acc.zw += vec2(1.0 - fc, fc) * w;
        }
    }
    imageStore(uLut, id, max(acc / float(count), vec4(0.0)));
}
