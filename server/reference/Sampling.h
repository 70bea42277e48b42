// Random numbers and direction sampling for the reference renderer.
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

} // namespace gis::reference
