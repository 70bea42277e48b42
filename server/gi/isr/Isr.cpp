#include "gi/isr/Isr.h"

#include <algorithm>
#include <string>

#include "gi/Catalog.h"
#include "gi/common/BiasCompensation.h"
#include "gi/common/VplGrid.h"

namespace gis {
namespace {
constexpr int kSelectGroup = 256; // local_size_x of isr/select.comp
}

Isr::Isr() {
    SelectProgram& s = mSelect;
    s.program = gl::Program::build({{GL_COMPUTE_SHADER, "gi/isr/select.comp"}});
    s.phase = s.program.location("uPhase");
    s.finest = s.program.location("uFinest");
    s.coarsest = s.program.location("uCoarsest");
    s.first = s.program.location("uFirst");
    s.nodeCount = s.program.location("uNodeCount");
    s.capacity = s.program.location("uCapacity");
    s.depthThreshold = s.program.location("uDepthThreshold");
    s.normalThreshold = s.program.location("uNormalThreshold");
    s.counts = s.program.storageBlock("IsrCounts");
    s.vpls = s.program.storageBlock("IsrVpls");
    // The gather is multires_gather's, always with the disk kernel (001 Eq. 1).
    GatherProgram& g = mGather;
    g.program = gl::Program::build({{GL_COMPUTE_SHADER, "gi/multires_gather/gather.comp"}},
                                   kernelDefines(VplKernel::Disk, {}));
    g.vplCount = g.program.location("uVplCount");
    g.vplScale = g.program.location("uVplScale");
    g.transport = VplTransportHandles(g.program);
    g.eye = EyeReceiverPassHandles(g.program);
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

    GLuint counts[1 + GIS_MAX_LIGHT_LEVELS] = {};
    {
        gl::Pass pass(timer, "isr_select");
        const GLuint zero = 0;
        glClearNamedBufferSubData(mCounts.id(), GL_R32UI, 0, header, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
        const SelectProgram& s = mSelect;
        pass.use(s.program);
        mTree.bind();
        pass.buffer(s.counts, mCounts).buffer(s.vpls, mVpls);
        pass.set(s.finest, finest)
            .set(s.coarsest, coarsest)
            .set(s.first, first)
            .set(s.nodeCount, nodeCount)
            .set(s.capacity, capacity)
            .set(s.depthThreshold, static_cast<float>(params.getFloat("light_depth_threshold")))
            .set(s.normalThreshold, static_cast<float>(params.getFloat("light_normal_threshold")));
        for (int phase = 0; phase < 2; ++phase)
            pass.set(s.phase, phase).dispatch(groups).barrier(GL_SHADER_STORAGE_BARRIER_BIT);
        pass.barrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
        glGetNamedBufferSubData(mCounts.id(), 0, header, counts);
    }

    const int count = static_cast<int>(std::min<GLuint>(counts[0], static_cast<GLuint>(capacity)));
    counters["vpl_count"] = count;
    for (int l = finest; l <= coarsest; ++l)
        counters["vpls_r" + std::to_string(levels[static_cast<size_t>(l)].side)] = counts[1 + l];
    return count;
}

void Isr::execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer, Counters& counters) {
    mTree.build(in, timer, counters);
    // The hierarchy comes first: its receivers decide how fine a cut the work cap leaves this frame.
    mEye.build(in, params, timer);
    // The eye hierarchy is whole (a later part of the same image keeps it): input may stop the frame.
    if (in.interrupted()) return;
    // The receiver work cap (gi/Catalog.h): a view with more receivers than its share selects light
    // patches no finer than a coarser isr_finest.
    ParamSet cut = params;
    if (mTree.valid())
        mEye.capVplsToReceivers(
            in, findTechniqueInfo("isr"), cut,
            [](const ParamSet& p) { return squared(p.getInt("isr_finest")); }, counters);
    mVplCount = mTree.valid() ? select(cut, timer, counters) : 0;
    if (!mTree.valid()) counters["vpl_count"] = 0;

    {
        gl::Pass pass(timer, "vpl_gather");
        if (mVplCount > 0) {
            const GatherProgram& g = mGather;
            pass.use(g.program);
            g.transport.set(pass, params, in.sceneSize, false, in.glossyMinRoughness, nullptr);
            mEye.beginReceiverPass(pass, g.eye, in);
            // In refinement the gather goes in pieces that input can stop between: batches, or
            // chunks of the receiver list (gatherCut).
            int batches = 0;
            const bool whole = mBatches.forEachPiece(
                mVpls, mVplCount, in.interruptCheck,
                [&](int count, int, int cuts) {
                    return mEye.dispatchReceivers(pass.set(g.vplCount, count).set(g.vplScale, 1.0f), g.eye,
                                                  in.interruptCheck, cuts);
                },
                batches);
            counters["vpl_batches"] = batches;
            if (!whole) return;
        }
    }

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
