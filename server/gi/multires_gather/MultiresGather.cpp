#include "gi/multires_gather/MultiresGather.h"

namespace gis {

TechniqueInfo MultiresGather::info() {
    std::vector<ParamSpec> specs = vplParamSpecs(VplKernel::Disk);
    for (auto& s : eyeHierarchyParamSpecs()) specs.push_back(std::move(s));
    return {"multires_gather", "stencil-selected multiresolution gather from grid VPLs, upsampled",
            "001 §3.2", ParamTable(std::move(specs))};
}

MultiresGather::MultiresGather() {
    mGather = KernelPrograms({{GL_VERTEX_SHADER, "render/fullscreen.vert"},
                              {GL_FRAGMENT_SHADER, "gi/multires_gather/gather.frag"}});
    mEmptyVao = gl::VertexArray::create();
}

void MultiresGather::resize(int width, int height) {
    mIndirect = gl::Texture::create2D(GL_RGBA32F, width, height);
    mTarget = gl::Framebuffer::create();
    mTarget.attachColor(0, mIndirect);
    mTarget.finish(1, "multires_gather indirect");
}

void MultiresGather::execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                             Counters& counters) {
    const int vplCount = mVpls.extract(in, params.getInt("vpl_grid"), timer, counters);
    mEye.build(in, params, timer);

    timer.begin("vpl_gather");
    if (vplCount > 0) {
        glBindFramebuffer(GL_FRAMEBUFFER, mEye.illuminationTarget().id());
        glViewport(0, 0, mEye.atlasWidth(), mEye.atlasHeight());
        const gl::Program& gather = mGather.get(vplKernel(params));
        glUseProgram(gather.id());
        glUniform1f(gather.uniform("uMinDistance"), static_cast<float>(params.getFloat("min_distance")));
        setVplClamp(gather, params);
        glBindTextureUnit(0, mEye.geoPosition().id());
        glBindTextureUnit(1, mEye.geoNormal().id());
        mEye.bindPixels(in);
        glBindVertexArray(mEmptyVao.id());
        glEnable(GL_STENCIL_TEST);
        glStencilFunc(GL_EQUAL, 1, 0xFF);
        glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
        glEnable(GL_BLEND);
        glBlendFuncSeparate(GL_ONE, GL_ONE, GL_ONE, GL_ZERO); // rgb accumulates, alpha marks data
        counters["vpl_batches"] = mVpls.forEachBatch([&](int count) {
            glUniform1i(gather.uniform("uVplCount"), count);
            glDrawArrays(GL_TRIANGLES, 0, 3);
        });
        glDisable(GL_BLEND);
        glDisable(GL_STENCIL_TEST);
    }
    timer.end();

    mEye.reconstruct(in, params, true, mTarget, timer);
    mEye.countReceivers(counters);
    mSsbc.apply(in, params, mIndirect, timer, counters);
}

} // namespace gis
