#version 450 core
// Environment probe, step 3 (004 §2.2.1): the reflected environment of smooth specular eye pixels,
// added (blend ONE, ONE) to the reflections target. Split sum (Karis 2013):
//     L = prefiltered(r, roughness) (F0 A + F90 B),  r = reflect(-v, n),
// A, B from the environment-BRDF table (env_brdf_lut.comp: rg for GGX, ba for Phong). Opaque
// surfaces: Schlick's Fresnel of render/brdf.glsl, no transmitted / total-internal-reflection term.
// Back-facing pairs (n.v <= 0, grazing or an interpolated normal turned away) reflect exactly 0,
// like brdfSpecular. With uParallax, r is first intersected with the scene's bounding box and the
// cube is read towards the hit point from the probe (parallax correction).
#include "common.glsl"
#include "render/brdf.glsl"

layout(binding = 0) uniform sampler2D gPosition;  // RGBA32F, w = 1 covered
layout(binding = 1) uniform sampler2D gNormal;    // xyz unit normal, w = mirror index + 1
layout(binding = 2) uniform sampler2D gSpecular;  // rgb F0, a roughness
layout(binding = 3) uniform samplerCube uEnv;     // prefiltered radiance, level k = roughness k / uMaxLod
layout(binding = 5) uniform sampler2D uEnvBrdf;   // rg: GGX (A, B); ba: Phong (A, B)
// Local probes (render/Reflections EnvObject): pixels whose G-buffer id is -(k + 1) read probe k,
// rendered at their object's centre without the object. Three explicit samplers: GLSL 4.5 allows
// only dynamically uniform indices into sampler arrays.
layout(binding = 6) uniform samplerCube uLocal0;
layout(binding = 7) uniform samplerCube uLocal1;
layout(binding = 8) uniform samplerCube uLocal2;
uniform vec3 uLocalProbe[3]; // local probe centres (m)
uniform int uLocalCount;     // local probes in use, 0..3

uniform vec3 uProbe;         // probe centre (m)
uniform vec3 uBoxMin;        // scene bounds (m)
uniform vec3 uBoxMax;
uniform int uParallax;       // 1: box parallax correction
uniform float uMaxRoughness; // ReflectionInputs::envMaxRoughness
uniform float uMaxLod;       // last prefiltered level
uniform int uSkipMirrors;    // 1: planar-mirror pixels are the mirror pass's

layout(location = 0) out vec4 outRadiance;

// The lookup direction for a ray from p along unit r: towards the ray's exit from the box, seen
// from the probe. Falls back to r when p is outside the box or the hit coincides with the probe.
vec3 parallaxDirection(vec3 p, vec3 r, vec3 probe) {
    if (any(lessThan(p, uBoxMin - 1e-4)) || any(greaterThan(p, uBoxMax + 1e-4))) return r;
    // Per-axis exit distance (m); an axis the ray does not move along never exits (1e30).
    vec3 tExit;
    for (int i = 0; i < 3; ++i) {
        float d = r[i];
        if (abs(d) < 1e-8) tExit[i] = 1e30;
        else tExit[i] = ((d > 0.0 ? uBoxMax[i] : uBoxMin[i]) - p[i]) / d;
    }
    float t = max(min(tExit.x, min(tExit.y, tExit.z)), 0.0);
    if (!(t < 1e29)) return r;
    vec3 dir = p + r * t - probe;
    float len2 = dot(dir, dir);
    return len2 > 1e-12 ? dir * inversesqrt(len2) : r;
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    outRadiance = vec4(0.0);
    vec4 pos = texelFetch(gPosition, px, 0);
    if (pos.w < 0.5) return;
    vec4 nrm = texelFetch(gNormal, px, 0);
    if (uSkipMirrors == 1 && nrm.w > 0.5) return;
    // -(k + 1): the object of local probe k.
    int local = nrm.w < -0.5 ? int(-nrm.w + 0.5) - 1 : -1;
    if (local >= uLocalCount) local = -1;
    vec4 spec = texelFetch(gSpecular, px, 0);
    vec3 f0 = clamp(sanitize(spec.rgb), 0.0, 1.0);
    float roughness = clamp(isBad(spec.a) ? 1.0 : spec.a, 0.0, 1.0);
    if (!brdfHasSpecular(f0) || !(roughness < uMaxRoughness)) return;
    float n2 = dot(nrm.xyz, nrm.xyz);
    if (!(n2 > 1e-12) || isBad(n2)) return;
    vec3 n = nrm.xyz * inversesqrt(n2);
    vec3 toEye = gFrame.cameraPos.xyz - pos.xyz;
    float e2 = dot(toEye, toEye);
    if (!(e2 > 1e-20) || isBad(e2)) return;
    vec3 v = toEye * inversesqrt(e2);
    float nv = dot(n, v);
    if (!(nv > 0.0)) return; // back-facing or exactly grazing: the BRDF is 0 there
    vec3 r = 2.0 * nv * n - v; // unit: reflection of a unit vector about a unit normal
    vec3 probe = local < 0 ? uProbe : uLocalProbe[local];
    if (uParallax == 1) r = parallaxDirection(pos.xyz, r, probe);
    float lod = clamp(roughness, 0.0, 1.0) * uMaxLod;
    vec3 sampled;
    if (local == 0) sampled = textureLod(uLocal0, r, lod).rgb;
    else if (local == 1) sampled = textureLod(uLocal1, r, lod).rgb;
    else if (local == 2) sampled = textureLod(uLocal2, r, lod).rgb;
    else sampled = textureLod(uEnv, r, lod).rgb;
    vec3 env = max(sanitize(sampled), vec3(0.0));
    // Table texel centres cover n.v and roughness in [0.5/N, 1 - 0.5/N]; the sampler clamps beyond.
    vec4 ab = texture(uEnvBrdf, vec2(clamp(nv, 0.0, 1.0), roughness));
    vec2 lobe = int(gFrame.shadingInfo.x) == GIS_LOBE_PHONG ? ab.ba : ab.rg;
    vec3 albedo = f0 * lobe.x + vec3(brdfF90(f0) * lobe.y);
    outRadiance = vec4(max(sanitize(env * albedo), vec3(0.0)), 0.0);
}
