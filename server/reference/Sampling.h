// Random numbers and direction sampling for the reference renderer: cosine-weighted hemispheres for
// Lambertian surfaces and importance sampling of the whole reflection model of scene/Brdf.h (diffuse
// lobe + GGX or Phong specular lobe) for the others.
//
// Determinism: every (seed, pixel, sample) triple gets its own generator state, derived by hashing, so
// the image does not depend on how pixels are spread over threads or in which order samples run.
// The generator is PCG32 (O'Neill 2014, "PCG: a family of simple fast space-efficient statistically
// good algorithms for random number generation", XSH-RR output); states are derived with the
// SplitMix64 finaliser (Steele et al. 2014).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "scene/Brdf.h"

namespace gis::reference {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;

inline std::uint64_t mix64(std::uint64_t z) {
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

class Rng {
public:
    Rng(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample) {
        const std::uint64_t key = mix64(mix64(seed) ^ mix64(pixel * 0x100000001b3ull + 0x51ed27ull) ^ sample);
        mInc = (mix64(key ^ 0xda3e39cb94b95bdbull) << 1) | 1u; // stream selector must be odd
        mState = 0;
        next();
        mState += key;
        next();
    }

    std::uint32_t next() {
        const std::uint64_t old = mState;
        mState = old * 6364136223846793005ull + mInc;
        const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
        const auto rot = static_cast<std::uint32_t>(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
    }

    /// Uniform in [0, 1): 24 random bits, so the result is exactly representable and never 1.
    float uniform() { return static_cast<float>(next() >> 8) * (1.0f / 16777216.0f); }

private:
    std::uint64_t mState = 0;
    std::uint64_t mInc = 1;
};

/// Orthonormal basis around unit n (Duff et al. 2017, "Building an orthonormal basis, revisited").
inline void basisAround(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float c = n.x * n.y * a;
    t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
    b = glm::vec3(c, sign + n.y * n.y * a, -n.y);
}

/// Cosine-weighted direction around unit n (Malley's method: uniform disk, projected up);
/// pdf = cos(theta) / pi.
inline glm::vec3 sampleCosine(const glm::vec3& n, float u1, float u2) {
    const float r = std::sqrt(u1);
    const float phi = 2.0f * kPi * u2;
    const float x = r * std::cos(phi);
    const float y = r * std::sin(phi);
    const float z = std::sqrt(std::max(0.0f, 1.0f - u1));
    glm::vec3 t, b;
    basisAround(n, t, b);
    return x * t + y * b + z * n;
}

// ---- BRDF importance sampling (scene/Brdf.h) ------------------------------------------------------
//
// One sample picks a lobe with probability p_s (specular) or 1 - p_s (diffuse), samples a direction from
// it, and weighs the value by the COMBINED density pdf(wi) = (1 - p_s) pdf_d(wi) + p_s pdf_s(wi) (the
// one-sample balance heuristic, Veach 1997 §9.2.4): weight = f(wi, wo) (n.wi) / pdf(wi) with f the whole
// BRDF (diffuse + specular). Unbiased wherever pdf > 0 covers f > 0: the diffuse lobe covers the
// hemisphere when rho_d > 0, and both specular samplers cover it too (GGX D > 0 everywhere; Phong's
// cos^e lobe > 0 over the half space around the mirror direction, which holds its whole support).
//  - diffuse:  cosine-weighted, pdf_d = (n.wi) / pi
//  - GGX:      visible normals (Heitz 2018, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4)),
//              wi = reflect(-wo, h), pdf_s = D(h) G1(wo) / (4 n.wo) with Smith's GGX G1; the weight of a
//              pure specular sample is F G2/G1 <= 1, so even alpha at its 2e-3 floor (mirrors) converges
//              at the rate of the Fresnel term's variation
//  - Phong:    cos^e around the mirror direction r of wo, pdf_s = (e + 1) / (2 pi) max(wi.r, 0)^e
//              (Lafortune & Willems 1994); the weight of a pure specular sample is F (e + 2)/(e + 1) n.wi
//  - p_s = lum(F(n.wo)) / (lum(F(n.wo)) + lum(rho_d)): the lobes' estimated albedos (Schlick at the view
//    angle for the specular one); 0 without a specular lobe, 1 without a diffuse one.
// A sampled direction below the shading surface (possible for both specular samplers) has f = 0: the
// sample is lost, which is the single-scattering GGX's own energy loss, not the estimator's.

/// Rec. 709 luminance, the scalar the lobe-selection probability compares.
inline float luminance(const glm::vec3& c) {
    return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b;
}

/// Smith G1 of GGX for a direction at cosine c to the normal (dimensionless, in (0, 1]).
inline float ggxG1(float c, float alpha) {
    const float a2 = alpha * alpha;
    const float cc = std::max(c, 0.0f);
    const float den = cc + std::sqrt(std::max(a2 + (1.0f - a2) * cc * cc, 0.0f));
    return den > 1e-30f ? 2.0f * cc / den : 0.0f;
}

/// Probability of sampling the specular lobe (dimensionless, [0, 1]); nv = n.wo.
inline float specularPickProbability(const brdf::Surface& s, float nv) {
    if (!s.hasSpecular()) return 0.0f;
    const float spec = luminance(brdf::fresnel(s, nv));
    const float diff = luminance(s.diffuse);
    if (!(diff > 0.0f)) return 1.0f;
    const float p = spec / std::max(spec + diff, 1e-30f);
    return std::isfinite(p) ? std::clamp(p, 0.0f, 1.0f) : 0.5f;
}

/// GGX visible-normal half vector for unit n, unit wo with n.wo > 0 (Heitz 2018, listing 1).
inline glm::vec3 sampleGgxHalfVector(const glm::vec3& n, const glm::vec3& wo, float alpha, float u1,
                                     float u2) {
    glm::vec3 t, b;
    basisAround(n, t, b);
    const glm::vec3 ve(glm::dot(wo, t), glm::dot(wo, b), glm::dot(wo, n));
    // Stretch to the hemisphere configuration (alpha = 1).
    glm::vec3 vh(alpha * ve.x, alpha * ve.y, ve.z);
    const float vl = glm::dot(vh, vh);
    vh = vl > 1e-30f ? vh / std::sqrt(vl) : glm::vec3(0.0f, 0.0f, 1.0f);
    const float lensq = vh.x * vh.x + vh.y * vh.y;
    const glm::vec3 t1 =
        lensq > 1e-20f ? glm::vec3(-vh.y, vh.x, 0.0f) / std::sqrt(lensq) : glm::vec3(1.0f, 0.0f, 0.0f);
    const glm::vec3 t2 = glm::cross(vh, t1);
    const float r = std::sqrt(u1);
    const float phi = 2.0f * kPi * u2;
    const float p1 = r * std::cos(phi);
    float p2 = r * std::sin(phi);
    const float sHalf = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - sHalf) * std::sqrt(std::max(1.0f - p1 * p1, 0.0f)) + sHalf * p2;
    const glm::vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(1.0f - p1 * p1 - p2 * p2, 0.0f)) * vh;
    // Unstretch.
    glm::vec3 hl(alpha * nh.x, alpha * nh.y, std::max(nh.z, 0.0f));
    const float hl2 = glm::dot(hl, hl);
    hl = hl2 > 1e-30f ? hl / std::sqrt(hl2) : glm::vec3(0.0f, 0.0f, 1.0f);
    return hl.x * t + hl.y * b + hl.z * n;
}

/// Unit direction around unit axis `r` with density (e + 1) / (2 pi) cos^e (1/sr).
inline glm::vec3 samplePhongLobe(const glm::vec3& r, float e, float u1, float u2) {
    const float c = std::pow(u1, 1.0f / (e + 1.0f)); // u1 = 0 gives c = 0: the lobe's edge, still valid
    const float sn = std::sqrt(std::max((1.0f - c) * (1.0f + c), 0.0f));
    const float phi = 2.0f * kPi * u2;
    glm::vec3 t, b;
    basisAround(r, t, b);
    return sn * std::cos(phi) * t + sn * std::sin(phi) * b + c * r;
}

/// Density (1/sr) of the specular sampler alone at unit wi (0 where it cannot produce wi).
inline float specularPdf(const brdf::Surface& s, brdf::Lobe lobe, const glm::vec3& n, const glm::vec3& wi,
                         const glm::vec3& wo) {
    const float nv = glm::dot(n, wo);
    if (!(nv > 0.0f)) return 0.0f;
    if (lobe == brdf::Lobe::Phong) {
        const float e = brdf::phongExponent(s.alpha);
        const glm::vec3 r = 2.0f * nv * n - wo;
        const float c = glm::dot(wi, r);
        return c > 0.0f ? (e + 1.0f) * 0.5f * kInvPi * std::pow(c, e) : 0.0f;
    }
    // The half vector exactly as brdf::specular() forms it, so D cancels to rounding in f / pdf.
    glm::vec3 h = wi + wo;
    const float hl = glm::dot(h, h);
    if (!(hl > 1e-20f)) return 0.0f;
    h /= std::sqrt(hl);
    const float nh = glm::dot(n, h);
    if (!(nh > 0.0f)) return 0.0f;
    const float d = brdf::ggxD(nh, s.alpha);
    return d * ggxG1(nv, s.alpha) / (4.0f * nv); // nv > 0 checked above
}

/// The combined density (1/sr) of sampleBrdf() at unit wi.
inline float brdfPdf(const brdf::Surface& s, brdf::Lobe lobe, const glm::vec3& n, const glm::vec3& wi,
                     const glm::vec3& wo) {
    const float ps = specularPickProbability(s, glm::dot(n, wo));
    float pdf = 0.0f;
    if (ps < 1.0f) pdf += (1.0f - ps) * std::max(glm::dot(n, wi), 0.0f) * kInvPi;
    if (ps > 0.0f) pdf += ps * specularPdf(s, lobe, n, wi, wo);
    return pdf;
}

struct BrdfSample {
    glm::vec3 wi{0.0f};     ///< unit sampled direction (towards where the light comes from)
    glm::vec3 weight{0.0f}; ///< f(wi, wo) (n.wi) / pdf(wi), finite and >= 0; 0 when the sample is lost
    float pdf = 0.0f;       ///< combined density of wi (1/sr)
    bool specular = false;  ///< the specular lobe was picked
};

/// Samples the whole BRDF of `s` at unit shading normal n for unit wo (n.wo > 0), from three uniform
/// numbers in [0, 1). False when nothing was sampled (wo below the surface, a degenerate direction);
/// a sample whose f is 0 (wi below the surface) returns true with weight 0.
inline bool sampleBrdf(const brdf::Surface& s, brdf::Lobe lobe, const glm::vec3& n, const glm::vec3& wo,
                       float uPick, float u1, float u2, BrdfSample& out) {
    out = BrdfSample{};
    const float nv = glm::dot(n, wo);
    if (!(nv > 0.0f)) return false;
    const float ps = specularPickProbability(s, nv);
    glm::vec3 wi;
    if (uPick < ps) {
        out.specular = true;
        if (lobe == brdf::Lobe::Phong) {
            wi = samplePhongLobe(2.0f * nv * n - wo, brdf::phongExponent(s.alpha), u1, u2);
        } else {
            const glm::vec3 h = sampleGgxHalfVector(n, wo, s.alpha, u1, u2);
            wi = 2.0f * glm::dot(wo, h) * h - wo;
        }
    } else {
        wi = sampleCosine(n, u1, u2);
    }
    const float len2 = glm::dot(wi, wi);
    if (!(len2 > 1e-20f) || !std::isfinite(len2)) return false;
    wi /= std::sqrt(len2);
    out.wi = wi;
    const float nl = glm::dot(n, wi);
    if (!(nl > 0.0f)) return true; // below the surface: f = 0
    out.pdf = brdfPdf(s, lobe, n, wi, wo);
    // A density below 1e-30 / sr belongs to a direction the sampler (almost) never produces; dropping it
    // is a bias of at most that probability.
    if (!(out.pdf > 1e-30f) || !std::isfinite(out.pdf)) return true;
    const glm::vec3 w = brdf::evaluate(s, lobe, n, wi, wo) * (nl / out.pdf);
    for (int i = 0; i < 3; ++i) out.weight[i] = std::isfinite(w[i]) ? std::max(w[i], 0.0f) : 0.0f;
    return true;
}

} // namespace gis::reference
