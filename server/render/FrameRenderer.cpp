#include "render/FrameRenderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_transform.hpp>

#include "core/Error.h"
#include "core/Log.h"
#include "core/Timer.h"
#include "frame/LightModel.h"
#include "gl/Pass.h"
#include "gl/ShaderShared.h"

namespace gis {
namespace {

std::vector<std::uint8_t> readRgba8(const gl::Framebuffer& fbo, int attachment, int w, int h) {
    std::vector<std::uint8_t> pixels(static_cast<size_t>(w) * static_cast<size_t>(h) * 4);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo.id());
    glReadBuffer(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(attachment));
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
    // GL's rows run bottom to top; images everywhere else run top to bottom.
    const size_t row = static_cast<size_t>(w) * 4;
    std::vector<std::uint8_t> tmp(row);
    for (int y = 0; y < h / 2; ++y) {
        std::uint8_t* a = pixels.data() + static_cast<size_t>(y) * row;
        std::uint8_t* b = pixels.data() + static_cast<size_t>(h - 1 - y) * row;
        std::memcpy(tmp.data(), a, row);
        std::memcpy(a, b, row);
        std::memcpy(b, tmp.data(), row);
    }
    return pixels;
}

std::vector<float> readRgba32f(const gl::Framebuffer& fbo, int attachment, int w, int h) {
    std::vector<float> pixels(static_cast<size_t>(w) * static_cast<size_t>(h) * 4);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo.id());
    glReadBuffer(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(attachment));
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, pixels.data());
    const size_t row = static_cast<size_t>(w) * 4;
    std::vector<float> tmp(row);
    for (int y = 0; y < h / 2; ++y) {
        float* a = pixels.data() + static_cast<size_t>(y) * row;
        float* b = pixels.data() + static_cast<size_t>(h - 1 - y) * row;
        std::memcpy(tmp.data(), a, row * sizeof(float));
        std::memcpy(a, b, row * sizeof(float));
        std::memcpy(b, tmp.data(), row * sizeof(float));
    }
    return pixels;
}

} // namespace

void writeLightUniforms(const LightModel& light, shader::FrameUniforms& u) {
    u.lightViewProj = light.viewProj;
    u.lightPos = glm::vec4(light.position, light.intensity);
    u.lightDir = glm::vec4(light.axis, light.cosOuter);
    u.lightColor = glm::vec4(light.color, light.cosInner);
}

FrameRenderer::FrameRenderer(bool useTimerQueries) : mTimer(useTimerQueries) {
    const gl::ShaderStage meshVert{GL_VERTEX_SHADER, "render/mesh.vert"};
    const gl::ShaderStage fullscreen{GL_VERTEX_SHADER, "render/fullscreen.vert"};
    // The shadow map draws depth only: its program reads no material.
    enum class Materials { None, Used, All };
    auto meshPass = [&](const char* fragment, Materials materials) {
        MeshPass p{gl::Program::build({meshVert, {GL_FRAGMENT_SHADER, fragment}}), {}, {}};
        p.view = p.program.location("uView");
        if (materials != Materials::None)
            p.materials = MaterialSlots::of(p.program, materials == Materials::All);
        return p;
    };
    mShadowPass = meshPass("render/shadow.frag", Materials::None);
    mRsmPass = meshPass("render/rsm.frag", Materials::Used);
    mGBufferPass = meshPass("render/gbuffer.frag", Materials::All);
    mDirectPass.program = gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "render/direct.frag"}});
    const gl::Program& d = mDirectPass.program;
    mDirectPass.position = d.textureUnit("gPosition");
    mDirectPass.normal = d.textureUnit("gNormal");
    mDirectPass.albedo = d.textureUnit("gAlbedo");
    mDirectPass.emissive = d.textureUnit("gEmissive");
    mDirectPass.shadow = d.textureUnit("gShadowMap");
    mDirectPass.specular = d.textureUnit("gSpecular");
    mCompositePass.program = gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "render/composite.frag"}});
    const gl::Program& c = mCompositePass.program;
    mCompositePass.direct = c.textureUnit("gDirect");
    mCompositePass.indirect = c.textureUnit("gIndirect");
    mCompositePass.reflection = c.textureUnit("gReflection");
    mCompositePass.hasIndirect = c.location("uHasIndirect");
    mCompositePass.hasReflection = c.location("uHasReflection");
    mFrameUbo = gl::Buffer::create(sizeof(shader::FrameUniforms));
    mEmptyVao = gl::VertexArray::create();
    gl::checkErrors("renderer setup");
}

FrameRenderer::~FrameRenderer() = default;

void FrameRenderer::setScene(std::shared_ptr<const Scene> scene) {
    GIS_ASSERT(scene != nullptr);
    mSceneGpu = std::make_unique<SceneGpu>(*scene);
    mScene = std::move(scene);
}

void FrameRenderer::ensureTargets(int width, int height, int rsmSize, int shadowSize) {
    if (shadowSize != mShadowSize) {
        mShadowDepth = gl::Texture::create2D(GL_DEPTH_COMPONENT32F, shadowSize, shadowSize);
        mShadowDepth.setFilter(GL_LINEAR, GL_LINEAR); // hardware 2x2 PCF with the compare mode
        glTextureParameteri(mShadowDepth.id(), GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
        glTextureParameteri(mShadowDepth.id(), GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
        mShadowFbo = gl::Framebuffer::of("shadow map", {}, &mShadowDepth);
        mShadowSize = shadowSize;
    }
    if (rsmSize != mRsmSize) {
        mRsmPosition = gl::Texture::create2D(GL_RGBA32F, rsmSize, rsmSize);
        mRsmNormal = gl::Texture::create2D(GL_RGBA16F, rsmSize, rsmSize);
        mRsmFlux = gl::Texture::create2D(GL_RGBA32F, rsmSize, rsmSize);
        mRsmSpecular = gl::Texture::create2D(GL_RGBA8, rsmSize, rsmSize);
        mRsmDepth = gl::Texture::create2D(GL_DEPTH_COMPONENT32F, rsmSize, rsmSize);
        mRsmFbo = gl::Framebuffer::of("reflective shadow map",
                                      {&mRsmPosition, &mRsmNormal, &mRsmFlux, &mRsmSpecular}, &mRsmDepth);
        mRsmSize = rsmSize;
    }
    if (width != mWidth || height != mHeight) {
        mGPosition = gl::Texture::create2D(GL_RGBA32F, width, height);
        mGNormal = gl::Texture::create2D(GL_RGBA16F, width, height);
        mGAlbedo = gl::Texture::create2D(GL_RGBA8, width, height);
        mGEmissive = gl::Texture::create2D(GL_RGBA16F, width, height);
        mGSpecular = gl::Texture::create2D(GL_RGBA8, width, height);
        mGDepth = gl::Texture::create2D(GL_DEPTH_COMPONENT32F, width, height);
        mGBufferFbo = gl::Framebuffer::of(
            "G-buffer", {&mGPosition, &mGNormal, &mGAlbedo, &mGEmissive, &mGSpecular}, &mGDepth);
        mDirect = gl::Texture::create2D(GL_RGBA32F, width, height);
        mDirectFbo = gl::Framebuffer::of("direct light", {&mDirect});
        mDisplay = gl::Texture::create2D(GL_RGBA8, width, height);
        mLinear = gl::Texture::create2D(GL_RGBA32F, width, height);
        mCompositeFbo = gl::Framebuffer::of("composite", {&mDisplay, &mLinear});
        mWidth = width;
        mHeight = height;
    }
}

void FrameRenderer::ensureTechnique(const std::string& name, int width, int height) {
    if (!mTechnique || name != mTechniqueName) {
        mTechnique = findTechnique(name).create();
        mTechniqueName = name;
        mTechniqueWidth = mTechniqueHeight = 0;
    }
    if (width != mTechniqueWidth || height != mTechniqueHeight) {
        mTechnique->resize(width, height);
        mTechniqueWidth = width;
        mTechniqueHeight = height;
    }
}

void FrameRenderer::renderShadowMap(int light) {
    // Depth only, with a slope-scaled offset against acne.
    gl::Pass pass(mTimer, "shadow_map");
    pass.target(mShadowFbo, mShadowSize, mShadowSize)
        .depthTest(GL_LESS)
        .clearDepth()
        .polygonOffset(2.0f, 4.0f);
    pass.use(mShadowPass.program).set(mShadowPass.view, 1);
    mSceneGpu->draw(mShadowPass.program, nullptr);
    mResources.publish(FrameResources::light(light, "shadow"), "shadow_map", mShadowDepth);
}

void FrameRenderer::renderRsm(int light, int rsmSize) {
    gl::Pass pass(mTimer, "rsm");
    pass.target(mRsmFbo, rsmSize, rsmSize).depthTest(GL_LESS).clearColor(4).clearDepth();
    pass.use(mRsmPass.program).set(mRsmPass.view, 1);
    mSceneGpu->draw(mRsmPass.program, &mRsmPass.materials);
    mResources.publish(FrameResources::light(light, "rsm.position"), "rsm", mRsmPosition);
    mResources.publish(FrameResources::light(light, "rsm.normal"), "rsm", mRsmNormal);
    mResources.publish(FrameResources::light(light, "rsm.flux"), "rsm", mRsmFlux);
    mResources.publish(FrameResources::light(light, "rsm.specular"), "rsm", mRsmSpecular);
}

void FrameRenderer::renderGBuffer(int width, int height) {
    gl::Pass pass(mTimer, "gbuffer");
    pass.target(mGBufferFbo, width, height).depthTest(GL_LESS).clearColor(5).clearDepth();
    pass.use(mGBufferPass.program).set(mGBufferPass.view, 0);
    mSceneGpu->draw(mGBufferPass.program, &mGBufferPass.materials);
    mResources.publish("gbuffer.position", "gbuffer", mGPosition);
    mResources.publish("gbuffer.normal", "gbuffer", mGNormal);
    mResources.publish("gbuffer.albedo", "gbuffer", mGAlbedo);
    mResources.publish("gbuffer.emissive", "gbuffer", mGEmissive);
    mResources.publish("gbuffer.specular", "gbuffer", mGSpecular);
    mResources.publish("gbuffer.depth", "gbuffer", mGDepth);
}

void FrameRenderer::renderDirect() {
    // The viewport is the G-buffer's, set by the pass before.
    gl::Pass pass(mTimer, "direct");
    glBindFramebuffer(GL_FRAMEBUFFER, mDirectFbo.id());
    const DirectPass& d = mDirectPass;
    pass.use(d.program)
        .texture(d.position, mResources.get("gbuffer.position"))
        .texture(d.normal, mResources.get("gbuffer.normal"))
        .texture(d.albedo, mResources.get("gbuffer.albedo"))
        .texture(d.emissive, mResources.get("gbuffer.emissive"))
        .texture(d.shadow, mResources.get(FrameResources::light(0, "shadow")))
        .texture(d.specular, mResources.get("gbuffer.specular"));
    pass.drawFullscreen(mEmptyVao);
    mResources.publish("direct", "direct", mDirect);
}

void FrameRenderer::composite(int width, int height, const gl::Texture* indirect,
                              const gl::Texture* reflection) {
    gl::Pass pass(mTimer, "composite");
    const CompositePass& c = mCompositePass;
    const gl::Texture& direct = mResources.get("direct");
    pass.target(mCompositeFbo, width, height).use(c.program);
    pass.set(c.hasIndirect, indirect ? 1 : 0).set(c.hasReflection, reflection ? 1 : 0);
    pass.texture(c.direct, direct)
        .texture(c.indirect, indirect ? *indirect : direct)
        .texture(c.reflection, reflection ? *reflection : direct);
    pass.drawFullscreen(mEmptyVao);
    mResources.publish("display", "composite", mDisplay);
    mResources.publish("linear", "composite", mLinear);
}

FrameOutput FrameRenderer::render(const FrameState& state, bool wantLinear) {
    GIS_ASSERT(mSceneGpu != nullptr);
    GIS_ASSERT(state.width > 0 && state.height > 0);
    Stopwatch frameClock;
    const ParamSet& fp = state.frameParams;
    const int rsmSize = fp.getInt("rsm_size");
    ensureTargets(state.width, state.height, rsmSize, fp.getInt("shadow_map_size"));
    ensureTechnique(state.technique, state.width, state.height);
    const Reflections::Decision nonDiffuse =
        mReflections.decide(*mScene, *mSceneGpu, fp, mTechnique->glossyTransport(state.techniqueParams));

    // Frame uniforms.
    shader::FrameUniforms u{};
    const LightModel light = makeLightModel(state, mScene->bounds);
    const float tanHalf = light.tanHalfFov;
    u.viewProj = cameraViewProj(state.camera, state.width, state.height);
    u.cameraPos = glm::vec4(state.camera.position, 0.0f);
    const bool lightOn = light.on;
    writeLightUniforms(light, u);
    u.viewport = glm::vec4(state.width, state.height, 1.0f / state.width, 1.0f / state.height);
    u.rsmInfo = glm::vec4(rsmSize, tanHalf, mShadowSize, fp.getInt("pcf_radius"));
    u.toneInfo =
        glm::vec4(std::exp2(fp.getFloat("exposure")), fp.getEnum("tonemap") == "filmic" ? 1.0f : 0.0f,
                  lightOn ? 1.0f : 0.0f, fp.getEnum("rsm_solid_angle") == "equal" ? 1.0f : 0.0f);
    u.shadingInfo = glm::vec4(fp.getEnum("specular_lobe") == "phong" ? 1.0f : 0.0f,
                              fp.getFloat("glossy_split"), nonDiffuse.specular ? 1.0f : 0.0f, 0.0f);
    mFrameUbo.upload(0, sizeof u, &u);
    glBindBufferBase(GL_UNIFORM_BUFFER, GIS_UBO_FRAME, mFrameUbo.id());

    mTimer.beginFrame();
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    renderShadowMap(0);
    renderRsm(0, rsmSize);
    renderGBuffer(state.width, state.height);
    renderDirect();

    // The technique's indirect passes read the G-buffer, the RSM and the direct light by name.
    Counters counters;
    FrameInputs in;
    in.width = state.width;
    in.height = state.height;
    in.resources = &mResources;
    in.rsmSize = rsmSize;
    in.glossy = nonDiffuse.glossy;
    in.glossyMinRoughness = fp.getFloat("glossy_split");
    in.lightEnabled = lightOn;
    in.frame = &u;
    in.drawGeometry = [this](const gl::Program& program, int instances) {
        mSceneGpu->draw(program, nullptr, instances);
    };
    in.sceneExtent = std::max(glm::length(mScene->bounds.max - mScene->bounds.min), 1e-3f);
    mTechnique->execute(in, state.techniqueParams, mTimer, counters);
    glBindBufferBase(GL_UNIFORM_BUFFER, GIS_UBO_FRAME, mFrameUbo.id());
    const gl::Texture* indirect = mTechnique->indirect();
    if (indirect)
        mResources.publish("indirect", "technique", *indirect);
    else
        mResources.withdraw("indirect");

    // Reflections: environment probe and planar mirrors (docs/nondiffuse.md).
    ReflectionInputs rin;
    rin.width = state.width;
    rin.height = state.height;
    rin.resources = &mResources;
    rin.frame = &u;
    rin.scene = mScene.get();
    rin.sceneGpu = mSceneGpu.get();
    rin.envMaxRoughness = nonDiffuse.glossy ? fp.getFloat("glossy_split") : 1.01f;
    const gl::Texture* reflection = mReflections.execute(nonDiffuse, rin, fp, mTimer, counters);
    glBindBufferBase(GL_UNIFORM_BUFFER, GIS_UBO_FRAME, mFrameUbo.id());
    if (reflection)
        mResources.publish("reflection", "reflections", *reflection);
    else
        mResources.withdraw("reflection");

    composite(state.width, state.height, indirect, reflection);

    FrameOutput out;
    out.width = state.width;
    out.height = state.height;
    Stopwatch readClock;
    out.rgba8 = readRgba8(mCompositeFbo, 0, state.width, state.height);
    if (wantLinear) out.linear = readRgba32f(mCompositeFbo, 1, state.width, state.height);
    const double readbackMs = readClock.elapsedMs();
    std::vector<gl::PassTiming> passes = mTimer.resolve();
    gl::logErrors("frame");

    nlohmann::json passJson = nlohmann::json::array();
    for (const auto& p : passes)
        passJson.push_back({{"name", p.name}, {"gpu_ms", p.gpuMs}, {"cpu_ms", p.cpuMs}});
    nlohmann::json countJson = nlohmann::json::object();
    countJson["triangles"] = mSceneGpu->triangleCount();
    countJson["pixels"] = state.width * state.height;
    for (const auto& [k, v] : counters) countJson[k] = v;
    nlohmann::json params = paramsJson(state);
    out.stats = {{"technique", state.technique},
                 {"size", {state.width, state.height}},
                 {"frame_ms", frameClock.elapsedMs()},
                 {"readback_ms", readbackMs},
                 {"timing", mTimer.usesQueries() ? "gpu_query" : "cpu_finish"},
                 {"passes", std::move(passJson)},
                 {"counts", std::move(countJson)},
                 {"params", std::move(params)}};
    if (!state.plan.is_null()) out.stats["plan"] = state.plan;
    out.stats["nondiffuse"] = nonDiffuse.reasons;
    out.stats["lighting"] = {{"source", state.lightSource}, {"note", state.lightNote}};
    return out;
}

} // namespace gis
