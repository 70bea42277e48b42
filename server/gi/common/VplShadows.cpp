#include "gi/common/VplShadows.h"

#include <algorithm>

namespace gis {

VplShadows::VplShadows() {
    mProgram = gl::Program::build(
        {{GL_VERTEX_SHADER, "gi/common/vpl_shadow.vert"}, {GL_FRAGMENT_SHADER, "gi/common/vpl_shadow.frag"}});
    glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &mMaxLayers);
}

int VplShadows::render(const FrameInputs& in, const ParamSet& params, const gl::Buffer& vpls, int vplCount,
                       gl::PassTimer& timer, Counters& counters) {
    mShadowed = 0;
    if (!params.getBool("vpl_shadows") || vplCount <= 0 || !in.drawGeometry) return 0;
    const int size = params.getInt("vpl_shadow_size");
    const int shadowed = std::min(vplCount, std::max(mMaxLayers, 6) / 6);
    const int layers = shadowed * 6;
    if (size != mSize || layers > mLayers) {
        mMaps = gl::Texture::create2DArray(GL_DEPTH_COMPONENT32F, size, size, layers);
        mMaps.setFilter(GL_NEAREST, GL_NEAREST);
        mMaps.setWrap(GL_CLAMP_TO_EDGE);
        mFbo = gl::Framebuffer::create();
        mFbo.attachDepth(mMaps); // all layers: the vertex shader picks one per instance
        mFbo.finish(0, "VPL shadow maps");
        mSize = size;
        mLayers = layers;
    }
    timer.begin("vpl_shadows");
    glBindFramebuffer(GL_FRAMEBUFFER, mFbo.id());
    glViewport(0, 0, size, size);
    const float one = 1.0f;
    glClearNamedFramebufferfv(mFbo.id(), GL_DEPTH, 0, &one);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glUseProgram(mProgram.id());
    glUniform1i(mProgram.uniform("uFirstVpl"), 0);
    glUniform1f(mProgram.uniform("uFar"), in.sceneExtent);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, vpls.id());
    in.drawGeometry(mProgram, layers);
    glDisable(GL_DEPTH_TEST);
    timer.end();
    mShadowed = shadowed;
    counters["vpl_shadowed"] = shadowed;
    return shadowed;
}

void VplShadows::bind(const gl::Program& program, const FrameInputs& in, const ParamSet& params) const {
    glUniform1i(program.uniform("uVplShadows"), mShadowed > 0 ? 1 : 0);
    glUniform1i(program.uniform("uVplShadowed"), mShadowed);
    glUniform1f(program.uniform("uVplShadowFar"), in.sceneExtent);
    glUniform1f(program.uniform("uVplShadowBias"), static_cast<float>(params.getFloat("vpl_shadow_bias")));
    if (mShadowed > 0) glBindTextureUnit(7, mMaps.id());
}

} // namespace gis
