// The one surface-reflection model the GL pipeline (shaders/render/brdf.glsl) and the CPU reference
// renderer share, so an error between them measures the technique, not a model mismatch
// (docs/nondiffuse.md). From a glTF metallic-roughness material:
//
//   base   baseColor (x texture), metal = metallic, r = roughness, s = specular (KHR_materials_specular)
//   F0     = mix(0.04 s, base, metal)                reflectance at normal incidence, per channel
//   F90    = clamp(50 * 0.33 * (F0.r + F0.g + F0.b)) grazing reflectance; 0 when F0 = 0, so a surface
//                                                   without specular (s = 0, metal = 0) is exactly
//                                                   Lambertian (Filament's specular-occlusion rule)
//   F(c)   = F0 + (F90 - F0) (1 - c)^5              Schlick, c = cos(view, half vector)
//   rho_d  = base (1 - metal) (1 - Favg)            diffuse albedo; Favg = F0 + (F90 - F0) / 21 is
//                                                   Schlick's hemispherical mean, which keeps the
//                                                   diffuse weight direction-independent (one value
//                                                   in the G-buffer and the RSM; reciprocal)
//   alpha  = max(r^2, kMinAlpha)                    GGX width; the floor keeps D finite for mirrors
//
//   f(wi, wo) = rho_d / pi + F(wo.h) D(h) V(wi, wo)
//     ggx:   D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2), V = height-correlated Smith / (4 n.wi n.wo)
//     phong: the energy-conserving (modified) Phong lobe 000 uses, (e + 2) / (2 pi) max(r_wi . wo, 0)^e
//            (004 Eq. 4 without its 1/cos, which 004 calls not physically valid), with
//            e = 2 / alpha^2 - 2 (the usual GGX-to-Phong width match), clamped to [0, kMaxPhongExponent]
//
// Every division is guarded: back-facing or grazing pairs (n.wi or n.wo <= 0) reflect exactly 0.
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "scene/Scene.h"

namespace gis::brdf {

inline constexpr float kPi = 3.14159265358979f;
inline constexpr float kInvPi = 0.31830988618379f;
/// GGX alpha floor (dimensionless): roughness 0 becomes alpha 2e-3, a lobe about 0.1 degree wide.
inline constexpr float kMinAlpha = 2e-3f;
/// Phong exponent ceiling: e = 2/alpha^2 - 2 at the alpha floor would be 5e5.
inline constexpr float kMaxPhongExponent = 1e4f;

enum class Lobe { Ggx, Phong };

struct Surface {
    glm::vec3 diffuse{0.0f}; ///< rho_d, in [0, 1]
    glm::vec3 f0{0.0f};      ///< in [0, 1]
    float f90 = 0.0f;        ///< in [0, 1]
    float alpha = 1.0f;      ///< in [kMinAlpha, 1]
    bool hasSpecular() const { return f90 > 0.0f; }
};

inline float f90From(const glm::vec3& f0) {
    return std::clamp(50.0f * 0.33f * (f0.r + f0.g + f0.b), 0.0f, 1.0f);
}

inline float alphaFrom(float roughness) {
    const float r = std::clamp(roughness, 0.0f, 1.0f);
    return std::max(r * r, kMinAlpha);
}

/// The shading inputs of a material at one point whose base colour (factor x texture) is `base`.
inline Surface surfaceFrom(const glm::vec3& base, float metallic, float roughness, float specular) {
    const float metal = std::clamp(metallic, 0.0f, 1.0f);
    const glm::vec3 b = glm::clamp(base, 0.0f, 1.0f);
    Surface s;
    s.f0 = glm::mix(glm::vec3(0.04f * std::clamp(specular, 0.0f, 1.0f)), b, metal);
    s.f90 = f90From(s.f0);
    const glm::vec3 favg = s.f0 + (glm::vec3(s.f90) - s.f0) * (1.0f / 21.0f);
    s.diffuse = b * (1.0f - metal) * (glm::vec3(1.0f) - favg);
    s.alpha = alphaFrom(roughness);
    return s;
}

inline Surface surfaceFrom(const Material& m, const glm::vec3& base) {
    return surfaceFrom(base, m.metallic, m.roughness, m.specular);
}

inline glm::vec3 fresnel(const Surface& s, float cosTheta) {
    const float c = std::clamp(cosTheta, 0.0f, 1.0f);
    const float k = (1.0f - c) * (1.0f - c) * (1.0f - c) * (1.0f - c) * (1.0f - c);
    return s.f0 + (glm::vec3(s.f90) - s.f0) * k;
}

inline float ggxD(float nh, float alpha) {
    const float a2 = alpha * alpha;
    const float t = nh * nh * (a2 - 1.0f) + 1.0f;
    return a2 / std::max(kPi * t * t, 1e-30f);
}

/// Height-correlated Smith visibility G2 / (4 n.l n.v) for GGX.
inline float ggxV(float nl, float nv, float alpha) {
    const float a2 = alpha * alpha;
    const float gv = nl * std::sqrt(std::max(nv * nv * (1.0f - a2) + a2, 0.0f));
    const float gl = nv * std::sqrt(std::max(nl * nl * (1.0f - a2) + a2, 0.0f));
    return 0.5f / std::max(gv + gl, 1e-30f);
}

inline float phongExponent(float alpha) {
    return std::clamp(2.0f / std::max(alpha * alpha, 1e-12f) - 2.0f, 0.0f, kMaxPhongExponent);
}

/// The specular part of f (1/sr), for unit vectors: n the normal, wi towards the light, wo towards
/// the viewer.
inline glm::vec3 specular(const Surface& s, Lobe lobe, const glm::vec3& n, const glm::vec3& wi,
                          const glm::vec3& wo) {
    if (!s.hasSpecular()) return glm::vec3(0.0f);
    const float nl = glm::dot(n, wi), nv = glm::dot(n, wo);
    if (!(nl > 0.0f) || !(nv > 0.0f)) return glm::vec3(0.0f);
    glm::vec3 h = wi + wo;
    const float hl = glm::dot(h, h);
    if (!(hl > 1e-20f)) return glm::vec3(0.0f);
    h /= std::sqrt(hl);
    const glm::vec3 f = fresnel(s, glm::dot(wo, h));
    if (lobe == Lobe::Ggx) return f * (ggxD(std::max(glm::dot(n, h), 0.0f), s.alpha) * ggxV(nl, nv, s.alpha));
    const float e = phongExponent(s.alpha);
    const glm::vec3 r = 2.0f * nl * n - wi;
    const float c = std::max(glm::dot(r, wo), 0.0f);
    return f * ((e + 2.0f) * 0.5f * kInvPi * (c > 0.0f ? std::pow(c, e) : 0.0f));
}

/// The whole f(wi, wo) (1/sr).
inline glm::vec3 evaluate(const Surface& s, Lobe lobe, const glm::vec3& n, const glm::vec3& wi,
                          const glm::vec3& wo) {
    if (!(glm::dot(n, wi) > 0.0f) || !(glm::dot(n, wo) > 0.0f)) return glm::vec3(0.0f);
    return s.diffuse * kInvPi + specular(s, lobe, n, wi, wo);
}

} // namespace gis::brdf
