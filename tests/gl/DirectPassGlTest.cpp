// The direct pass is built once per specular case (GIS_SPECULAR in shaders/render/lighting.glsl:
// diffuse only, GGX, Phong) because llvmpipe runs both sides of a branch on a uniform. Each case the
// renderer picks must draw what the program that tests the frame's uniforms draws: the test runs that
// program over the frame's own G-buffer and shadow maps and compares the two images.
#include <algorithm>
#include <cmath>
#include <vector>

#include "GlTestSupport.h"
#include "gl/Objects.h"
#include "gl/Shader.h"

using namespace gis;

namespace {

std::vector<float> readRgba(const gl::Texture& t, int w, int h) {
    std::vector<float> pixels(static_cast<size_t>(w) * h * 4);
    glGetTextureImage(t.id(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(pixels.size() * sizeof(float)),
                      pixels.data());
    return pixels;
}

struct DirectImages {
    std::vector<float> renderer; // the frame's own direct pass
    std::vector<float> perFrame; // the program that tests gFrame.shadingInfo
};

// Renders `scene` with `params` and draws the per-frame program over the frame's inputs, with the
// frame's uniform blocks still bound.
DirectImages directBothWays(const std::string& scene, const nlohmann::json& params, int w, int h) {
    test::renderScene(scene, "none", w, h, params);
    const FrameResources& res = test::sharedRenderer().resources();
    const gl::Program program = gl::Program::build(
        {{GL_VERTEX_SHADER, "render/fullscreen.vert"}, {GL_FRAGMENT_SHADER, "render/direct.frag"}});
    const gl::Texture target = gl::Texture::create2D(GL_RGBA32F, w, h);
    const gl::Framebuffer fbo = gl::Framebuffer::of("direct, per-frame program", {&target});
    const gl::VertexArray vao = gl::VertexArray::create();
    const std::pair<const char*, const char*> inputs[] = {
        {"gPosition", "gbuffer.position"}, {"gNormal", "gbuffer.normal"},
        {"gAlbedo", "gbuffer.albedo"},     {"gEmissive", "gbuffer.emissive"},
        {"gSpecular", "gbuffer.specular"}, {"gShadowMap", "lights.shadow"}};
    glUseProgram(program.id());
    for (const auto& [sampler, resource] : inputs)
        glBindTextureUnit(program.textureUnit(sampler).unit, res.get(resource).id());
    glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
    glViewport(0, 0, w, h);
    glDisable(GL_BLEND);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_STENCIL_TEST);
    glBindVertexArray(vao.id());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glFinish();
    return {readRgba(res.get("direct"), w, h), readRgba(target, w, h)};
}

double maxRelativeDifference(const std::vector<float>& a, const std::vector<float>& b) {
    double worst = 0;
    for (size_t i = 0; i < a.size(); ++i)
        worst = std::max(worst, std::abs(double(a[i]) - b[i]) / std::max(1e-3, std::abs(double(b[i]))));
    return worst;
}

double meanAbsDifference(const std::vector<float>& a, const std::vector<float>& b) {
    double sum = 0;
    for (size_t i = 0; i < a.size(); ++i) sum += std::abs(double(a[i]) - b[i]);
    return a.empty() ? 0 : sum / double(a.size());
}

TEST(DirectPass, EachSpecularCaseDrawsWhatThePerFrameProgramDraws) {
    test::sharedContext();
    constexpr int kW = 96, kH = 80;
    // gallery has specular materials (GGX by default, Phong on request); the Cornell box is diffuse.
    const DirectImages ggx = directBothWays("builtin:gallery", {}, kW, kH);
    const DirectImages phong = directBothWays("builtin:gallery", {{"specular_lobe", "phong"}}, kW, kH);
    const DirectImages diffuse = directBothWays("builtin:cornell", {}, kW, kH);
    EXPECT_LE(maxRelativeDifference(ggx.renderer, ggx.perFrame), 1e-5);
    EXPECT_LE(maxRelativeDifference(phong.renderer, phong.perFrame), 1e-5);
    EXPECT_LE(maxRelativeDifference(diffuse.renderer, diffuse.perFrame), 1e-5);
    // The lobes are really there: the two gallery frames differ where the surfaces are glossy.
    EXPECT_GT(meanAbsDifference(ggx.renderer, phong.renderer), 1e-4);
}

} // namespace
