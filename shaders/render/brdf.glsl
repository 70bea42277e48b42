// The reflection model of scene/Brdf.h, term for term (the reference renderer evaluates that file;
// docs/nondiffuse.md). A surface is (rho_d, F0, roughness); F90 follows from F0, so a surface with
// F0 = 0 is exactly Lambertian. Vectors are unit length: n normal, wi towards the light, wo towards
// the viewer. Back-facing or grazing pairs reflect exactly 0; every division is guarded.
#ifndef GIS_BRDF_GLSL
#define GIS_BRDF_GLSL

const float kMinAlpha = 2e-3;          // GGX alpha floor: roughness 0 is a 0.1 degree lobe, not a delta
const float kMaxPhongExponent = 1e4;   // e = 2/alpha^2 - 2 at the floor would be 5e5

#define GIS_LOBE_GGX 0
#define GIS_LOBE_PHONG 1

float brdfF90(vec3 f0) { return clamp(50.0 * 0.33 * (f0.r + f0.g + f0.b), 0.0, 1.0); }
float brdfAlpha(float roughness) {
    float r = clamp(roughness, 0.0, 1.0);
    return max(r * r, kMinAlpha);
}
bool brdfHasSpecular(vec3 f0) { return brdfF90(f0) > 0.0; }

vec3 brdfFresnel(vec3 f0, float cosTheta) {
    float c = clamp(cosTheta, 0.0, 1.0);
    float k = (1.0 - c) * (1.0 - c) * (1.0 - c) * (1.0 - c) * (1.0 - c);
    return f0 + (vec3(brdfF90(f0)) - f0) * k;
}

float ggxD(float nh, float alpha) {
    float a2 = alpha * alpha;
    float t = nh * nh * (a2 - 1.0) + 1.0;
    return a2 / max(kPi * t * t, 1e-30);
}

float ggxV(float nl, float nv, float alpha) {
    float a2 = alpha * alpha;
    float gv = nl * sqrt(max(nv * nv * (1.0 - a2) + a2, 0.0));
    float gl = nv * sqrt(max(nl * nl * (1.0 - a2) + a2, 0.0));
    return 0.5 / max(gv + gl, 1e-30);
}

float phongExponent(float alpha) { return clamp(2.0 / max(alpha * alpha, 1e-12) - 2.0, 0.0, kMaxPhongExponent); }

// The specular part of f (1/sr) for a surface with reflectance f0 and perceptual roughness.
vec3 brdfSpecular(vec3 f0, float roughness, int lobe, vec3 n, vec3 wi, vec3 wo) {
    if (!brdfHasSpecular(f0)) return vec3(0.0);
    float nl = dot(n, wi), nv = dot(n, wo);
    if (!(nl > 0.0) || !(nv > 0.0)) return vec3(0.0);
    vec3 h = wi + wo;
    float hl = dot(h, h);
    if (!(hl > 1e-20)) return vec3(0.0);
    h *= inversesqrt(hl);
    vec3 f = brdfFresnel(f0, dot(wo, h));
    float alpha = brdfAlpha(roughness);
    if (lobe == GIS_LOBE_GGX) return f * (ggxD(max(dot(n, h), 0.0), alpha) * ggxV(nl, nv, alpha));
    float e = phongExponent(alpha);
    vec3 r = 2.0 * nl * n - wi;
    float c = max(dot(r, wo), 0.0);
    return f * ((e + 2.0) * 0.5 * kInvPi * (c > 0.0 ? pow(c, e) : 0.0));
}

#endif
