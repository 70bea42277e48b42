// Small vector helpers shared by the scene layer's loaders and finishing step. Every normalisation
// goes through safeNormalize so zero-length or non-finite input never turns into NaN output.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

namespace gis {

inline bool isFinite(float v) {
    return std::isfinite(v);
}
inline bool isFinite(const glm::vec2& v) {
    return std::isfinite(v.x) && std::isfinite(v.y);
}
inline bool isFinite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
inline bool isFinite(const glm::vec4& v) {
    return isFinite(glm::vec3(v)) && std::isfinite(v.w);
}

/// v / |v|, or fallback when v is (nearly) zero or not finite.
inline glm::vec3 safeNormalize(const glm::vec3& v, const glm::vec3& fallback) {
    const float len2 = glm::dot(v, v);
    if (!std::isfinite(len2) || len2 <= 1e-30f) return fallback;
    return v / std::sqrt(len2);
}

/// Cross product of the edges: twice the triangle's area times its CCW unit normal.
inline glm::vec3 areaNormal(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    return glm::cross(b - a, c - a);
}

} // namespace gis
