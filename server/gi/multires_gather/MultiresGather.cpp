#include "gi/multires_gather/MultiresGather.h"

#include <algorithm>

namespace gis {

MultiresGather::GatherProgram::GatherProgram(gl::Program built)
    : program(std::move(built)),
      minDistance(program.optionalLocation("uMinDistance")) /* point kernel only */,
      vplCount(program.location("uVplCount")), vplPhase(program.location("uVplPhase")),
      vplStride(program.location("uVplStride")), allVpls(program.storageBlock("VplAll")), transport(program),
      eye(program) {}

MultiresGather::MultiresGather() {
    mGather = KernelPrograms<GatherProgram>({{GL_VERTEX_SHADER, "render/fullscreen.vert"},
                                             {GL_FRAGMENT_SHADER, "gi/multires_gather/gather.frag"}});
}

void MultiresGather::resize(int width, int height) {
    mIndirect.resize(width, height, "multires_gather indirect");
}

void MultiresGather::execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                             Counters& counters) {
    const int vplCount = mVpls.extract(in, params.getInt("vpl_grid"), timer, counters);
    mEye.build(in, params, timer);

    {
        gl::Pass pass(timer, "vpl_gather");
        if (vplCount > 0) {
            const GatherProgram& g = mGather.get(vplKernel(params));
            pass.use(g.program).set(g.minDistance, static_cast<float>(params.getFloat("min_distance")));
            g.transport.set(pass, params, false, in.glossyMinRoughness, nullptr);
            mEye.beginIlluminationPass(pass, g.eye, in, true);
            if (in.vplParts > 1) {
                // A refinement VPL part: one draw striding over the whole buffer (the batches' uniform
                // block is bound but not read).
                const int part = std::clamp(in.vplPart, 0, in.vplParts - 1);
                pass.buffer(g.allVpls, mVpls.buffer());
                bool drawn = false;
                mVpls.forEachBatch([&](int) {
                    if (drawn || part >= vplCount) return;
                    pass.set(g.vplCount, vplCount)
                        .set(g.vplPhase, part)
                        .set(g.vplStride, in.vplParts)
                        .drawFullscreen(mEye.emptyVao());
                    drawn = true;
                });
                counters["vpl_batches"] = drawn ? 1 : 0;
                counters["vpl_part"] = part;
                counters["vpl_parts"] = in.vplParts;
            } else {
                counters["vpl_batches"] = mVpls.forEachBatch([&](int count) {
                    pass.set(g.vplCount, count)
                        .set(g.vplPhase, 0)
                        .set(g.vplStride, 1)
                        .drawFullscreen(mEye.emptyVao());
                });
            }
        }
    }

    mEye.reconstruct(in, params, true, mIndirect.framebuffer, timer);
    mEye.countReceivers(counters);
    mSsbc.apply(in, params, mIndirect.texture, timer, counters);
}

} // namespace gis
