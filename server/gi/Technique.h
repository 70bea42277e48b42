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
#include "gl/Background.h"
#include "gl/Objects.h"
#include "gl/PassTimer.h"
#include "gl/Shader.h"

namespace gis {

namespace shader {
struct FrameUniforms;
struct LightUniforms;
} // namespace shader

/// The frame pipeline's products a technique may read. Textures are owned by the renderer and read
/// from the frame's resource table by name (gl/FrameResources.h, docs/architecture.md):
///   gbuffer.position  RGBA32F world position, w = 1 where covered
///   gbuffer.normal    RGBA16F unit normal facing the camera
///   gbuffer.albedo    RGBA8 linear diffuse albedo rho_d (scene/Brdf.h)
///   gbuffer.specular  RGBA8: rgb F0, a perceptual roughness (F0 = 0: no lobe)
/// and, one layer per light view (2D arrays, lightViews layers; shared/FrameData.h LightView):
///   lights.rsm.position  RGBA32F, w = 1 where a surface was hit
///   lights.rsm.normal    RGBA16F, facing the light
///   lights.rsm.flux      RGBA32F: rgb diffusely reflected flux per texel, a its area perpendicular
///                        to the light (m^2; the VPL disk area of 001 Eq. 3)
///   lights.rsm.specular  RGBA8: rgb F0, a roughness of the texel's surface
///   lights.shadow        DEPTH32F shadow maps
///   direct            RGBA32F shadowed direct radiance plus emission
struct FrameInputs {
    int width = 0, height = 0;
    /// Everything the frame produced before the technique, by name.
    const FrameResources* resources = nullptr;
    int rsmSize = 0;    ///< texels per side of each light view's RSM layer
    int lightViews = 0; ///< RSM layers that hold a light view (0: no light is on)
    /// The side the parameters ask for (after the views' own limits): above rsmSize in an interactive
    /// frame that capped its light views (FrameState::lightViewCap), whose still view draws them at
    /// this side again. 0: rsmSize.
    int rsmSizeAsked = 0;
    /// Reflected flux luminance of each view's RSM (the VPL budget's split); empty without a light.
    std::vector<double> viewFlux;
    const shader::LightUniforms* lights = nullptr; ///< CPU copy of the bound gLights block
    /// Glossy VPL transport (effect_glossy): when true, a technique whose glossyTransport() is true
    /// adds the specular lobe (lobe: frame shadingInfo.x) at receivers whose roughness is at least
    /// glossyMinRoughness; smoother receivers get theirs from the reflection passes.
    bool glossy = false;
    float glossyMinRoughness = 0.35f;
    bool lightEnabled = true;
    /// The light views (shadow maps, RSMs) are the previous frame's, unchanged: what a technique
    /// derived from them alone (the extracted VPLs) still holds.
    bool lightViewsReused = false;
    const shader::FrameUniforms* frame = nullptr; ///< CPU copy of the bound gFrame block
    /// Draws the scene's triangles (positions at attribute 0, placed in the world by
    /// render/instance.glsl's placedPosition(); texture coordinates at 2, vertex colours at 4) with
    /// `program` bound, `instances` times; techniques see geometry only
    /// through this (VPL shadow maps). With sceneCutsOut it also sets the material uniforms of
    /// render/material.glsl that `program` declares, for its cutout test.
    std::function<void(const gl::Program& program, int instances)> drawGeometry;
    /// Some material cuts out (alpha MASK or BLEND): programs drawn through drawGeometry are built
    /// with GIS_ALPHA_CUTOUT so cut-out fragments are let through, as in the frame's own passes.
    bool sceneCutsOut = false;
    float sceneExtent = 1.0f; ///< diagonal of the scene's bounds (m), > 0
    /// Longest side of the scene's bounds (m), > 0: the unit of the scene-relative knobs
    /// (min_distance, clamp_b; gi/common/ParamSpecs.h).
    float sceneSize = 1.0f;
    /// One of vplParts interleaved VPL subsets (TechniqueInfo::vplParts): the VPLs whose index modulo
    /// vplParts is vplPart, their light scaled by vplParts. 1 part: every VPL.
    int vplPart = 0;
    int vplParts = 1;
    /// FrameState::receiverCapExponent: what the receiver cap cuts the VPLs by (0: the technique's
    /// fixed exponent).
    double receiverCapExponent = 0.0;
    /// A later VPL part of the image the previous frame rendered (same size, window, camera and
    /// parameters): what a technique derived from the G-buffer alone (the eye hierarchy) still holds.
    bool sameImageAsLastPart = false;
    /// Refinement's interruption (FrameRenderer::setInterruptCheck): says true once input waits and
    /// the frame will be dropped. A technique asks between its stages, where returning at once leaves
    /// whole what it keeps for later frames; the renderer's check finishes the GL work queued before it
    /// asks, so the work between two checks is one stage. Empty: frames run to the end.
    std::function<bool()> interruptCheck;
    /// With interruptCheck, storage of at least this many bytes is made in the background while
    /// input is asked (gl/Background.h; FrameRenderer::setBackgroundBytes).
    double backgroundBytes = static_cast<double>(gl::kBackgroundBytes);

    /// Whether the frame should stop here (interruptCheck, when set).
    bool interrupted() const { return interruptCheck && interruptCheck(); }

    /// The resource `name`, or nullptr when the frame did not produce it.
    const gl::Texture* find(const std::string& name) const {
        return resources ? resources->find(name) : nullptr;
    }
    /// The resource `name`; asserts that the frame produced it.
    const gl::Texture& get(const std::string& name) const;
    /// Whether the G-buffer, the lights' RSMs and the direct light are all published.
    bool complete() const;
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
