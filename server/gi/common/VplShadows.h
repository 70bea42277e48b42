// Optional VPL visibility for the VPL transport: a cube shadow map per VPL (6 layers of one depth
// array), all rendered by one instanced draw of the scene with vertex-shader layer selection.
// Chosen over imperfect shadow maps: the scenes here are small enough that exact shadow maps of
// 32^2 per face cost tens of milliseconds on llvmpipe (docs/ssbc.md), and they need no point
// sampling of the scene. GL limits the array to GL_MAX_ARRAY_TEXTURE_LAYERS / 6 VPLs; VPLs beyond
// that are unshadowed and the count is reported (counter vpl_shadowed).
//
// Parameters (vplShadowParamSpecs): vpl_shadows (off), vpl_shadow_size (texels per face, 32),
// vpl_shadow_bias (fraction of the VPL-receiver distance, 0.02). Alpha cutouts (MASK, BLEND at 0.5)
// are let through, as in every other pass.
#pragma once

#include <vector>

#include "core/Param.h"
#include "gi/Technique.h"
#include "gi/common/ParamSpecs.h"
#include "gl/Objects.h"
#include "gl/Pass.h"
#include "gl/PassTimer.h"
#include "gl/Shader.h"

namespace gis {

/// The lookup uniforms of vpl_shadow.glsl in a receiving program, resolved once.
struct VplShadowHandles {
    VplShadowHandles() = default;
    explicit VplShadowHandles(const gl::Program& program);
    gl::UniformLocation enabled, shadowed, far, bias;
    gl::TextureUnit maps{gl::kNoUnit};
};

class VplShadows {
public:
    VplShadows();
    /// Renders the shadow maps of the first VPLs of `vpls` ("vpl_shadows" pass) when the parameter
    /// is on; returns the number of VPLs that have one (0 when off).
    int render(const FrameInputs& in, const ParamSet& params, const gl::Buffer& vpls, int vplCount,
               gl::PassTimer& timer, Counters& counters);
    /// Sets the lookup uniforms of vpl_shadow.glsl in `pass` (its program in use) and binds the maps.
    void bind(gl::Pass& pass, const VplShadowHandles& handles, const FrameInputs& in,
              const ParamSet& params) const;

private:
    struct MapProgram {
        gl::Program program;
        gl::UniformLocation firstVpl, far;
        gl::BlockBinding vpls;
    };
    static MapProgram buildProgram(bool cutout);
    MapProgram mProgram;
    /// Built with GIS_ALPHA_CUTOUT on the first scene with cut-out materials (FrameInputs::sceneCutsOut):
    /// their cut-out fragments cast no indirect shadow, as in the light's own shadow map.
    MapProgram mCutoutProgram;
    gl::Texture mMaps;
    gl::Framebuffer mFbo;
    int mSize = 0, mLayers = 0, mShadowed = 0, mMaxLayers = 0;
};

} // namespace gis
