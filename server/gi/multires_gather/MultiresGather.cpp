#include "gi/multires_gather/MultiresGather.h"

#include <algorithm>

#include "gi/Catalog.h"
#include "gi/common/ParamSpecs.h"

namespace gis {

MultiresGather::GatherProgram::GatherProgram(gl::Program built)
    : program(std::move(built)),
      minDistance(program.optionalLocation("uMinDistance")) /* point kernel only */,
      vplCount(program.location("uVplCount")), vplScale(program.location("uVplScale")), transport(program),
      eye(program) {}

MultiresGather::MultiresGather() {
    mGather = KernelPrograms<GatherProgram>({{GL_COMPUTE_SHADER, "gi/multires_gather/gather.comp"}});
}

void MultiresGather::resize(int width, int height) {
    mIndirect.resize(width, height, "multires_gather indirect");
}

void MultiresGather::execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                             Counters& counters) {
    // The hierarchy comes first: its receivers decide how many VPLs the work cap leaves this frame.
    mEye.build(in, params, timer);
    // The eye hierarchy is whole (a later part of the same image keeps it): input may stop the frame.
    if (in.interrupted()) return;
    // The parts of a refinement step share one VPL set, sized by their own planner: no work cap.
    ParamSet capped = params;
    if (in.vplParts <= 1)
        mEye.capVplsToReceivers(
            in, findTechniqueInfo("multires_gather"), capped,
            [](const ParamSet& p) { return squared(p.getInt("vpl_grid")); }, counters);
    const int vplCount = mVpls.extract(in, capped.getInt("vpl_grid"), timer, counters);
    if (in.vplParts > 1) mVpls.preparePart(in.vplPart, in.vplParts, timer);

    {
        gl::Pass pass(timer, "vpl_gather");
        if (vplCount > 0) {
            const GatherProgram& g = mGather.get(vplKernel(params));
            pass.use(g.program).set(g.minDistance, vplMinDistance(params, in.sceneSize));
            g.transport.set(pass, params, in.sceneSize, false, in.glossyMinRoughness, nullptr);
            mEye.beginReceiverPass(pass, g.eye, in);
            // A VPL part (refinement) gathers every vplParts-th VPL, laid out contiguously.
            const int parts = std::max(1, in.vplParts);
            pass.set(g.vplScale, static_cast<float>(parts));
            // In refinement the gather goes in pieces that input can stop between (a VPL part's
            // gather is a whole slice): batches, or chunks of the receiver list (gatherCut).
            int batches = 0;
            const bool whole = mVpls.forEachPiece(
                parts > 1, in.interruptCheck,
                [&](int count, int, int cuts) {
                    return mEye.dispatchReceivers(pass.set(g.vplCount, count), g.eye, in.interruptCheck,
                                                  cuts);
                },
                batches);
            counters["vpl_batches"] = batches;
            if (parts > 1) {
                counters["vpl_part"] = std::clamp(in.vplPart, 0, parts - 1);
                counters["vpl_parts"] = parts;
            }
            if (!whole) return;
        }
    }

    mEye.reconstruct(in, params, true, mIndirect.framebuffer, timer);
    mEye.countReceivers(counters);
    mSsbc.apply(in, params, mIndirect.texture, timer, counters);
}

} // namespace gis
