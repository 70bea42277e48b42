// Technique `rsm_gather`: one-bounce indirect light gathered at full resolution from virtual point
// lights on a regular reflective-shadow-map grid.
//
// Paper: 000 (Nichols & Wyman 2009) §3 steps 1-3 and Eq. 2 with diffuse BRDFs; the "rsm_naive"
// preset of digest S.3 (VPL set A, receivers R0, kernel K1, no visibility between VPL and receiver).
// It is the full-resolution baseline that the multiresolution techniques are measured against.
//
// Pipeline:
//   1. (renderer) an RSM per light view: position, normal, reflected flux per texel
//   2. vpl_extract: a compute pass turns each of vpl_grid^2 cells into one VPL (centre texel's
//      position and normal, the cell's summed flux) written to a buffer
//   3. vpl_gather: a full-screen pass per batch of up to 1024 VPLs (read as buffer-texture texels)
//      evaluates the clamped point kernel at every covered pixel, blended additively
//   4. output: linear radiance albedo/pi * E, sanitised and >= 0
//   A refinement VPL part (FrameInputs::vplPart, without bias compensation) gathers in 3 only every
//   vplParts-th VPL, scaled by vplParts; the renderer averages the parts.
//
// Parameters:
//   vpl_grid      VPLs per side, [1, 256] (clamped to rsm_size), default 16 (256 VPLs)
//   kernel        point (000 Eq. 2, default) or disk (001 Eq. 1: bounded, needs no clamp)
//   min_distance  point kernel: distance clamp of the 1/d^2 falloff, [0, 0.5] of the scene's size (its
//                 longest side), default 0.05 (0.1 m in the 2 m Cornell room)
//   clamp_b, ssbc_*  K3 clamp and bias compensation (BiasCompensation.h), off by default; the
//                 `ssbc` preset (002) is this pipeline with clamp_b 40 (1/size^2) and ssbc_iterations 1
//
// Glossy transport (FrameInputs::glossy, docs/nondiffuse.md): VPLs and receivers on specular surfaces
// at least glossy_split rough add their specular lobes (gi/common/vpl_glossy.glsl).
//
// Limits: no indirect visibility (light leaks behind occluders, as in 000/001); smooth VPLs are diffuse;
// grid sampling ignores flux (000 suggests importance sampling as future work).
#pragma once

#include "gi/Technique.h"
#include "gi/common/IndirectTarget.h"
#include "gi/common/BiasCompensation.h"
#include "gi/common/VplGrid.h"
#include "gi/common/VplShadows.h"
#include "gl/Shader.h"

namespace gis {

class RsmGather final : public Technique {
public:
    RsmGather();
    void resize(int width, int height) override;
    void execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                 Counters& counters) override;
    const gl::Texture* indirect() const override { return &mIndirect.texture; }
    bool glossyTransport(const ParamSet&) const override { return true; }

private:
    VplGrid mVpls;
    VplShadows mShadows;
    struct GatherProgram {
        explicit GatherProgram(gl::Program built);
        gl::Program program;
        gl::UniformLocation minDistance, vplCount, vplFirst, vplPhase, vplStride;
        gl::TextureUnit position, normal, albedo, specular;
        VplTransportHandles transport;
        VplShadowHandles shadows;
    };
    /// Without and with the VPL shadow lookup (GIS_VPL_SHADOWED in gather.frag).
    KernelPrograms<GatherProgram> mGather, mShadowedGather;
    BiasCompensation mSsbc;
    IndirectTarget mIndirect;
    gl::VertexArray mEmptyVao;
};

} // namespace gis
