#include "gi/isr/Isr.h"

#include <algorithm>
#include <string>

#include "gi/common/BiasCompensation.h"
#include "gi/common/VplGrid.h"

namespace gis {
namespace {
constexpr int kSelectGroup = 256; // local_size_x of isr/select.comp
}

Isr::Isr() {
    mSelect = gl::Program::build({{GL_COMPUTE_SHADER, "gi/isr/select.comp"}});
    // The gather is multires_gather's, always with the disk kernel (001 Eq. 1).
    mGather = gl::Program::build({{GL_VERTEX_SHADER, "render/fullscreen.vert"},
                                  {GL_FRAGMENT_SHADER, "gi/multires_gather/gather.frag"}},
                                 {{"GIS_VPL_KERNEL", "GIS_KERNEL_DISK"}});
}

void Isr::resize(int width, int height) {
    mIndirect.resize(width, height, "isr indirect");
}

int Isr::select(const ParamSet& params, gl::PassTimer& timer, Counters& counters) {
    const auto& levels = mTree.levels();
    const int finest = lightLevelForResolution(levels, params.getInt("isr_finest"));
    const int coarsest = std::max(finest, lightLevelForResolution(levels, params.getInt("isr_coarsest")));
    const int first = levels[static_cast<size_t>(finest)].offset;
    const LightLevel& last = levels[static_cast<size_t>(coarsest)];
    const int nodeCount = last.offset + last.side * last.side - first;
    const int groups = (nodeCount + kSelectGroup - 1) / kSelectGroup;
    // Each VPL covers at least one node of the finest level, so that level's size bounds the count.
    const int capacity = levels[static_cast<size_t>(finest)].side * levels[static_cast<size_t>(finest)].side;

    const GLsizeiptr vplBytes =
        static_cast<GLsizeiptr>(capacity) * static_cast<GLsizeiptr>(sizeof(shader::Vpl));
    if (mVpls.size() < vplBytes) mVpls = gl::Buffer::create(vplBytes);
    const GLsizeiptr header = (1 + GIS_MAX_LIGHT_LEVELS) * sizeof(GLuint);
    const GLsizeiptr countBytes =
        header + static_cast<GLsizeiptr>(groups) * static_cast<GLsizeiptr>(sizeof(GLuint));
    if (mCounts.size() < countBytes)
        mCounts = gl::Buffer::create(countBytes, nullptr, GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);

    timer.begin("isr_select");
    const GLuint zero = 0;
    glClearNamedBufferSubData(mCounts.id(), GL_R32UI, 0, header, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glUseProgram(mSelect.id());
    mTree.bind();
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, mCounts.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, mVpls.id());
    glUniform1i(mSelect.uniform("uFinest"), finest);
    glUniform1i(mSelect.uniform("uCoarsest"), coarsest);
    glUniform1i(mSelect.uniform("uFirst"), first);
    glUniform1i(mSelect.uniform("uNodeCount"), nodeCount);
    glUniform1i(mSelect.uniform("uCapacity"), capacity);
    glUniform1f(mSelect.uniform("uDepthThreshold"),
                static_cast<float>(params.getFloat("light_depth_threshold")));
    glUniform1f(mSelect.uniform("uNormalThreshold"),
                static_cast<float>(params.getFloat("light_normal_threshold")));
    for (int phase = 0; phase < 2; ++phase) {
        glUniform1i(mSelect.uniform("uPhase"), phase);
        glDispatchCompute(static_cast<GLuint>(groups), 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
    glMemoryBarrier(GL_UNIFORM_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    GLuint counts[1 + GIS_MAX_LIGHT_LEVELS] = {};
    glGetNamedBufferSubData(mCounts.id(), 0, header, counts);
    timer.end();

    const int count = static_cast<int>(std::min<GLuint>(counts[0], static_cast<GLuint>(capacity)));
    counters["vpl_count"] = count;
    for (int l = finest; l <= coarsest; ++l)
        counters["vpls_r" + std::to_string(levels[static_cast<size_t>(l)].side)] = counts[1 + l];
    return count;
}

void Isr::execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer, Counters& counters) {
    mTree.build(in, timer, counters);
    mVplCount = mTree.valid() ? select(params, timer, counters) : 0;
    if (!mTree.valid()) counters["vpl_count"] = 0;
    mEye.build(in, params, timer);

    timer.begin("vpl_gather");
    if (mVplCount > 0) {
        glUseProgram(mGather.id());
        setVplClamp(mGather, params);
        mEye.beginIlluminationPass(in, true);
        const GLint countLoc = mGather.uniform("uVplCount");
        counters["vpl_batches"] = forEachVplBatch(mVpls, mVplCount, [&](int count) {
            glUniform1i(countLoc, count);
            glDrawArrays(GL_TRIANGLES, 0, 3);
        });
        mEye.endIlluminationPass();
    }
    timer.end();

    mEye.reconstruct(in, params, true, mIndirect.framebuffer, timer);
    mEye.countReceivers(counters);
    mSsbc.apply(in, params, mIndirect.texture, timer, counters);
}

std::vector<shader::Vpl> Isr::readVpls() const {
    std::vector<shader::Vpl> vpls(static_cast<size_t>(mVplCount));
    if (mVplCount > 0)
        glGetNamedBufferSubData(mVpls.id(), 0, static_cast<GLsizeiptr>(vpls.size() * sizeof(shader::Vpl)),
                                vpls.data());
    return vpls;
}

} // namespace gis
