#include "gi/common/VplGrid.h"

#include <algorithm>

#include "gi/common/BiasCompensation.h"
#include "gl/ShaderShared.h"

namespace gis {

std::vector<std::pair<std::string, std::string>>
kernelDefines(VplKernel kernel, const std::vector<std::pair<std::string, std::string>>& defines) {
    auto all = defines;
    all.emplace_back("GIS_VPL_KERNEL", kernel == VplKernel::Disk ? "GIS_KERNEL_DISK" : "GIS_KERNEL_POINT");
    return all;
}

VplTransportHandles::VplTransportHandles(const gl::Program& program)
    : invClampB(program.optionalLocation("uVplInvClampB")), hasGlossy(program.declares("uGlossy")) {
    if (hasGlossy) {
        glossy = program.optionalLocation("uGlossy");
        glossyMinRoughness = program.optionalLocation("uGlossyMinRoughness");
        glossyVpls = program.optionalStorageBlock("VplGlossyBuffer");
    }
}

void VplTransportHandles::set(gl::Pass& pass, const ParamSet& params, bool glossyOn, float minRoughness,
                              const gl::Buffer* glossyData) const {
    pass.set(invClampB, vplInverseClampB(params));
    if (!hasGlossy) return;
    pass.set(glossy, glossyOn ? 1 : 0).set(glossyMinRoughness, minRoughness);
    if (glossyOn && glossyData) pass.buffer(glossyVpls, *glossyData);
}

VplGrid::VplGrid() {
    gl::Program p = gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/vpl_extract.comp"}});
    mExtract = {{},
                p.location("uGrid"),
                p.location("uRsmSize"),
                p.textureUnit("gRsmPosition"),
                p.textureUnit("gRsmNormal"),
                p.textureUnit("gRsmFlux"),
                p.textureUnit("gRsmSpecular"),
                p.storageBlock("VplOut"),
                p.storageBlock("VplGlossyOut")};
    mExtract.program = std::move(p);
}

int VplGrid::extract(const FrameInputs& in, int grid, gl::PassTimer& timer, Counters& counters) {
    grid = std::clamp(grid, 1, std::max(in.rsmSize, 1));
    mCount = in.lightEnabled ? grid * grid : 0;
    counters["vpl_count"] = mCount;
    const GLsizeiptr bytes = static_cast<GLsizeiptr>(std::max(mCount, 1)) * sizeof(shader::Vpl);
    if (mVpls.size() < bytes) mVpls = gl::Buffer::create(bytes);
    const GLsizeiptr glossyBytes = static_cast<GLsizeiptr>(std::max(mCount, 1)) * sizeof(shader::VplGlossy);
    if (mGlossy.size() < glossyBytes) mGlossy = gl::Buffer::create(glossyBytes);
    if (mCount == 0) return 0;

    const ExtractProgram& e = mExtract;
    gl::Pass pass(timer, "vpl_extract");
    pass.use(e.program).set(e.grid, grid).set(e.rsmSize, in.rsmSize);
    pass.texture(e.position, in.light(0, "rsm.position"))
        .texture(e.normal, in.light(0, "rsm.normal"))
        .texture(e.flux, in.light(0, "rsm.flux"))
        .texture(e.specular, in.find(FrameResources::light(0, "rsm.specular")));
    pass.buffer(e.vpls, mVpls).buffer(e.glossy, mGlossy);
    pass.dispatch((mCount + 63) / 64).barrier(GL_UNIFORM_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    return mCount;
}

int forEachVplBatch(const gl::Buffer& vpls, int count, const std::function<void(int batchCount)>& draw) {
    int batches = 0;
    for (int first = 0; first < count; first += GIS_MAX_VPLS_PER_BATCH, ++batches) {
        const int n = std::min(GIS_MAX_VPLS_PER_BATCH, count - first);
        glBindBufferRange(GL_UNIFORM_BUFFER, GIS_UBO_VPLS, vpls.id(),
                          static_cast<GLintptr>(first) * static_cast<GLintptr>(sizeof(shader::Vpl)),
                          static_cast<GLsizeiptr>(n) * static_cast<GLsizeiptr>(sizeof(shader::Vpl)));
        draw(n);
    }
    return batches;
}

int VplGrid::forEachBatch(const std::function<void(int batchCount)>& draw) const {
    return forEachVplBatch(mVpls, mCount, draw);
}

} // namespace gis
