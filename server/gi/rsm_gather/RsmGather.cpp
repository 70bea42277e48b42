#include "gi/rsm_gather/RsmGather.h"

#include <algorithm>

#include "gl/ShaderShared.h"

namespace gis {

TechniqueInfo RsmGather::info() {
    return {"rsm_gather", "full-resolution gather from VPLs on a regular RSM grid", "000 §3, Eq. 2",
            ParamTable(vplParamSpecs(VplKernel::Point))};
}

RsmGather::RsmGather() {
    mGather = KernelPrograms(
        {{GL_VERTEX_SHADER, "render/fullscreen.vert"}, {GL_FRAGMENT_SHADER, "gi/rsm_gather/gather.frag"}});
    mEmptyVao = gl::VertexArray::create();
}

void RsmGather::resize(int width, int height) {
    mIndirect = gl::Texture::create2D(GL_RGBA32F, width, height);
    mTarget = gl::Framebuffer::create();
    mTarget.attachColor(0, mIndirect);
    mTarget.finish(1, "rsm_gather indirect");
}

void RsmGather::execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                        Counters& counters) {
    const int vplCount = mVpls.extract(in, params.getInt("vpl_grid"), timer, counters);

    timer.begin("vpl_gather");
    glBindFramebuffer(GL_FRAMEBUFFER, mTarget.id());
    glViewport(0, 0, in.width, in.height);
    const float zero[4] = {0, 0, 0, 0};
    glClearNamedFramebufferfv(mTarget.id(), GL_COLOR, 0, zero);
    if (vplCount > 0) {
        const gl::Program& gather = mGather.get(vplKernel(params));
        glUseProgram(gather.id());
        glUniform1f(gather.uniform("uMinDistance"), static_cast<float>(params.getFloat("min_distance")));
        glBindTextureUnit(0, in.gPosition->id());
        glBindTextureUnit(1, in.gNormal->id());
        glBindTextureUnit(2, in.gAlbedo->id());
        glBindVertexArray(mEmptyVao.id());
        glEnable(GL_BLEND);
        glBlendFunc(GL_ONE, GL_ONE);
        counters["vpl_batches"] = mVpls.forEachBatch([&](int count) {
            glUniform1i(gather.uniform("uVplCount"), count);
            glDrawArrays(GL_TRIANGLES, 0, 3);
        });
        glDisable(GL_BLEND);
    }
    timer.end();
}

} // namespace gis
