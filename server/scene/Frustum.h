// The six clip planes of a world -> clip-space matrix, for culling draws that GL would clip whole.
// GL-free: the draw loop (render/SceneGpu) and its tests use it.
#pragma once

#include <array>

#include <glm/glm.hpp>

namespace gis {

class Frustum {
public:
    /// The planes of `clip` (OpenGL conventions, -w <= x, y, z <= w), each as (n, d) with n.p + d >= 0
    /// inside. A point with w <= 0 fails at least one of them, so geometry wholly behind a
    /// perspective eye is outside too.
    explicit Frustum(const glm::mat4& clip) {
        const glm::vec4 r0(clip[0][0], clip[1][0], clip[2][0], clip[3][0]);
        const glm::vec4 r1(clip[0][1], clip[1][1], clip[2][1], clip[3][1]);
        const glm::vec4 r2(clip[0][2], clip[1][2], clip[2][2], clip[3][2]);
        const glm::vec4 r3(clip[0][3], clip[1][3], clip[2][3], clip[3][3]);
        mPlanes = {r3 + r0, r3 - r0, r3 + r1, r3 - r1, r3 + r2, r3 - r2};
    }

    /// True when the box [lo, hi] lies wholly on the outer side of one plane: every point of it would
    /// be clipped. Conservative (a box that straddles the frustum's corners can be kept, never the
    /// reverse); a non-finite matrix or box is never culled.
    bool outside(const glm::vec3& lo, const glm::vec3& hi) const {
        for (const glm::vec4& p : mPlanes) {
            // The box corner farthest along the plane's normal.
            const glm::vec3 far(p.x >= 0.0f ? hi.x : lo.x, p.y >= 0.0f ? hi.y : lo.y,
                                p.z >= 0.0f ? hi.z : lo.z);
            const float distance = p.x * far.x + p.y * far.y + p.z * far.z + p.w;
            if (distance < 0.0f) return true; // NaN compares false: kept
        }
        return false;
    }

private:
    std::array<glm::vec4, 6> mPlanes;
};

} // namespace gis
