#include "gi/multires_gather/MultiresGather.h"

namespace gis {

MultiresGather::MultiresGather() {
    mGather = KernelPrograms({{GL_VERTEX_SHADER, "render/fullscreen.vert"},
                              {GL_FRAGMENT_SHADER, "gi/multires_gather/gather.frag"}});
}

void MultiresGather::resize(int width, int height) {
    mIndirect.resize(width, height, "multires_gather indirect");
}

void MultiresGather::execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                             Counters& counters) {
    const int vplCount = mVpls.extract(in, params.getInt("vpl_grid"), timer, counters);
    mEye.build(in, params, timer);

    timer.begin("vpl_gather");
    if (vplCount > 0) {
        const gl::Program& gather = mGather.get(vplKernel(params));
        glUseProgram(gather.id());
        glUniform1f(gather.uniform("uMinDistance"), static_cast<float>(params.getFloat("min_distance")));
        setVplClamp(gather, params);
        mEye.beginIlluminationPass(in, true);
        counters["vpl_batches"] = mVpls.forEachBatch([&](int count) {
            glUniform1i(gather.uniform("uVplCount"), count);
            glDrawArrays(GL_TRIANGLES, 0, 3);
        });
        mEye.endIlluminationPass();
    }
    timer.end();

    mEye.reconstruct(in, params, true, mIndirect.framebuffer, timer);
    mEye.countReceivers(counters);
    mSsbc.apply(in, params, mIndirect.texture, timer, counters);
}

} // namespace gis
