// Dynamic environment reflections (004 §2.1 cube maps, §2.2.1 Fresnel decomposition, §2.2.2 glossy
// prefiltering), rendered on the fly every frame:
//   1. env_render: six 90-degree forward renders of the scene (render/forward.*: emission + shadowed
//      lights) from the probe into an RGBA16F cube map of env_size^2 per face with a depth buffer,
//      face by face; then its box-filtered mip chain (the source of filtered importance sampling);
//   2. env_prefilter (shaders/render/env_prefilter.comp): a second cube whose level k holds roughness
//      k / (levels - 1), levels = min(log2(env_size) + 1, kMaxLevels); level 0 is a copy (roughness
//      0), level k >= 1 the lobe-weighted mean over the GGX (or, with specular_lobe=phong, the Phong)
//      lobe under the split-sum assumption n = v = r, from env_samples Hammersley importance samples,
//      each read from the source mip whose texel solid angle matches the sample's 1 / (N pdf)
//      (filtered importance sampling: solid-angle weighted, no aliasing at few samples);
//   3. env_apply (shaders/render/env_apply.frag): per covered eye pixel with a specular lobe,
//      roughness below ReflectionInputs::envMaxRoughness and not a planar mirror the mirror pass
//      shades: radiance += prefiltered(r, roughness) x (F0 A + F90 B), r = reflect(-v, n), (A, B) the
//      split-sum environment BRDF (the lobe's directional albedo split by Schlick's Fresnel) from a
//      32 x 32 table computed once at construction (shaders/render/env_brdf_lut.comp; GGX and Phong
//      each have their own exact table). Fresnel: Schlick on v.h of each table sample, clamped to
//      [0, 1]; n.v <= 0 (grazing or back-facing) reflects exactly 0, the table is clamped to its
//      first texel centre (n.v = 1/64) above that, so no NaN at grazing angles. Opaque surfaces only:
//      no transmitted or total-internal-reflection term. With env_parallax=box the reflected ray is
//      intersected with the scene bounds and the cube read towards the hit point from the probe.
// The cube map is sampled with GL_TEXTURE_CUBE_MAP_SEAMLESS (enabled when the probe is created).
// Parameters (frame table): env_size (8-512 texels per face), env_samples (1-256), env_parallax,
// specular_lobe, env_budget_ms (0: none; else the probe count and face size are planned from the
// probes' measured cost to fit it, render/EnvProbeBudget.h). Timer passes env_render,
// env_prefilter, env_apply; counters env_size (rendered), env_size_requested, env_probes,
// env_probes_wanted, env_budget_ms, env_predicted_ms, env_samples, env_levels, env_cubes_reused.
// Probes: the room probe at the centre of the scene bounds, and one local probe per
// ReflectionInputs::envObjects entry (at most kMaxLocalProbes curved objects), at the object's
// centre and blind to it, read by the pixels whose G-buffer id is -(k + 1).
// Limits: other curved objects reflect from the room probe; reflections show direct light and emission
// only (no indirect light in the probe); direct specular highlights in the probe are seen from the
// probe, not from the reflecting point; between two levels the roughness is interpolated linearly.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/Param.h"
#include "gi/Technique.h"
#include "gl/Objects.h"
#include "gl/PassTimer.h"
#include "render/Reflections.h"

namespace gis {

class EnvProbe {
public:
    /// The most prefiltered levels (roughness 0, 0.2, ..., 1 at the full count).
    static constexpr int kMaxLevels = 6;
    /// Side of the environment-BRDF table (n.v x roughness texels).
    static constexpr int kBrdfTableSize = 32;

    EnvProbe(); ///< compiles its programs and computes the BRDF table: may throw gis::Error
    ~EnvProbe();
    /// Renders and prefilters the cube, then ADDS the reflected radiance into the framebuffer
    /// `target` (RGBA32F colour attachment 0, in.width x in.height; the caller cleared it).
    /// Never throws; leaves blending and depth testing off and the viewport at in.width x in.height.
    void execute(const ReflectionInputs& in, const ParamSet& frameParams, const gl::Framebuffer& target,
                 gl::PassTimer& timer, Counters& counters);

    /// The frame's resolved pass times: the probe passes' share becomes the cost model's measurement
    /// for the size and probe count this frame rendered (nothing when it kept its cubes).
    void noteTimings(const std::vector<gl::PassTiming>& passes);
    /// The last plan in words ("env_size 64, 1 probe: predicted ... within the ... budget").
    const std::string& planReason() const;

    /// Prefiltered levels for a cube of `envSize` texels per face.
    static int levelCount(int envSize);
    /// The probe position for `bounds`: their centre (inside the room of the builtin scenes).
    static glm::vec3 probePosition(const Bounds& bounds) { return bounds.center(); }
    /// World -> clip of cube face `face` (GL order +X, -X, +Y, -Y, +Z, -Z) seen from `probe`, so that
    /// a render into that face is what samplerCube returns for the same directions.
    static glm::mat4 faceViewProj(int face, const glm::vec3& probe, float zNear, float zFar);

private:
    struct Impl;
    std::unique_ptr<Impl> mImpl;
};

} // namespace gis
