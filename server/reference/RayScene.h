// Ray queries and surface shading data for the reference renderer: the scene's triangles in an Embree 3
// BVH, plus the same material and normal rules as the GL pipeline (shaders/render/material.glsl), so a
// hit here and a G-buffer / RSM texel there describe the same surface: the same brdf::Surface
// (scene/Brdf.h surfaceFrom() of the material and its textured base colour).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "core/Error.h"
#include "scene/Brdf.h"
#include "scene/Scene.h"

namespace gis::reference {

/// A ray-surface hit with what the light transport needs.
struct SurfaceHit {
    float t = 0.0f;
    glm::vec3 position{0.0f};
    glm::vec3 geometricNormal{0.0f, 1.0f, 0.0f}; ///< unit, unoriented (triangle winding)
    glm::vec3 shadingNormal{0.0f, 1.0f, 0.0f};   ///< unit, unoriented (interpolated vertex normals)
    /// Diffuse albedo rho_d = surface.diffuse (the G-buffer's gAlbedo): base (1 - metal) (1 - Favg) with
    /// base = clamp(baseColor * texture, 0, 1); exactly the base colour for a Lambertian material
    /// (metallic 0, specular 0, so F0 = 0).
    glm::vec3 albedo{0.0f};
    glm::vec3 emission{0.0f}; ///< >= 0, finite
    /// The whole reflection model at this point (rho_d, F0, F90, alpha); Lambertian black without a
    /// material.
    brdf::Surface surface{};
    int mesh = -1; ///< index into Scene::meshes, -1 when unresolved
};

/// Minimal ray record for the all-hits query: the surface is resolved only when needed.
struct RawHit {
    float t = 0.0f;
    unsigned geomId = 0;
    unsigned primId = 0;
    float u = 0.0f, v = 0.0f;
};

/// How a RayScene is built.
struct RaySceneOptions {
    /// Embree's build quality: high (default; the reference renderer's millions of rays repay the
    /// slower build) or medium, for a few thousand rays (the effect planner: 10-30% faster at 0.5-2M
    /// triangles in as much memory; low was faster still but took 30% more). The structure changes,
    /// not what a ray hits.
    bool fastBuild = false;
    /// Asked between meshes and during Embree's build (on its threads); true stops the build with
    /// BuildCancelled. Null: never. Must not throw.
    std::function<bool()> cancelled;
};

/// A RayScene build stopped because RaySceneOptions::cancelled asked it to.
class BuildCancelled : public Error {
public:
    BuildCancelled() : Error("reference: the ray structure's build was cancelled") {}
};

class RayScene {
public:
    /// Builds the BVH. Throws gis::Error if Embree cannot be set up, BuildCancelled when cancelled.
    explicit RayScene(const Scene& scene, const RaySceneOptions& options = {});
    ~RayScene();
    RayScene(const RayScene&) = delete;
    RayScene& operator=(const RayScene&) = delete;

    /// Closest hit in (tnear, tfar); false when the ray escapes.
    bool intersect(const glm::vec3& origin, const glm::vec3& dir, float tnear, float tfar,
                   SurfaceHit& hit) const;
    /// intersect() for a ray from the camera: back faces of single-sided materials
    /// (Material::doubleSided false) are passed, as the G-buffer culls them.
    bool intersectFromCamera(const glm::vec3& origin, const glm::vec3& dir, float tnear, float tfar,
                             SurfaceHit& hit) const;
    /// True when anything lies in (tnear, tfar).
    bool occluded(const glm::vec3& origin, const glm::vec3& dir, float tnear, float tfar) const;
    /// Every surface crossing in (tnear, tfar), each triangle at most once, unordered. `hits` is cleared.
    void intersectAll(const glm::vec3& origin, const glm::vec3& dir, float tnear, float tfar,
                      std::vector<RawHit>& hits) const;
    SurfaceHit resolve(const RawHit& raw, const glm::vec3& origin, const glm::vec3& dir) const;

    /// Ray-origin offset (metres) that keeps a spawned ray off the surface it leaves.
    float epsilon() const { return mEpsilon; }

private:
    struct Impl;
    std::unique_ptr<Impl> mImpl;
    float mEpsilon = 1e-4f;
};

} // namespace gis::reference
