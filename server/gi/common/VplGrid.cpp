#include "gi/common/VplGrid.h"

#include <algorithm>

#include "gi/common/BiasCompensation.h"
#include "gl/ShaderShared.h"

namespace gis {

KernelPrograms::KernelPrograms(const std::vector<gl::ShaderStage>& stages,
                               const std::vector<std::pair<std::string, std::string>>& defines) {
    auto with = [&](const char* kernel) {
        auto all = defines;
        all.emplace_back("GIS_VPL_KERNEL", kernel);
        return all;
    };
    mPoint = gl::Program::build(stages, with("GIS_KERNEL_POINT"));
    mDisk = gl::Program::build(stages, with("GIS_KERNEL_DISK"));
}

VplGrid::VplGrid() {
    mExtract = gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/vpl_extract.comp"}});
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

    timer.begin("vpl_extract");
    glUseProgram(mExtract.id());
    glUniform1i(mExtract.uniform("uGrid"), grid);
    glUniform1i(mExtract.uniform("uRsmSize"), in.rsmSize);
    glBindTextureUnit(0, in.find(FrameResources::light(0, "rsm.position"))->id());
    glBindTextureUnit(1, in.find(FrameResources::light(0, "rsm.normal"))->id());
    glBindTextureUnit(2, in.find(FrameResources::light(0, "rsm.flux"))->id());
    glBindTextureUnit(3, in.find(FrameResources::light(0, "rsm.specular"))
                             ? in.find(FrameResources::light(0, "rsm.specular"))->id()
                             : 0);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, mVpls.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, mGlossy.id());
    glDispatchCompute(static_cast<GLuint>((mCount + 63) / 64), 1, 1);
    glMemoryBarrier(GL_UNIFORM_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    timer.end();
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
