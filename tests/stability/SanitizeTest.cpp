// NaN injection at the pass boundaries (digest S.4 case 5, issue #10): one G-buffer texel and one RSM
// texel forced to NaN must not propagate through the min-max / mean mip chains (eye hierarchy, SSBC,
// the light tree) into whole screen regions. The test copies a real frame's G-buffer, RSM and direct
// light, pokes the NaN into the copies and runs a fresh technique instance on them through the public
// Technique interface (FrameRenderer's API is unchanged); the clean copies give the reference.
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "StabilityLab.h"
#include "StabilityScenes.h"
#include "gi/Technique.h"
#include "gl/ShaderShared.h"
#include "frame/FrameState.h"

using namespace gis;
using namespace gis::stability;
namespace sc = gis::stability::scenes;

namespace {

// A copy of a 2D texture or of a 2D array (the light views' RSM layers), of the same kind.
gl::Texture copyOf(GLuint source) {
    GLint format = 0, w = 0, h = 0, layers = 0, target = 0;
    glGetTextureLevelParameteriv(source, 0, GL_TEXTURE_INTERNAL_FORMAT, &format);
    glGetTextureLevelParameteriv(source, 0, GL_TEXTURE_WIDTH, &w);
    glGetTextureLevelParameteriv(source, 0, GL_TEXTURE_HEIGHT, &h);
    glGetTextureLevelParameteriv(source, 0, GL_TEXTURE_DEPTH, &layers);
    glGetTextureParameteriv(source, GL_TEXTURE_TARGET, &target);
    if (target == GL_TEXTURE_2D_ARRAY) {
        gl::Texture t = gl::Texture::create2DArray(static_cast<GLenum>(format), w, h, layers);
        glCopyImageSubData(source, GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0, t.id(), GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0,
                           w, h, layers);
        return t;
    }
    gl::Texture t = gl::Texture::create2D(static_cast<GLenum>(format), w, h);
    glCopyImageSubData(source, GL_TEXTURE_2D, 0, 0, 0, 0, t.id(), GL_TEXTURE_2D, 0, 0, 0, 0, w, h, 1);
    return t;
}

// One texel of a 2D texture, or of layer 0 of an array.
void poke(const gl::Texture& t, int x, int y, const float rgba[4]) {
    GLint target = 0;
    glGetTextureParameteriv(t.id(), GL_TEXTURE_TARGET, &target);
    if (target == GL_TEXTURE_2D_ARRAY)
        glTextureSubImage3D(t.id(), 0, x, y, 0, 1, 1, 1, GL_RGBA, GL_FLOAT, rgba);
    else
        glTextureSubImage2D(t.id(), 0, x, y, 1, 1, GL_RGBA, GL_FLOAT, rgba);
}

struct Injection {
    bool gbuffer = false, rsm = false;
};

struct Result {
    Image indirect;
    size_t nonFiniteElsewhere = 0; ///< in every float texture but the injected inputs
    std::string first;
};

/// Runs a fresh `technique` on copies of the last frame's inputs, with the requested NaN texels.
Result runInjected(const std::string& technique, const RenderSpec& spec, const Frame& frame, Injection inj) {
    FrameRenderer& renderer = rendererFor(technique);
    const int w = spec.width, h = spec.height, rsm = frame.rsmFlux.width;
    const FrameTextures src = frameTextures(renderer);
    Result r;
    if (!src.gPosition || !src.rsmPosition || !src.direct) {
        ADD_FAILURE() << "frame textures not found by introspection";
        return r;
    }
    gl::Texture gPos = copyOf(src.gPosition), gNrm = copyOf(src.gNormal), gAlb = copyOf(src.gAlbedo);
    gl::Texture rPos = copyOf(src.rsmPosition), rNrm = copyOf(src.rsmNormal), rFlux = copyOf(src.rsmFlux);
    gl::Texture direct = copyOf(src.direct);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float nanPosition[4] = {nan, nan, nan, 1.0f}; // still marked covered / valid
    const float nanVector[4] = {nan, nan, nan, 0.0f};
    if (inj.gbuffer) {
        poke(gPos, w / 2, h / 2, nanPosition);
        poke(gNrm, w / 2, h / 2, nanVector);
    }
    if (inj.rsm) {
        poke(rPos, rsm / 2, rsm / 2, nanPosition);
        poke(rNrm, rsm / 2, rsm / 2, nanVector);
        poke(rFlux, rsm / 2, rsm / 2, nanVector);
    }
    // The frame uniforms the renderer left bound (it rebinds its block after the technique).
    GLint ubo = 0;
    glGetIntegeri_v(GL_UNIFORM_BUFFER_BINDING, GIS_UBO_FRAME, &ubo);
    shader::FrameUniforms u{};
    glGetNamedBufferSubData(static_cast<GLuint>(ubo), 0, sizeof u, &u);

    FrameResources resources;
    resources.publish("gbuffer.position", "test", gPos);
    resources.publish("gbuffer.normal", "test", gNrm);
    resources.publish("gbuffer.albedo", "test", gAlb);
    resources.publish("lights.rsm.position", "test", rPos);
    resources.publish("lights.rsm.normal", "test", rNrm);
    resources.publish("lights.rsm.flux", "test", rFlux);
    resources.publish("direct", "test", direct);
    FrameInputs in;
    in.width = w;
    in.height = h;
    in.resources = &resources;
    in.rsmSize = rsm;
    in.lightEnabled = true;
    in.lightViews = 1;
    // The light block too: the scene's one spot light has one view.
    GLint lightUbo = 0;
    glGetIntegeri_v(GL_UNIFORM_BUFFER_BINDING, GIS_UBO_LIGHTS, &lightUbo);
    auto lightBlock = std::make_unique<shader::LightUniforms>();
    glGetNamedBufferSubData(static_cast<GLuint>(lightUbo), 0, sizeof *lightBlock, lightBlock.get());
    in.lights = lightBlock.get();
    in.frame = &u;
    in.drawGeometry = [](const gl::Program&, int) {};
    in.sceneExtent = glm::length(spec.scene->bounds.max - spec.scene->bounds.min);

    FrameState state = makeFrameState(*spec.scene, technique);
    for (const auto& [k, v] : spec.params.items())
        if (state.techniqueParams.has(k)) state.techniqueParams.set(k, v, "test");
    std::unique_ptr<Technique> t = findTechnique(technique).create();
    t->resize(w, h);
    gl::PassTimer timer(false);
    timer.beginFrame();
    Counters counters;
    t->execute(in, state.techniqueParams, timer, counters);
    timer.resolve();
    r.indirect = readTexture(t->indirect()->id());
    r.nonFiniteElsewhere =
        countNonFiniteTextures({gPos.id(), gNrm.id(), rPos.id(), rNrm.id(), rFlux.id()}, &r.first);
    return r;
}

/// Pixels whose indirect radiance differs by more than 1% of the image's maximum.
double damagedFraction(const Image& clean, const Image& dirty) {
    double maxV = 0;
    for (float v : clean.rgba) maxV = std::max(maxV, double(v));
    size_t damaged = 0, n = clean.rgba.size() / 4;
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            const double a = clean.rgba[i * 4 + c], b = dirty.rgba[i * 4 + c];
            if (!std::isfinite(b) || std::abs(a - b) > 0.01 * maxV) {
                ++damaged;
                break;
            }
        }
    return n ? double(damaged) / double(n) : 0.0;
}

class Sanitize : public ::testing::TestWithParam<std::string> {
protected:
    void TearDown() override { endCell(HasFailure(), IsSkipped()); }
};

} // namespace

TEST_P(Sanitize, C05_InjectedNanTexels) {
    beginCell("C05_InjectedNan", GetParam());
    RenderSpec spec;
    spec.scene = sc::builtin("cornell");
    spec.technique = GetParam();
    // coarsest_size 1: the eye hierarchy reduces to a single texel, the longest chain a NaN can climb.
    spec.params = {{"coarsest_size", 1}, {"ssbc_iterations", GetParam() == "ssbc" ? 1 : 0}};
    const Frame frame = renderRaw(spec);
    const Result clean = runInjected(GetParam(), spec, frame, {});
    ASSERT_FALSE(clean.indirect.empty());
    ASSERT_EQ(clean.nonFiniteElsewhere, 0u) << clean.first;
    for (const auto& [name, inj] :
         {std::pair{"G-buffer", Injection{true, false}}, std::pair{"RSM", Injection{false, true}}}) {
        SCOPED_TRACE(name);
        const Result dirty = runInjected(GetParam(), spec, frame, inj);
        size_t nonFinite = 0;
        for (float v : dirty.indirect.rgba) nonFinite += !std::isfinite(v);
        EXPECT_EQ(nonFinite, 0u) << "NaN reached the technique's output";
        EXPECT_EQ(dirty.nonFiniteElsewhere, 0u)
            << "NaN propagated into an intermediate buffer: " << dirty.first;
        const double damaged = damagedFraction(clean.indirect, dirty.indirect);
        note(std::string(name) + " NaN: pixels changed > 1% (%)", 100.0 * damaged);
        // One bad texel may cost its own pixel and, through coarse receivers and the upsampling, its
        // neighbourhood, never whole screen regions.
        EXPECT_LT(damaged, 0.02) << "one NaN texel changed " << 100.0 * damaged << "% of the pixels";
    }
}

INSTANTIATE_TEST_SUITE_P(Techniques, Sanitize, ::testing::ValuesIn(vplTechniques()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });
