// Shared by every technique that uses VPL set A (digest S.3 P4): the regular-grid VPL extraction
// (000 §3 step 3) into one compact buffer (001 §3.2.2's VPL cache), the kernel parameters every VPL
// technique exposes, and the batched binding of that buffer as the gather passes' uniform block.
#pragma once

#include <functional>
#include <vector>

#include "core/Param.h"
#include "gi/Technique.h"
#include "gi/common/ParamSpecs.h"
#include "gl/Objects.h"
#include "gl/PassTimer.h"
#include "gl/Shader.h"

namespace gis {

/// One program per kernel, built with GIS_VPL_KERNEL defined (see vpl_transport.glsl).
class KernelPrograms {
public:
    KernelPrograms() = default;
    explicit KernelPrograms(const std::vector<gl::ShaderStage>& stages,
                            const std::vector<std::pair<std::string, std::string>>& defines = {});
    const gl::Program& get(VplKernel kernel) const { return kernel == VplKernel::Disk ? mDisk : mPoint; }

private:
    gl::Program mPoint, mDisk;
};

/// Binds the first `count` VPLs of `vpls` batch by batch (GIS_MAX_VPLS_PER_BATCH each) at
/// GIS_UBO_VPLS and calls `draw(batchCount)` for each batch. Returns the number of batches.
int forEachVplBatch(const gl::Buffer& vpls, int count, const std::function<void(int batchCount)>& draw);

class VplGrid {
public:
    VplGrid();
    /// Extracts min(vpl_grid, rsm_size)^2 VPLs from the RSM (none when the light is off); records
    /// the pass "vpl_extract" and the counter "vpl_count". Returns the VPL count.
    int extract(const FrameInputs& in, int grid, gl::PassTimer& timer, Counters& counters);
    const gl::Buffer& buffer() const { return mVpls; }
    /// The VPLs' glossy data (shader::VplGlossy), indexed like buffer().
    const gl::Buffer& glossyBuffer() const { return mGlossy; }
    int count() const { return mCount; }
    /// Binds the VPLs batch by batch (GIS_MAX_VPLS_PER_BATCH each) at GIS_UBO_VPLS and calls
    /// `draw(batchCount)` for each batch. Returns the number of batches.
    int forEachBatch(const std::function<void(int batchCount)>& draw) const;

private:
    gl::Program mExtract;
    gl::Buffer mVpls;
    gl::Buffer mGlossy;
    int mCount = 0;
};

} // namespace gis
