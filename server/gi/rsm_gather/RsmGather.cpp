#include "gi/rsm_gather/RsmGather.h"

#include <algorithm>

#include "gl/ShaderShared.h"

namespace gis {

namespace {} // namespace

RsmGather::RsmGather() {
    mGather = KernelPrograms(
        {{GL_VERTEX_SHADER, "render/fullscreen.vert"}, {GL_FRAGMENT_SHADER, "gi/rsm_gather/gather.frag"}});
    mEmptyVao = gl::VertexArray::create();
}

void RsmGather::resize(int width, int height) {
    mIndirect.resize(width, height, "rsm_gather indirect");
}

void RsmGather::execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                        Counters& counters) {
    const int vplCount = mVpls.extract(in, params.getInt("vpl_grid"), timer, counters);
    mShadows.render(in, params, mVpls.buffer(), vplCount, timer, counters);

    timer.begin("vpl_gather");
    glBindFramebuffer(GL_FRAMEBUFFER, mIndirect.framebuffer.id());
    glViewport(0, 0, in.width, in.height);
    const float zero[4] = {0, 0, 0, 0};
    glClearNamedFramebufferfv(mIndirect.framebuffer.id(), GL_COLOR, 0, zero);
    if (vplCount > 0) {
        const gl::Program& gather = mGather.get(vplKernel(params));
        glUseProgram(gather.id());
        glUniform1f(gather.uniform("uMinDistance"), static_cast<float>(params.getFloat("min_distance")));
        setVplClamp(gather, params);
        mShadows.bind(gather, in, params);
        glBindTextureUnit(0, in.find("gbuffer.position")->id());
        glBindTextureUnit(1, in.find("gbuffer.normal")->id());
        glBindTextureUnit(2, in.find("gbuffer.albedo")->id());
        const bool glossy = in.glossy && in.find("gbuffer.specular") != nullptr;
        glUniform1i(gather.uniform("uGlossy"), glossy ? 1 : 0);
        glUniform1f(gather.uniform("uGlossyMinRoughness"), in.glossyMinRoughness);
        if (glossy) {
            glBindTextureUnit(3, in.find("gbuffer.specular")->id());
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, mVpls.glossyBuffer().id());
        }
        glBindVertexArray(mEmptyVao.id());
        glEnable(GL_BLEND);
        glBlendFunc(GL_ONE, GL_ONE);
        int first = 0;
        counters["vpl_batches"] = mVpls.forEachBatch([&](int count) {
            glUniform1i(gather.uniform("uVplCount"), count);
            glUniform1i(gather.uniform("uVplFirst"), first);
            glDrawArrays(GL_TRIANGLES, 0, 3);
            first += count;
        });
        glDisable(GL_BLEND);
    }
    timer.end();
    mSsbc.apply(in, params, mIndirect.texture, timer, counters);
}

} // namespace gis
