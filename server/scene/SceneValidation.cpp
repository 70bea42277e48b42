#include "scene/SceneLoader.h"

#include <cmath>

#include "core/Error.h"
#include "scene/Geometry.h"

namespace gis {
namespace {

constexpr float kHalfPi = 1.5707964f; // rounded up so a float pi/2 from double passes
constexpr float kUnitTolerance = 1e-3f;

std::string label(const char* kind, const std::string& name, std::size_t index) {
    return std::string(kind) + " '" + name + "' (index " + std::to_string(index) + ")";
}

bool isUnit(const glm::vec3& v) {
    return isFinite(v) && std::abs(glm::length(v) - 1.0f) <= kUnitTolerance;
}

class Validator {
public:
    Validator(const Scene& scene, const std::string& where) : mScene(scene), mWhere(where) {}

    void run() const {
        if (mScene.meshes.empty()) fail("scene has no meshes");
        if (mScene.materials.empty()) fail("scene has no materials");
        if (mScene.cameras.empty()) fail("scene has no cameras");
        for (std::size_t i = 0; i < mScene.textures.size(); ++i) checkTexture(i);
        for (std::size_t i = 0; i < mScene.materials.size(); ++i) checkMaterial(i);
        for (std::size_t i = 0; i < mScene.meshes.size(); ++i) checkMesh(i);
        for (std::size_t i = 0; i < mScene.lights.size(); ++i) checkLight(i);
        for (std::size_t i = 0; i < mScene.cameras.size(); ++i) checkCamera(i);
    }

private:
    [[noreturn]] void fail(const std::string& message) const { throw InputError(mWhere, message); }

    void checkTexture(std::size_t i) const {
        const TextureImage& t = mScene.textures[i];
        const std::string what = label("texture", t.name, i);
        if (t.width <= 0 || t.height <= 0) fail(what + ": size must be positive");
        if (t.rgba.size() != static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height) * 4)
            fail(what + ": pixel data does not match " + std::to_string(t.width) + "x" +
                 std::to_string(t.height) + " RGBA8");
    }

    void checkMaterial(std::size_t i) const {
        const Material& m = mScene.materials[i];
        const std::string what = label("material", m.name, i);
        if (!isFinite(m.baseColor)) fail(what + ": base colour is not finite");
        if (!isFinite(m.emissive) || glm::any(glm::lessThan(m.emissive, glm::vec3(0.0f))))
            fail(what + ": emissive must be finite and non-negative");
        if (!(m.metallic >= 0.0f && m.metallic <= 1.0f)) fail(what + ": metallic must be in [0, 1]");
        if (!(m.roughness >= 0.0f && m.roughness <= 1.0f)) fail(what + ": roughness must be in [0, 1]");
        if (m.baseColorTexture < -1 || m.baseColorTexture >= static_cast<int>(mScene.textures.size()))
            fail(what + ": base colour texture " + std::to_string(m.baseColorTexture) + " does not exist (" +
                 std::to_string(mScene.textures.size()) + " textures)");
    }

    void checkMesh(std::size_t i) const {
        const Mesh& m = mScene.meshes[i];
        const std::string what = label("mesh", m.name, i);
        const std::size_t n = m.positions.size();
        if (m.indices.empty()) fail(what + ": has no triangles");
        if (m.indices.size() % 3 != 0)
            fail(what + ": index count " + std::to_string(m.indices.size()) + " is not a multiple of 3");
        if (m.normals.size() != n)
            fail(what + ": has " + std::to_string(m.normals.size()) + " normals for " + std::to_string(n) +
                 " positions");
        if (!m.texcoords.empty() && m.texcoords.size() != n)
            fail(what + ": has " + std::to_string(m.texcoords.size()) + " texcoords for " +
                 std::to_string(n) + " positions");
        for (std::size_t k = 0; k < m.indices.size(); ++k)
            if (m.indices[k] >= n)
                fail(what + ": index " + std::to_string(m.indices[k]) + " (entry " + std::to_string(k) +
                     ") is out of range for " + std::to_string(n) + " vertices");
        for (std::size_t k = 0; k < n; ++k) {
            if (!isFinite(m.positions[k])) fail(what + ": position " + std::to_string(k) + " is not finite");
            if (!isUnit(m.normals[k]))
                fail(what + ": normal " + std::to_string(k) + " is not a finite unit vector");
        }
        for (std::size_t k = 0; k < m.texcoords.size(); ++k)
            if (!isFinite(m.texcoords[k])) fail(what + ": texcoord " + std::to_string(k) + " is not finite");
        if (!m.colors.empty() && m.colors.size() != n)
            fail(what + ": has " + std::to_string(m.colors.size()) + " colours for " + std::to_string(n) +
                 " positions");
        for (std::size_t k = 0; k < m.colors.size(); ++k)
            if (!(m.colors[k].x >= 0.0f && m.colors[k].x <= 1.0f && m.colors[k].y >= 0.0f &&
                  m.colors[k].y <= 1.0f && m.colors[k].z >= 0.0f && m.colors[k].z <= 1.0f &&
                  m.colors[k].w >= 0.0f && m.colors[k].w <= 1.0f))
                fail(what + ": colour " + std::to_string(k) + " is not in [0, 1]");
        if (!m.tangents.empty() && m.tangents.size() != n)
            fail(what + ": has " + std::to_string(m.tangents.size()) + " tangents for " + std::to_string(n) +
                 " positions");
        for (std::size_t k = 0; k < m.tangents.size(); ++k)
            if (!std::isfinite(m.tangents[k].x) || !std::isfinite(m.tangents[k].y) ||
                !std::isfinite(m.tangents[k].z) || !std::isfinite(m.tangents[k].w))
                fail(what + ": tangent " + std::to_string(k) + " is not finite");
        if (m.material < 0 || m.material >= static_cast<int>(mScene.materials.size()))
            fail(what + ": material " + std::to_string(m.material) + " does not exist (" +
                 std::to_string(mScene.materials.size()) + " materials)");
        for (std::size_t k = 0; k < m.instances.size(); ++k) {
            const glm::mat4& toWorld = m.instances[k];
            bool finite = true;
            for (int c = 0; c < 4; ++c) finite = finite && isFinite(toWorld[c]);
            // The vertex stage transforms normals by the inverse transpose and keeps the winding.
            const float det = glm::determinant(glm::mat3(toWorld));
            if (!finite || !std::isfinite(det) || !(det > 0.0f))
                fail(what + ": instance " + std::to_string(k) +
                     "'s matrix is not finite or does not have a positive determinant (mirrored or "
                     "collapsed placements must be flattened)");
        }
    }

    void checkLight(std::size_t i) const {
        const Light& l = mScene.lights[i];
        const std::string what = label("light", l.name, i);
        if (!isFinite(l.position)) fail(what + ": position is not finite");
        if (!isUnit(l.direction)) fail(what + ": direction is not a finite unit vector");
        if (!isFinite(l.color) || glm::any(glm::lessThan(l.color, glm::vec3(0.0f))))
            fail(what + ": colour must be finite and non-negative");
        if (!std::isfinite(l.intensity) || l.intensity < 0.0f)
            fail(what + ": intensity must be finite and >= 0");
        if (!std::isfinite(l.range) || l.range < 0.0f) fail(what + ": range must be finite and >= 0");
        if (l.type == LightType::Spot &&
            !(l.innerConeAngle >= 0.0f && l.innerConeAngle < l.outerConeAngle && l.outerConeAngle <= kHalfPi))
            fail(what + ": spot cone angles must satisfy 0 <= inner < outer <= pi/2 (inner " +
                 std::to_string(l.innerConeAngle) + ", outer " + std::to_string(l.outerConeAngle) + ")");
    }

    void checkCamera(std::size_t i) const {
        const Camera& c = mScene.cameras[i];
        const std::string what = label("camera", c.name, i);
        if (!isFinite(c.position) || !isFinite(c.target) || !isFinite(c.up))
            fail(what + ": position, target and up must be finite");
        const glm::vec3 view = c.target - c.position;
        if (glm::dot(view, view) <= 1e-12f) fail(what + ": target coincides with position");
        if (glm::length(glm::cross(safeNormalize(view, glm::vec3(0.0f)),
                                   safeNormalize(c.up, glm::vec3(0.0f)))) < 1e-4f)
            fail(what + ": up is zero or parallel to the view direction");
        if (!(c.yfovRadians > 0.0f && c.yfovRadians < 3.1415926f)) fail(what + ": yfov must be in (0, pi)");
        if (!(c.znear > 0.0f && std::isfinite(c.zfar) && c.zfar > c.znear))
            fail(what + ": clip planes must satisfy 0 < znear < zfar");
    }

    const Scene& mScene;
    const std::string& mWhere;
};

} // namespace

void validateScene(const Scene& scene, const std::string& where) {
    Validator(scene, where).run();
}

} // namespace gis
