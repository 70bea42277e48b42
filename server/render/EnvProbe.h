// Dynamic environment reflections (004 §2.1 cube maps, §2.2.1 Fresnel decomposition, §2.2.2 glossy
// prefiltering), rendered on the fly every frame:
//   1. six 90-degree forward renders of the scene (render/forward.*: emission + shadowed spotlight)
//      from the probe into a cube map of env_size^2 per face;
//   2. prefilter into a mip chain, one roughness per level, each texel a GGX-lobe integral with
//      env_samples samples weighted by solid angle;
//   3. per eye pixel with a specular lobe below ReflectionInputs::envMaxRoughness (and not a mirror):
//      radiance += prefiltered(R, roughness) x the lobe's directional albedo (Fresnel guarded, no
//      total internal reflection term for opaque surfaces), R optionally parallax-corrected against
//      the scene bounds (env_parallax).
// Parameters (frame table): env_size (8-512 texels per face), env_samples (1-256), env_parallax.
// Limits: one probe at the scene centre; reflections show direct light and emission only.
#pragma once

#include "core/Param.h"
#include "gi/Technique.h"
#include "gl/Objects.h"
#include "gl/PassTimer.h"
#include "render/Reflections.h"

namespace gis {

class EnvProbe {
public:
    EnvProbe(); ///< compiles its programs: may throw gis::Error
    ~EnvProbe();
    /// Renders and prefilters the cube, then ADDS the reflected radiance into the framebuffer
    /// `target` (RGBA32F colour attachment 0, in.width x in.height; the caller cleared it).
    void execute(const ReflectionInputs& in, const ParamSet& frameParams, const gl::Framebuffer& target,
                 gl::PassTimer& timer, Counters& counters);

private:
    struct Impl;
    std::unique_ptr<Impl> mImpl;
};

} // namespace gis
