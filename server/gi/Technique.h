// The interface every GI technique implements (DESIGN.md §4), and the one registry that the CLI,
// server, client UI, tests and benchmarks enumerate.
//
// Life cycle, all on the render thread with its GL context current:
//   create()            compiles shaders: may throw gis::Error (a setup boundary)
//   resize(w, h)        allocates size-dependent targets: may throw
//   execute(...)        one frame: never throws; sanitises its output
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/Param.h"
#include "gi/Catalog.h"
#include "gl/FrameResources.h"
#include "gl/Objects.h"
#include "gl/PassTimer.h"
#include "gl/Shader.h"

namespace gis {

namespace shader {
struct FrameUniforms;
}

/// The frame pipeline's products a technique may read. Textures are owned by the renderer.
struct FrameInputs {
    int width = 0, height = 0;
    /// Everything the frame produced before the technique, by name (gbuffer.*, light[i].*, direct);
    /// the pointers below are the same textures, kept for the techniques that predate the table.
    const FrameResources* resources = nullptr;
    const gl::Texture* gPosition = nullptr; ///< RGBA32F world position, w = 1 where covered
    const gl::Texture* gNormal = nullptr;   ///< RGBA16F unit normal facing the camera
    const gl::Texture* gAlbedo = nullptr;   ///< RGBA8 linear diffuse albedo rho_d (scene/Brdf.h)
    const gl::Texture* gSpecular = nullptr; ///< RGBA8: rgb F0, a perceptual roughness (F0 = 0: no lobe)
    int rsmSize = 0;
    const gl::Texture* rsmPosition = nullptr; ///< RGBA32F, w = 1 where a surface was hit
    const gl::Texture* rsmNormal = nullptr;   ///< RGBA16F, facing the light
    const gl::Texture* rsmFlux = nullptr;     ///< RGBA32F diffusely reflected flux per texel
    const gl::Texture* rsmSpecular = nullptr; ///< RGBA8: rgb F0, a roughness of the texel's surface
    /// Glossy VPL transport (effect_glossy): when true, a technique whose glossyTransport() is true
    /// adds the specular lobe (lobe: frame shadingInfo.x) at receivers whose roughness is at least
    /// glossyMinRoughness; smoother receivers get theirs from the reflection passes.
    bool glossy = false;
    float glossyMinRoughness = 0.35f;
    bool lightEnabled = true;
    const gl::Texture* direct = nullptr;          ///< RGBA32F shadowed direct radiance plus emission
    const shader::FrameUniforms* frame = nullptr; ///< CPU copy of the bound gFrame block
    /// Draws the scene's triangles (world-space positions at attribute 0) with `program` bound,
    /// `instances` times; techniques see geometry only through this (VPL shadow maps).
    std::function<void(const gl::Program& program, int instances)> drawGeometry;
    float sceneExtent = 1.0f; ///< diagonal of the scene's bounds (m), > 0
};

using Counters = std::map<std::string, double>;

class Technique {
public:
    virtual ~Technique() = default;
    virtual void resize(int width, int height) = 0;
    /// Renders the indirect radiance for this frame into indirect(); records passes in `timer` and
    /// counts (VPLs, receivers, ...) in `counters`.
    virtual void execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                         Counters& counters) = 0;
    /// Linear RGB radiance to add to the direct light, or nullptr when the technique adds none.
    virtual const gl::Texture* indirect() const = 0;
    /// True when execute() with these parameters honours FrameInputs::glossy (docs/nondiffuse.md);
    /// overrides return what their TechniqueInfo::glossyTransport says.
    virtual bool glossyTransport(const ParamSet& /*params*/) const { return false; }
};

struct TechniqueEntry {
    TechniqueInfo info;
    std::function<std::unique_ptr<Technique>()> create;
};

/// All techniques with their GL implementations, in techniqueCatalog()'s order.
const std::vector<TechniqueEntry>& techniqueRegistry();
/// Throws gis::InputError listing the known names when `name` is unknown. Code that needs no GL
/// asks findTechniqueInfo() (gi/Catalog.h) instead.
const TechniqueEntry& findTechnique(const std::string& name, const std::string& where = "technique");

} // namespace gis
