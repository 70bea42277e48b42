#include "gi/common/VplShadows.h"

#include <algorithm>

namespace gis {

VplShadowHandles::VplShadowHandles(const gl::Program& p)
    : enabled(p.optionalLocation("uVplShadows")), shadowed(p.optionalLocation("uVplShadowed")),
      far(p.optionalLocation("uVplShadowFar")), bias(p.optionalLocation("uVplShadowBias")),
      maps(p.optionalTextureUnit("uVplShadowMaps")) {}

VplShadows::MapProgram VplShadows::buildProgram(bool cutout) {
    std::vector<std::pair<std::string, std::string>> defines;
    if (cutout) defines.emplace_back("GIS_ALPHA_CUTOUT", "1");
    gl::Program p = gl::Program::build(
        {{GL_VERTEX_SHADER, "gi/common/vpl_shadow.vert"}, {GL_FRAGMENT_SHADER, "gi/common/vpl_shadow.frag"}},
        defines);
    MapProgram m{{}, p.location("uFirstVpl"), p.location("uFar"), p.storageBlock("VplBuffer")};
    m.program = std::move(p);
    return m;
}

VplShadows::VplShadows() : mProgram(buildProgram(false)) {
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
        // All layers attached: the vertex shader picks one per instance.
        mFbo = gl::Framebuffer::of("VPL shadow maps", {}, &mMaps);
        mSize = size;
        mLayers = layers;
    }
    {
        if (in.sceneCutsOut && !mCutoutProgram.program) mCutoutProgram = buildProgram(true);
        const MapProgram& program = in.sceneCutsOut ? mCutoutProgram : mProgram;
        gl::Pass pass(timer, "vpl_shadows");
        pass.target(mFbo, size, size).clearDepth().depthTest(GL_LESS);
        pass.use(program.program).set(program.firstVpl, 0).set(program.far, in.sceneExtent);
        pass.buffer(program.vpls, vpls);
        in.drawGeometry(program.program, layers);
    }
    mShadowed = shadowed;
    counters["vpl_shadowed"] = shadowed;
    return shadowed;
}

void VplShadows::bind(gl::Pass& pass, const VplShadowHandles& h, const FrameInputs& in,
                      const ParamSet& params) const {
    pass.set(h.enabled, mShadowed > 0 ? 1 : 0)
        .set(h.shadowed, mShadowed)
        .set(h.far, in.sceneExtent)
        .set(h.bias, static_cast<float>(params.getFloat("vpl_shadow_bias")));
    if (mShadowed > 0) pass.texture(h.maps, mMaps);
}

} // namespace gis
