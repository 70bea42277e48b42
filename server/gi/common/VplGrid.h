// Shared by every technique that uses VPL set A (digest S.3 P4): the regular-grid VPL extraction
// (000 §3 step 3) into one compact buffer (001 §3.2.2's VPL cache), the kernel parameters every VPL
// technique exposes, and the batched binding of that buffer for the gather passes (VplBatches).
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "core/Param.h"
#include "gi/Technique.h"
#include "gi/common/ParamSpecs.h"
#include "gl/Objects.h"
#include "gl/Pass.h"
#include "gl/PassTimer.h"
#include "gl/Shader.h"

namespace gis {

/// The defines of one kernel variant: `defines` plus GIS_VPL_KERNEL (see vpl_transport.glsl).
std::vector<std::pair<std::string, std::string>>
kernelDefines(VplKernel kernel, const std::vector<std::pair<std::string, std::string>>& defines);

/// One program per kernel, built with GIS_VPL_KERNEL defined. `P` holds a program and the handles
/// it resolved: it is constructed from the built gl::Program (so a bad name fails here).
template <class P> class KernelPrograms {
public:
    KernelPrograms() = default;
    explicit KernelPrograms(const std::vector<gl::ShaderStage>& stages,
                            const std::vector<std::pair<std::string, std::string>>& defines = {})
        : mPoint(std::make_unique<P>(gl::Program::build(stages, kernelDefines(VplKernel::Point, defines)))),
          mDisk(std::make_unique<P>(gl::Program::build(stages, kernelDefines(VplKernel::Disk, defines)))) {}
    const P& get(VplKernel kernel) const { return kernel == VplKernel::Disk ? *mDisk : *mPoint; }

private:
    std::unique_ptr<P> mPoint, mDisk;
};

/// The uniforms every VPL receiver program shares through vpl_transport.glsl and
/// vpl_glossy.glsl, resolved once (optional: a program may include a file and not use all of it).
struct VplTransportHandles {
    VplTransportHandles() = default;
    /// Resolves the glossy uniforms when a source of `program` declares them (vpl_glossy.glsl).
    explicit VplTransportHandles(const gl::Program& program);
    gl::UniformLocation invClampB;                  ///< 1/b (m^-2), 0: no clamp
    gl::UniformLocation glossy, glossyMinRoughness; ///< vpl_glossy.glsl (when built with it)
    gl::BlockBinding glossyVpls;                    ///< VplGlossyBuffer (when built with it)
    bool hasGlossy = false;
    /// Sets the clamp from clamp_b (relative to `sceneSize`, m) and, with vpl_glossy.glsl, the glossy
    /// switch; binds the glossy VPL data when `glossyOn`.
    void set(gl::Pass& pass, const ParamSet& params, float sceneSize, bool glossyOn, float minRoughness,
             const gl::Buffer* glossyData) const;
};

/// The VPL grid side of each of `views` light views: one VPL set of about `grid`^2 VPLs split in
/// proportion to each view's reflected flux `viewFlux` (measured from its RSM), so a dim light does not
/// take VPLs from a bright one: side_v = round(sqrt(grid^2 x share_v)), at least 1 for a view with
/// flux, 0 for one without, at most `rsmSide`. One view gets min(grid, rsmSide); views that all
/// measure no flux share evenly. Pure (unit-tested).
std::vector<int> splitVplGrid(int grid, const std::vector<double>& viewFlux, int views, int rsmSide);

/// Refinement's gathers go in about kGatherPieces pieces that input can stop between (the interrupt
/// check asked after each; it waits for the work queued first): whole batches where there are at least that
/// many, else each batch cut in bands or receiver-list chunks. A fixed cut rather than one by time keeps a
/// frame's checks the same from run to run. Pure (unit-tested).
constexpr int kGatherPieces = 8;
struct GatherCut {
    int cutsPerBatch = 1;    ///< pieces each batch's draw is cut in
    int batchesPerPiece = 1; ///< whole batches drawn before the check is asked
};
GatherCut gatherCut(int batches);

/// The gathers' VPLs, batch by batch (gi/common/vpl_batch.glsl): each batch of up to
/// GIS_MAX_VPLS_PER_BATCH VPLs of a buffer is viewed as RGBA32F texels, three per shader::Vpl, at
/// texture unit GIS_TEXTURE_VPLS. A buffer texture rather than a uniform block: llvmpipe reads a
/// block's array at a loop index one float per lane, a texel fetch one vec4 per lane (docs/multires.md).
class VplBatches {
public:
    VplBatches(); ///< needs the context current
    /// Binds the first `count` VPLs of `vpls` batch by batch and calls `draw(batchCount, first)` for
    /// each, `first` being the index in `vpls` of the batch's first VPL. Returns the number of batches.
    int forEach(const gl::Buffer& vpls, int count,
                const std::function<void(int batchCount, int first)>& draw);
    /// forEach() in refinement's pieces (gatherCut) when `stop` is set: `draw(batchCount, first,
    /// cuts)` draws its batch in `cuts` pieces and returns false once `stop` said true inside it;
    /// after a piece of whole batches `stop` is asked. Returns false once
    /// stopped (the rest is not drawn); `batches` counts the batches drawn.
    bool forEachPiece(const gl::Buffer& vpls, int count, const std::function<bool()>& stop,
                      const std::function<bool(int batchCount, int first, int cuts)>& draw, int& batches);

private:
    gl::BufferTexture mView;
};

class VplGrid {
public:
    VplGrid();
    /// Extracts about `grid`^2 VPLs from the light views' RSMs, split across views by
    /// splitVplGrid() (none when no light is on), in view order in one buffer; records the pass
    /// "vpl_extract" and the counter "vpl_count". Returns the VPL count.
    int extract(const FrameInputs& in, int grid, gl::PassTimer& timer, Counters& counters);
    const gl::Buffer& buffer() const { return mVpls; }
    /// The VPLs' glossy data (shader::VplGlossy), indexed like buffer().
    const gl::Buffer& glossyBuffer() const { return mGlossy; }
    int count() const { return mCount; }
    /// Refinement's VPL parts (FrameInputs::vplPart): copies the VPLs part, part + parts, ... of the
    /// extracted set into one run (pass "vpl_interleave", gi/common/vpl_interleave.comp) for
    /// forEachPiece(true, ...); returns how many there are. The set's index of the part's k-th VPL is
    /// part + k * parts (its glossy data and shadow maps).
    int preparePart(int part, int parts, gl::PassTimer& timer);
    /// Binds the VPLs batch by batch (VplBatches), or the prepared part's VPLs when `part` (then
    /// `draw`'s `first` is the index in the part of the batch's first VPL), and draws them, in
    /// refinement's pieces when `stop` is set (VplBatches::forEachPiece).
    bool forEachPiece(bool part, const std::function<bool()>& stop,
                      const std::function<bool(int batchCount, int first, int cuts)>& draw, int& batches);

private:
    struct ExtractProgram {
        gl::Program program;
        gl::UniformLocation grid, rsmSize, view, offset;
        gl::TextureUnit position, normal, flux, specular;
        gl::BlockBinding vpls, glossy;
    } mExtract;
    struct InterleaveProgram {
        gl::Program program;
        gl::UniformLocation partCount, part, parts;
        gl::BlockBinding in, out;
    } mInterleave;
    gl::Buffer mVpls;
    gl::Buffer mGlossy;
    gl::Buffer mPartVpls; ///< the prepared part's VPLs (preparePart)
    VplBatches mBatches;
    int mCount = 0;
    int mPartCount = 0;
    /// What the buffer holds: the sides and RSM size of the last extraction (valid when mExtracted).
    bool mExtracted = false;
    std::vector<int> mExtractedSides;
    int mExtractedRsmSize = 0;
};

} // namespace gis
