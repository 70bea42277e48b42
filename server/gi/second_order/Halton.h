// Deterministic low-discrepancy light placement for `second_order` (003 §3.1): Halton points on the
// unit sphere, rejection-sampled to a cone, and the solid angle of a view frustum. Pure functions,
// no GL, so tests can check them exactly.
//
// Convention (digest 003.1 ambiguity "j-th prime" vs "base j"): the usual Halton (2, 3) pair,
// u = radical inverse in base 2, v = radical inverse in base 3. Indices start at 1, because index 0
// gives u = v = 0, a point every Halton sequence shares (the cone's anti-pole).
//
// Sphere point i (003 §3.1): phi = 2 pi u, delta = asin(2 v - 1),
//   s = (sin phi cos delta, cos phi cos delta, sin delta),
// so z = sin(delta) = 2 v - 1 is uniform in [-1, 1] and the points are uniform in solid angle.
// The cone's axis is +z of a local frame: a point lies in a cone of half-angle theta iff
// z >= cos(theta), which depends on v alone, so rejected draws never compute u.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace gis::halton {

/// Draw cap of the rejection loop. A cone of half-angle theta accepts (1 - cos theta) / 2 of the
/// draws (digest 003.5 item 5): 2^20 draws yield 256 lights down to about 1.8 degrees, and about
/// 20 lights for a 0.5 degree cone (digest S.4 case 16), in some 10-30 ms of CPU time once per
/// change of the cone (callers cache the result).
constexpr std::uint32_t kMaxDraws = 1u << 20;

/// Phi_base(i): the base-`base` digits of i mirrored about the radix point. base >= 2.
inline double radicalInverse(std::uint32_t i, std::uint32_t base) {
    if (base < 2) return 0.0;
    const double inv = 1.0 / static_cast<double>(base);
    double scale = inv, result = 0.0;
    while (i > 0) {
        result += static_cast<double>(i % base) * scale;
        i /= base;
        scale *= inv;
    }
    return result;
}

/// 003 §3.1's sphere point for index i (local frame, unit length).
inline glm::dvec3 sphereDirection(std::uint32_t i) {
    const double pi = 3.14159265358979323846;
    const double phi = 2.0 * pi * radicalInverse(i, 2);
    const double z = std::clamp(2.0 * radicalInverse(i, 3) - 1.0, -1.0, 1.0);
    const double cosDelta = std::sqrt(std::max(1.0 - z * z, 0.0));
    return {std::sin(phi) * cosDelta, std::cos(phi) * cosDelta, z};
}

struct ConeSamples {
    std::vector<glm::vec3> directions; ///< local frame, axis +z, in Halton order
    std::uint32_t draws = 0;           ///< sphere points examined (indices 1..draws)
    bool capped = false;               ///< stopped at the draw cap before `count` were accepted
};

/// The first `count` Halton sphere points inside the cone z >= cosHalfAngle, examining at most
/// `maxDraws` points. cosHalfAngle <= -1 (a cone of 180 degrees or more) accepts every point; a
/// NaN cone accepts none.
inline ConeSamples sampleCone(double cosHalfAngle, int count, std::uint32_t maxDraws = kMaxDraws) {
    ConeSamples out;
    if (count <= 0) return out;
    out.directions.reserve(static_cast<size_t>(count));
    std::uint32_t i = 1;
    for (; i <= maxDraws && out.directions.size() < static_cast<size_t>(count); ++i) {
        const double z = 2.0 * radicalInverse(i, 3) - 1.0;
        if (!(z >= cosHalfAngle)) continue;
        out.directions.push_back(glm::vec3(sphereDirection(i)));
    }
    out.draws = i - 1;
    out.capped = out.directions.size() < static_cast<size_t>(count);
    return out;
}

/// Solid angle (sr) of the spherical triangle spanned by unit vectors a, b, c (Van Oosterom and
/// Strackee 1983): tan(Omega / 2) = |a . (b x c)| / (1 + a.b + b.c + c.a). atan2 keeps it finite for
/// every input, including degenerate triangles (0).
inline double triangleSolidAngle(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    const double num = std::abs(glm::dot(a, glm::cross(b, c)));
    const double den = 1.0 + glm::dot(a, b) + glm::dot(b, c) + glm::dot(c, a);
    const double omega = 2.0 * std::atan2(num, den);
    return std::isfinite(omega) ? omega : 0.0;
}

/// Solid angle (sr) of a convex view frustum given the unit directions through its four image
/// corners, in order around the image.
inline double frustumSolidAngle(const glm::dvec3 corners[4]) {
    return triangleSolidAngle(corners[0], corners[1], corners[2]) +
           triangleSolidAngle(corners[0], corners[2], corners[3]);
}

/// An orthonormal frame (right, up, axis) around a unit axis, continuous except where the axis
/// crosses +-y. Maps local cone samples (axis +z) to world directions.
struct Frame {
    glm::vec3 right{1, 0, 0}, up{0, 1, 0}, axis{0, 0, 1};
    glm::vec3 toWorld(glm::vec3 local) const { return local.x * right + local.y * up + local.z * axis; }
};

inline Frame frameAround(glm::vec3 axis) {
    Frame f;
    const float len2 = glm::dot(axis, axis);
    if (!(len2 > 1e-24f) || !std::isfinite(len2)) return f;
    f.axis = axis / std::sqrt(len2);
    const glm::vec3 helper = std::abs(f.axis.y) < 0.999f ? glm::vec3(0, 1, 0) : glm::vec3(0, 0, 1);
    f.right = glm::normalize(glm::cross(helper, f.axis)); // |helper x axis| >= sqrt(1 - 0.999^2)
    f.up = glm::cross(f.axis, f.right);
    return f;
}

} // namespace gis::halton
