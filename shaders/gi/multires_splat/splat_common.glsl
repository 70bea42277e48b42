// What one VPL sends to one eye patch in multires_splat.
//   geometry refinement (diffuse): irradiance E; albedo / pi is applied per pixel after upsampling.
//   per-VPL refinement: outgoing radiance f_r * E towards the eye, f_r a normalised Phong BRDF
//     (1 - ks) albedo / pi + ks (e + 2) / (2 pi) max(<R, V>, 0)^e with R the VPL direction mirrored
//     about the normal: energy conserving for ks in [0, 1]; ks = 0 is Lambertian.
//   per-VPL refinement with glossy transport on (uGlossy, docs/nondiffuse.md): the materials'
//     reflection model instead (render/brdf.glsl; the patch's centre pixel's material), plus the
//     VPL's own specular lobe (gi/common/vpl_glossy.glsl), so 000's illumination-driven refinement
//     follows the glossy highlights.
#include "gi/common/vpl_transport.glsl"
#include "render/brdf.glsl"

layout(std430, binding = 0) readonly buffer VplBuffer {
    Vpl gVpls[];
};

uniform float uMinDistance; // m, point kernel only
uniform int uPerVpl;        // 1: radiance with the Phong BRDF; 0: irradiance
uniform float uPhongKs;     // [0, 1]
uniform float uPhongExponent;
layout(binding = 14) uniform sampler2D uPatchSpecular; // the G-buffer's gSpecular (rgb F0, a roughness)
#include "gi/common/vpl_glossy.glsl"

vec3 phongBrdf(vec3 albedo, vec3 n, vec3 toVpl, vec3 toEye) {
    vec3 r = reflect(-toVpl, n);
    float c = max(dot(r, toEye), 0.0);
    float lobe = c > 0.0 ? pow(c, uPhongExponent) : 0.0;
    return (1.0 - uPhongKs) * albedo * kInvPi + vec3(uPhongKs * (uPhongExponent + 2.0) * 0.5 * kInvPi * lobe);
}

vec3 splatContribution(uint index, EyePatch p) {
    Vpl v = gVpls[index];
    vec3 e = vplIrradianceSelected(p.position, p.normal, v, uMinDistance);
    if (uPerVpl == 0) return e;
    vec3 toVpl = v.position.xyz - p.position;
    vec3 toEye = gFrame.cameraPos.xyz - p.position;
    float lv = dot(toVpl, toVpl), le = dot(toEye, toEye);
    if (!(lv > 1e-20) || !(le > 1e-20)) return vec3(0.0);
    vec3 wo = toEye * inversesqrt(le);
    if (uGlossy == 1) {
        vec4 spec = texelFetch(uPatchSpecular, p.pixel, 0);
        vec3 eExtra = vec3(0.0), lGlossy = vec3(0.0);
        vplGlossyAccumulate(v, gVplGlossy[index], e, 1.0, uMinDistance, p.position, p.normal, wo, spec,
                            glossyLobe(spec), eExtra, lGlossy);
        return p.albedo * kInvPi * (e + eExtra) + lGlossy;
    }
    return e * phongBrdf(p.albedo, p.normal, toVpl * inversesqrt(lv), wo);
}
