#include "render/FrameRenderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/common/ParamSpecs.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/Timer.h"
#include "frame/Exposure.h"
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

// The light views' tolerance for levels of detail, in texels of their maps (light_lod_texels' maximum):
// the shadow lookup offsets its point along the normal by one to two and a half shadow texels
// (shaders/render/lighting.glsl), so a surface simplified by up to one texel is still not shadowed by
// its own full mesh or by itself.
constexpr float kLightLodMaxTexels = 1.0f;

// What each light view tolerates of the levels of detail: `texels` of its side x side map. A
// perspective view's texel grows with distance from its eye; an orthographic view's is one size.
std::vector<LodView> lightViewLods(const LightSetModel& set, float texels, int side) {
    std::vector<LodView> lods;
    if (!(texels > 0.0f) || side <= 0) return lods;
    lods.reserve(set.views.size());
    for (const LightViewModel& v : set.views) {
        LodView lod;
        lod.eye = v.eye;
        const float perTexel = texels * 2.0f / static_cast<float>(side);
        if (v.orthographic)
            lod.errorAtEye = std::isfinite(v.halfWidth) ? perTexel * std::max(v.halfWidth, 0.0f) : 0.0f;
        else
            lod.errorPerMetre = std::isfinite(v.tanHalfFov) ? perTexel * std::max(v.tanHalfFov, 0.0f) : 0.0f;
        lods.push_back(lod);
    }
    return lods;
}

// Bands of rows in which refinement draws a light view larger than the default's, asking between
// them whether input arrived: as many as the side is a multiple of the default side (at most 16), so
// each costs about a default map (a 4096 shadow map took 25-35 ms and a 1024 RSM 25-40 ms as one
// stage on llvmpipe, the input waiting for it). The geometry is drawn once per band: the default
// sides, drawn whole, cost nothing more.
int lightViewBands(int side, int defaultSide) {
    return std::clamp(side / std::max(defaultSide, 1), 1, 16);
}

// Every layer of a light-view array (one framebuffer each, `side` texels): bound with a depth test,
// cleared by `clear`, and, the first `views` of them, drawn by `draw(pass, view)`. With `bands` above
// one (lightViewBands), each view's layer goes in that many bands of rows, scissored, and `stop` is
// asked between them. False when it said stop: the layers are then incomplete.
bool drawLayersInBands(const char* name, const std::vector<gl::Framebuffer>& fbos, int side, int views,
                       int bands, const std::function<bool()>& stop,
                       const std::function<void(gl::Pass&)>& clear,
                       const std::function<void(gl::Pass&, int)>& draw) {
    for (int v = 0; v < static_cast<int>(fbos.size()); ++v) {
        const int pieces = v < views ? bands : 1;
        for (int b = 0; b < pieces; ++b) {
            if (pieces > 1 && (v > 0 || b > 0) && stop()) return false;
            gl::Pass layer(name);
            layer.target(fbos[static_cast<size_t>(v)], side, side).depthTest(GL_LESS);
            if (pieces > 1)
                layer.scissor(0, side * b / pieces, side, side * (b + 1) / pieces - side * b / pieces);
            clear(layer);
            if (v < views) draw(layer, v);
        }
    }
    return true;
}

} // namespace

nlohmann::json lightingStats(const FrameState& state, const LightSetModel& set,
                             const std::vector<double>& viewFlux) {
    nlohmann::json rendered = nlohmann::json::array();
    std::vector<std::string> dark;
    for (const LightModel& l : set.lights) {
        const char* type = l.type == LightType::Spot    ? "spot"
                           : l.type == LightType::Point ? "point"
                                                        : "directional";
        nlohmann::json entry = {{"id", l.id}, {"name", l.name}, {"type", type}, {"views", l.viewCount}};
        if (!viewFlux.empty()) {
            double flux = 0.0;
            for (int v = l.firstView; v < l.firstView + l.viewCount && v < static_cast<int>(viewFlux.size());
                 ++v)
                flux += viewFlux[static_cast<size_t>(v)];
            entry["reflected_flux"] = flux;
            if (!(flux > 0.0)) dark.push_back("light '" + l.name + "' (" + l.id + ")");
        }
        rendered.push_back(std::move(entry));
    }
    nlohmann::json out = {
        {"source", state.lightSource},     {"note", state.lightNote}, {"exposure", baseExposureJson(state)},
        {"rendered", std::move(rendered)}, {"skipped", set.skipped},  {"views", set.views.size()},
        {"shadow_side", set.shadowSide},   {"rsm_side", set.rsmSide}};
    if (set.lights.empty()) {
        out["warning"] = state.lights.empty()
                             ? "there are no lights: the view shows emission only"
                             : "none of the lights is rendered (see skipped): the view shows "
                               "emission only";
    } else if (!dark.empty()) {
        // Measured from the RSMs: no surface reflects such a light (it points into empty space, its cone
        // or range misses everything, or all it reaches is black).
        std::string names;
        for (const std::string& d : dark) names += (names.empty() ? "" : ", ") + d;
        out["warning"] = std::string(dark.size() == set.lights.size() ? "no surface reflects any light"
                                                                      : "no surface reflects") +
                         ": " + names + " (pointing into empty space, or at black surfaces only?)";
    }
    return out;
}

static_assert(kMaxLights == GIS_MAX_LIGHTS, "max_lights' maximum is the light block's capacity");

void writeLightUniforms(const LightSetModel& set, shader::LightUniforms& u) {
    const int lights = std::min(static_cast<int>(set.lights.size()), GIS_MAX_LIGHTS);
    const int views = std::min(static_cast<int>(set.views.size()), GIS_MAX_LIGHT_VIEWS);
    for (int i = 0; i < lights; ++i) {
        const LightModel& l = set.lights[static_cast<size_t>(i)];
        shader::GpuLight& g = u.lights[i];
        const float type = l.type == LightType::Spot    ? GIS_LIGHT_SPOT
                           : l.type == LightType::Point ? GIS_LIGHT_POINT
                                                        : GIS_LIGHT_DIRECTIONAL;
        g.position = glm::vec4(l.position, l.intensity);
        g.direction = glm::vec4(l.axis, l.cosOuter);
        g.color = glm::vec4(l.color, l.cosInner);
        g.info = glm::vec4(type, l.range, static_cast<float>(l.firstView), static_cast<float>(l.viewCount));
    }
    for (int v = 0; v < views; ++v) {
        const LightViewModel& m = set.views[static_cast<size_t>(v)];
        shader::LightView& g = u.views[v];
        g.viewProj = m.viewProj;
        g.eye = glm::vec4(m.eye, static_cast<float>(m.light));
        g.info = glm::vec4(m.orthographic ? 1.0f : 0.0f, m.orthographic ? m.halfWidth : m.tanHalfFov,
                           static_cast<float>(m.face), 0.0f);
        g.axis = glm::vec4(m.axis, 0.0f);
    }
    u.counts = glm::ivec4(lights, views, 0, 0);
}

FrameRenderer::MeshPass FrameRenderer::buildMeshPass(const char* fragment, MeshMaterials materials,
                                                     bool cutout, bool plain) {
    const gl::ShaderStage meshVert{GL_VERTEX_SHADER, "render/mesh.vert"};
    std::vector<std::pair<std::string, std::string>> defines;
    if (cutout) defines.emplace_back("GIS_ALPHA_CUTOUT", "1");
    if (plain) defines.emplace_back("GIS_MATERIAL_PLAIN", "1");
    MeshPass p{gl::Program::build({meshVert, {GL_FRAGMENT_SHADER, fragment}}, defines), {}, {}};
    p.view = p.program.location("uView");
    // A cut-out shadow map reads the base colour's alpha: it needs the materials too.
    if (materials != MeshMaterials::None || cutout)
        p.materials = MaterialSlots::of(p.program, materials == MeshMaterials::All);
    return p;
}

FrameRenderer::FrameRenderer(bool useTimerQueries) : mTimer(useTimerQueries) {
    const gl::ShaderStage fullscreen{GL_VERTEX_SHADER, "render/fullscreen.vert"};
    // The shadow map draws depth only: its program reads no material.
    mShadowPass = buildMeshPass("render/shadow.frag", MeshMaterials::None, false);
    // Diffuse only, GGX, Phong: the order of mDirectCase.
    const char* const specularCases[3] = {"GIS_SPECULAR_OFF", "GIS_LOBE_GGX", "GIS_LOBE_PHONG"};
    for (size_t k = 0; k < mDirectPasses.size(); ++k) {
        DirectPass& d = mDirectPasses[k];
        d.program = gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "render/direct.frag"}},
                                       {{"GIS_SPECULAR", specularCases[k]}});
        d.position = d.program.textureUnit("gPosition");
        d.normal = d.program.textureUnit("gNormal");
        d.albedo = d.program.textureUnit("gAlbedo");
        d.emissive = d.program.textureUnit("gEmissive");
        d.shadow = d.program.textureUnit("gShadowMap");
        d.specular = d.program.optionalTextureUnit("gSpecular"); // unused without a specular lobe
    }
    for (size_t reflection = 0; reflection < mCompositePasses.size(); ++reflection) {
        CompositePass& c = mCompositePasses[reflection];
        c.program = gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "render/composite.frag"}},
                                       {{"GIS_COMPOSITE_REFLECTION", reflection ? "1" : "0"}});
        c.direct = c.program.textureUnit("gDirect");
        c.indirect = c.program.textureUnit("gIndirect");
        c.reflection = reflection ? c.program.textureUnit("gReflection") : gl::TextureUnit{gl::kNoUnit};
        c.hasIndirect = c.program.location("uHasIndirect");
        c.albedo = c.program.textureUnit("gAlbedo");
        c.applyOcclusion = c.program.location("uApplyOcclusion");
    }
    mPartAverage.program =
        gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "render/vpl_part_average.frag"}});
    mPartAverage.part = mPartAverage.program.textureUnit("gPart");
    mPartAverage.weight = mPartAverage.program.location("uWeight");
    mFluxPass.program = gl::Program::build({{GL_COMPUTE_SHADER, "render/rsm_flux.comp"}});
    mFluxPass.rsmSize = mFluxPass.program.location("uRsmSize");
    mFluxPass.position = mFluxPass.program.textureUnit("gRsmPosition");
    mFluxPass.flux = mFluxPass.program.textureUnit("gRsmFlux");
    mFluxPass.sums = mFluxPass.program.storageBlock("ViewFlux");
    mFluxSums = gl::Buffer::create(GIS_MAX_LIGHT_VIEWS * sizeof(float));
    mFrameUbo = gl::Buffer::create(sizeof(shader::FrameUniforms));
    mLightUbo = gl::Buffer::create(sizeof(shader::LightUniforms));
    mLightBlock = std::make_unique<shader::LightUniforms>();
    mEmptyVao = gl::VertexArray::create();
    gl::checkErrors("renderer setup");
}

FrameRenderer::~FrameRenderer() = default;

void FrameRenderer::setScene(std::shared_ptr<const Scene> scene,
                             std::shared_ptr<const SceneGpu::Prepared> prepared) {
    GIS_ASSERT(scene != nullptr);
    auto gpu = std::make_unique<SceneGpu>(*scene, std::move(prepared));
    setScene(std::move(scene), std::move(gpu));
}

void FrameRenderer::setScene(std::shared_ptr<const Scene> scene, std::unique_ptr<SceneGpu> uploaded) {
    GIS_ASSERT(scene != nullptr && uploaded != nullptr && uploaded->complete());
    const bool cutsOut = std::any_of(scene->materials.begin(), scene->materials.end(),
                                     [](const Material& m) { return m.cutsOut(); });
    const bool plain = std::none_of(scene->materials.begin(), scene->materials.end(),
                                    [](const Material& m) { return m.hasMaps(); }) &&
                       std::all_of(scene->meshes.begin(), scene->meshes.end(),
                                   [](const Mesh& m) { return m.colors.empty(); });
    // The scene's programs first, each kind built once: a build that throws leaves the renderer as
    // it was.
    std::unique_ptr<MaterialPasses>& materials = plain ? mPlainPasses : mMappedPasses;
    if (!cutsOut && !materials)
        materials = std::make_unique<MaterialPasses>(
            MaterialPasses{buildMeshPass("render/rsm.frag", MeshMaterials::Used, false, plain),
                           buildMeshPass("render/gbuffer.frag",
                                         plain ? MeshMaterials::Used : MeshMaterials::All, false, plain)});
    if (cutsOut && !mCutoutPasses)
        mCutoutPasses = std::make_unique<CutoutPasses>(
            CutoutPasses{buildMeshPass("render/shadow.frag", MeshMaterials::None, true),
                         buildMeshPass("render/rsm.frag", MeshMaterials::Used, true),
                         buildMeshPass("render/gbuffer.frag", MeshMaterials::All, true)});
    mSceneGpu = std::move(uploaded);
    mSceneCutsOut = cutsOut;
    mScenePlain = plain;
    mSceneHasOcclusionMaps = std::any_of(scene->materials.begin(), scene->materials.end(),
                                         [](const Material& m) { return m.occlusionTexture >= 0; });
    // The scene's stats.not_shown, built once: every frame carries it.
    mNotShown = nlohmann::json::array();
    for (const NotShown& n : scene->notShown)
        mNotShown.push_back({{"feature", n.feature}, {"detail", n.detail}});
    mScene = std::move(scene);
    mLightPassesValid = false;
    mPartAverage.averaged = 0; // no part of another scene's image follows
}

template <class Maps>
std::optional<Maps> FrameRenderer::makeLightMaps(gl::BackgroundMaker<std::pair<int, int>, Maps>& maker,
                                                 std::pair<int, int> shape,
                                                 const std::function<bool()>& stop) {
    // On llvmpipe 13 views' 512^2 RSMs (164 MB) took 85-97 ms to make, one call that held input.
    std::optional<Maps> made =
        maker.make(shape, Maps::bytes(shape.first, shape.second), mBackgroundBytes, stop,
                   [shape] { return Maps::makeTextures(shape.first, shape.second); });
    if (!made) return std::nullopt;
    made->attach();
    ++mLightMapsCreated;
    return made;
}

bool FrameRenderer::ensureTargets(int width, int height, int rsmSide, int shadowSide, int views,
                                  int askedRsmSide, int askedShadowSide, const std::function<bool()>& stop) {
    // At least one layer, so that the shadow and RSM resources exist (and read as empty) with no light.
    const int layers = std::max(views, 1);
    // The maps of the side drawn before stay kept (mOtherShadow, mOtherRsm): interactive frames'
    // capped light views and refinement's asked ones alternate. The asked ones are kept whatever
    // their size, as the next refinement draws them again (13 point-lamp views' 512^2 RSMs, 164 MB,
    // were made again in each refinement after a drag); other ones up to kKeptLightMapBytes.
    const auto shape = [](int side, int count) { return std::pair{side, count}; };
    mOtherShadow.setMaxKeptCost(std::max(kKeptLightMapBytes, ShadowMaps::bytes(askedShadowSide, layers)));
    mOtherRsm.setMaxKeptCost(std::max(kKeptLightMapBytes, Rsms::bytes(askedRsmSide, layers)));
    // A stop while new maps are made leaves the current ones in place (a stop while the RSMs are
    // made keeps the shadow maps just made: the light views are drawn again after a change anyway).
    if (shadowSide != mShadowSize || layers != mShadowLayers) {
        std::optional<ShadowMaps> made;
        if (!mOtherShadow.holds(shape(shadowSide, layers)) &&
            !(made = makeLightMaps(mShadowMaker, shape(shadowSide, layers), stop)))
            return false;
        mShadow = mOtherShadow.exchange(shape(shadowSide, layers),
                                        mShadowSize > 0 ? std::optional(shape(mShadowSize, mShadowLayers))
                                                        : std::nullopt,
                                        std::move(mShadow), ShadowMaps::bytes(mShadowSize, mShadowLayers),
                                        [&] { return std::move(*made); });
        mShadowSize = shadowSide;
        mShadowLayers = layers;
        mLightPassesValid = false;
    }
    if (rsmSide != mRsmSize || layers != mRsmLayers) {
        std::optional<Rsms> made;
        if (!mOtherRsm.holds(shape(rsmSide, layers)) &&
            !(made = makeLightMaps(mRsmMaker, shape(rsmSide, layers), stop)))
            return false;
        mRsm = mOtherRsm.exchange(
            shape(rsmSide, layers), mRsmSize > 0 ? std::optional(shape(mRsmSize, mRsmLayers)) : std::nullopt,
            std::move(mRsm), Rsms::bytes(mRsmSize, mRsmLayers), [&] { return std::move(*made); });
        mRsmSize = rsmSide;
        mRsmLayers = layers;
        mLightPassesValid = false;
    }
    if (width != mWidth || height != mHeight) {
        // A size used before takes its targets back (the budget's sizes recur): no allocation and
        // no first touch of fresh memory on the frame.
        mScreen = mRecentScreens.exchange({width, height},
                                          mWidth > 0 ? std::optional<std::pair<int, int>>({mWidth, mHeight})
                                                     : std::nullopt,
                                          std::move(mScreen), static_cast<double>(mWidth) * mHeight,
                                          [&] { return ScreenTargets::create(width, height); });
        mWidth = width;
        mHeight = height;
    }
    return true;
}

FrameRenderer::ShadowMaps FrameRenderer::ShadowMaps::makeTextures(int side, int layers) {
    ShadowMaps m;
    m.depth = gl::Texture::create2DArray(GL_DEPTH_COMPONENT32F, side, side, layers);
    m.depth.setFilter(GL_LINEAR, GL_LINEAR); // hardware 2x2 PCF with the compare mode
    glTextureParameteri(m.depth.id(), GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTextureParameteri(m.depth.id(), GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    return m;
}

void FrameRenderer::ShadowMaps::attach() {
    for (int v = 0; v < depth.layers(); ++v)
        fbos.push_back(gl::Framebuffer::ofLayer("shadow map", {}, &depth, v));
}

FrameRenderer::Rsms FrameRenderer::Rsms::makeTextures(int side, int layers) {
    Rsms m;
    m.position = gl::Texture::create2DArray(GL_RGBA32F, side, side, layers);
    m.normal = gl::Texture::create2DArray(GL_RGBA16F, side, side, layers);
    m.flux = gl::Texture::create2DArray(GL_RGBA32F, side, side, layers);
    m.specular = gl::Texture::create2DArray(GL_RGBA8, side, side, layers);
    m.depth = gl::Texture::create2DArray(GL_DEPTH_COMPONENT32F, side, side, layers);
    return m;
}

void FrameRenderer::Rsms::attach() {
    for (int v = 0; v < depth.layers(); ++v)
        fbos.push_back(gl::Framebuffer::ofLayer("reflective shadow map",
                                                {&position, &normal, &flux, &specular}, &depth, v));
}

FrameRenderer::ScreenTargets FrameRenderer::ScreenTargets::create(int width, int height) {
    ScreenTargets t;
    t.gPosition = gl::Texture::create2D(GL_RGBA32F, width, height);
    t.gNormal = gl::Texture::create2D(GL_RGBA16F, width, height);
    t.gAlbedo = gl::Texture::create2D(GL_RGBA8, width, height);
    t.gEmissive = gl::Texture::create2D(GL_RGBA16F, width, height);
    t.gSpecular = gl::Texture::create2D(GL_RGBA8, width, height);
    t.gDepth = gl::Texture::create2D(GL_DEPTH_COMPONENT32F, width, height);
    t.gBufferFbo = gl::Framebuffer::of(
        "G-buffer", {&t.gPosition, &t.gNormal, &t.gAlbedo, &t.gEmissive, &t.gSpecular}, &t.gDepth);
    t.direct = gl::Texture::create2D(GL_RGBA32F, width, height);
    t.directFbo = gl::Framebuffer::of("direct light", {&t.direct});
    t.display = gl::Texture::create2D(GL_RGBA8, width, height);
    t.linear = gl::Texture::create2D(GL_RGBA32F, width, height);
    t.compositeFbo = gl::Framebuffer::of("composite", {&t.display, &t.linear});
    return t;
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

DrawCount FrameRenderer::renderShadowMaps(int views, std::span<const LodView> lods,
                                          const std::function<bool()>& stop) {
    // Depth only, with a slope-scaled offset against acne; layers without a view are cleared (lit).
    gl::Pass pass(mTimer, "shadow_map");
    DrawCount count;
    const int bands = stop ? lightViewBands(mShadowSize, lightViewDefaults().shadowSide) : 1;
    const bool whole = drawLayersInBands(
        "shadow_map view", mShadow.fbos, mShadowSize, views, bands, stop,
        [](gl::Pass& layer) { layer.clearDepth(); },
        [&](gl::Pass& layer, int v) {
            layer.polygonOffset(2.0f, 4.0f);
            const MeshPass& shadow = shadowPass();
            layer.use(shadow.program).set(shadow.view, v);
            count += mSceneGpu->draw(shadow.program, mSceneCutsOut ? &shadow.materials : nullptr, 1, -1,
                                     &mLightBlock->views[v].viewProj, false,
                                     static_cast<size_t>(v) < lods.size() ? &lods[static_cast<size_t>(v)]
                                                                          : nullptr);
        });
    if (whole) mResources.publish("lights.shadow", "shadow_map", mShadow.depth);
    return count;
}

DrawCount FrameRenderer::renderRsms(int views, std::span<const LodView> lods,
                                    const std::function<bool()>& stop) {
    gl::Pass pass(mTimer, "rsm");
    DrawCount count;
    const int bands = stop ? lightViewBands(mRsmSize, lightViewDefaults().rsmSide) : 1;
    const bool whole = drawLayersInBands(
        "rsm view", mRsm.fbos, mRsmSize, views, bands, stop,
        [](gl::Pass& layer) { layer.clearColor(4).clearDepth(); },
        [&](gl::Pass& layer, int v) {
            const MeshPass& rsm = rsmPass();
            layer.use(rsm.program).set(rsm.view, v);
            count += mSceneGpu->draw(
                rsm.program, &rsm.materials, 1, -1, &mLightBlock->views[v].viewProj, false,
                static_cast<size_t>(v) < lods.size() ? &lods[static_cast<size_t>(v)] : nullptr);
        });
    if (!whole) return count;
    mResources.publish("lights.rsm.position", "rsm", mRsm.position);
    mResources.publish("lights.rsm.normal", "rsm", mRsm.normal);
    mResources.publish("lights.rsm.flux", "rsm", mRsm.flux);
    mResources.publish("lights.rsm.specular", "rsm", mRsm.specular);
    return count;
}

void FrameRenderer::measureViewFlux(int views) {
    if (views <= 0) return;
    gl::Pass pass(mTimer, "rsm_flux");
    pass.use(mFluxPass.program).set(mFluxPass.rsmSize, mRsmSize);
    pass.texture(mFluxPass.position, mRsm.position).texture(mFluxPass.flux, mRsm.flux);
    pass.buffer(mFluxPass.sums, mFluxSums);
    pass.dispatch(views).barrier(GL_BUFFER_UPDATE_BARRIER_BIT);
}

std::vector<double> FrameRenderer::readViewFlux(int views) const {
    if (views <= 0) return {};
    std::vector<float> sums(static_cast<size_t>(views), 0.0f);
    glGetNamedBufferSubData(mFluxSums.id(), 0, static_cast<GLsizeiptr>(sums.size() * sizeof(float)),
                            sums.data());
    std::vector<double> out(sums.begin(), sums.end());
    for (double& f : out)
        if (!std::isfinite(f) || f < 0.0) f = 0.0;
    return out;
}

DrawCount FrameRenderer::renderGBuffer(int width, int height, const glm::mat4& viewProj, const LodView& lod) {
    gl::Pass pass(mTimer, "gbuffer");
    pass.target(mScreen.gBufferFbo, width, height).depthTest(GL_LESS).clearColor(5).clearDepth();
    const MeshPass& gbuffer = gbufferPass();
    pass.use(gbuffer.program).set(gbuffer.view, -1);
    const DrawCount count =
        mSceneGpu->draw(gbuffer.program, &gbuffer.materials, 1, -1, &viewProj, true, &lod);
    publishGBuffer();
    return count;
}

void FrameRenderer::publishGBuffer() {
    mResources.publish("gbuffer.position", "gbuffer", mScreen.gPosition);
    mResources.publish("gbuffer.normal", "gbuffer", mScreen.gNormal);
    mResources.publish("gbuffer.albedo", "gbuffer", mScreen.gAlbedo);
    mResources.publish("gbuffer.emissive", "gbuffer", mScreen.gEmissive);
    mResources.publish("gbuffer.specular", "gbuffer", mScreen.gSpecular);
    mResources.publish("gbuffer.depth", "gbuffer", mScreen.gDepth);
}

void FrameRenderer::renderDirect() {
    // The viewport is the G-buffer's, set by the pass before.
    gl::Pass pass(mTimer, "direct");
    glBindFramebuffer(GL_FRAMEBUFFER, mScreen.directFbo.id());
    const DirectPass& d = mDirectPasses[mDirectCase];
    pass.use(d.program)
        .texture(d.position, mResources.get("gbuffer.position"))
        .texture(d.normal, mResources.get("gbuffer.normal"))
        .texture(d.albedo, mResources.get("gbuffer.albedo"))
        .texture(d.emissive, mResources.get("gbuffer.emissive"))
        .texture(d.shadow, mResources.get("lights.shadow"))
        .texture(d.specular, mResources.get("gbuffer.specular"));
    pass.drawFullscreen(mEmptyVao);
    mResources.publish("direct", "direct", mScreen.direct);
}

void FrameRenderer::composite(int width, int height, const gl::Texture* indirect,
                              const gl::Texture* reflection, bool applyOcclusion) {
    gl::Pass pass(mTimer, "composite");
    const CompositePass& c = mCompositePasses[reflection ? 1 : 0];
    const gl::Texture& direct = mResources.get("direct");
    pass.target(mScreen.compositeFbo, width, height).use(c.program);
    pass.set(c.hasIndirect, indirect ? 1 : 0).set(c.applyOcclusion, indirect && applyOcclusion ? 1 : 0);
    pass.texture(c.direct, direct)
        .texture(c.indirect, indirect ? *indirect : direct)
        .texture(c.reflection, reflection ? *reflection : direct)
        .texture(c.albedo, mResources.get("gbuffer.albedo"));
    pass.drawFullscreen(mEmptyVao);
    mResources.publish("display", "composite", mScreen.display);
    mResources.publish("linear", "composite", mScreen.linear);
}

std::array<int, 7> FrameRenderer::partKey(const FrameState& state) {
    return {state.width,        state.height,           state.window.x,
            state.window.y,     state.window.fullWidth, state.window.fullHeight,
            state.vplPart.count};
}

bool FrameRenderer::followsLastPart(const FrameState& state, const glm::mat4& viewProj) const {
    const PartAverage& a = mPartAverage;
    return state.vplPart.index > 0 && a.averaged == state.vplPart.index && a.width == state.width &&
           a.height == state.height && partKey(state) == a.key && viewProj == a.viewProj &&
           state.techniqueParams.toJson() == a.techniqueParams;
}

const gl::Texture& FrameRenderer::averageVplPart(const FrameState& state, const glm::mat4& viewProj,
                                                 bool followsLast, const gl::Texture& part,
                                                 Counters& counters) {
    PartAverage& a = mPartAverage;
    if (a.width != state.width || a.height != state.height) {
        a.mean = gl::Texture::create2D(GL_RGBA32F, state.width, state.height);
        a.fbo = gl::Framebuffer::of("VPL part mean", {&a.mean});
        a.width = state.width;
        a.height = state.height;
        a.averaged = 0;
    }
    // Part 0 starts a mean; so does a part that does not follow the ones in it (another image, or a
    // part left out), which then shows the parts it has rather than mixing two images.
    if (!followsLast) a.averaged = 0;
    a.key = partKey(state);
    a.viewProj = viewProj;
    a.techniqueParams = state.techniqueParams.toJson();
    a.frameParams = state.frameParams.toJson();
    {
        gl::Pass pass(mTimer, "vpl_part_average");
        pass.target(a.fbo, state.width, state.height)
            .use(a.program)
            .texture(a.part, part)
            .set(a.weight, 1.0f / static_cast<float>(a.averaged + 1))
            .blend(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ZERO);
        pass.drawFullscreen(mEmptyVao);
    }
    ++a.averaged;
    counters["vpl_parts_averaged"] = a.averaged;
    return a.mean;
}

void FrameRenderer::setSceneLevels(std::shared_ptr<const SceneGpu::LodSet> levels) {
    GIS_ASSERT(mSceneGpu != nullptr);
    mSceneGpu->setLevels(std::move(levels));
}

bool FrameRenderer::sceneHasLevels() const {
    return mSceneGpu && mSceneGpu->hasLevels();
}

float FrameRenderer::lightLodTexelsOf(const FrameState& state) const {
    const float wanted = std::clamp(static_cast<float>(state.frameParams.getFloat("light_lod_texels")), 0.0f,
                                    kLightLodMaxTexels);
    return mSceneGpu && mSceneGpu->hasLevels() ? wanted : 0.0f;
}

glm::vec2 FrameRenderer::lightPassKey(const FrameState& state) {
    return {state.frameParams.getEnum("rsm_solid_angle") == "equal" ? 1.0f : 0.0f,
            findTechniqueInfo(state.technique).readsRsm ? 1.0f : 0.0f};
}

KeptLightViews FrameRenderer::keptLightViews(const FrameState& state,
                                             const shader::LightUniforms& lights) const {
    return {mReuseLightPasses && mLightPassesValid && mLightPassBlock &&
                lightPassKey(state) == mLightPassKey && mLightPassLodTexels <= lightLodTexelsOf(state) &&
                std::memcmp(mLightPassBlock.get(), &lights, sizeof lights) == 0,
            mLightPassShadowSide, mLightPassRsmSide};
}

bool FrameRenderer::keepsLightViews(const FrameState& state) {
    if (!mScene || !mSceneGpu || !mLightPassesValid) return false;
    const LightSetModel set = makeLightSet(state, mScene->bounds);
    if (!mQueryLightBlock) mQueryLightBlock = std::make_unique<shader::LightUniforms>();
    *mQueryLightBlock = shader::LightUniforms{};
    writeLightUniforms(set, *mQueryLightBlock);
    // Under whatever cap the budget then sets: kept maps of any side up to the asked serve.
    return lightViewSides(set.shadowSide, set.rsmSide, 1, 1, findTechniqueInfo(state.technique).readsRsm,
                          keptLightViews(state, *mQueryLightBlock))
        .keep;
}

bool FrameRenderer::wantsLevels(const FrameState& state) {
    return state.frameParams.getFloat("lod_pixels") > 0.0 ||
           state.frameParams.getFloat("light_lod_texels") > 0.0;
}

FrameOutput FrameRenderer::render(const FrameState& state, bool wantLinear, bool wantDirect) {
    GIS_ASSERT(mSceneGpu != nullptr);
    GIS_ASSERT(state.width > 0 && state.height > 0);
    Stopwatch frameClock;
    const ParamSet& fp = state.frameParams;
    LightSetModel lightSet = makeLightSet(state, mScene->bounds);
    const int views = static_cast<int>(lightSet.views.size());
    shader::LightUniforms& lights = *mLightBlock;
    lights = shader::LightUniforms{};
    writeLightUniforms(lightSet, lights);
    if (mLevelsOnDemand && wantsLevels(state) && !mSceneGpu->hasLevels())
        mSceneGpu->setLevels(SceneGpu::prepareLevels(*mScene));

    // The light views depend on the lights, the scene and the RSM's solid-angle rule only, never on
    // the camera: with reuse on, an unchanged light block keeps last frame's maps (an orbit or the
    // tiles of one refinement step render them once). Maps drawn at a finer level of detail than this
    // frame tolerates serve it as well; coarser ones never serve a frame that asks for more detail
    // (an API render after a live view's light drag). An interactive frame's cap (FrameState::
    // LightViewCap) draws them smaller and lets kept maps of any side between it and the asked serve.
    const bool readsRsm = findTechniqueInfo(state.technique).readsRsm;
    const float solidAngleEqual = fp.getEnum("rsm_solid_angle") == "equal" ? 1.0f : 0.0f;
    const float lightLodTexels = lightLodTexelsOf(state);
    const glm::vec2 lightKey = lightPassKey(state);
    const KeptLightViews kept = keptLightViews(state, lights);
    const int askedShadowSide = lightSet.shadowSide, askedRsmSide = lightSet.rsmSide;
    const LightViewSides sides = lightViewSides(askedShadowSide, askedRsmSide, state.lightViewCap.shadowSide,
                                                state.lightViewCap.rsmSide, readsRsm, kept);
    const bool reuseLights = sides.keep;
    lightSet.shadowSide = sides.shadow;
    lightSet.rsmSide = sides.rsm;
    // Refinement's interruption (setInterruptCheck): latched, so that the technique's checks and the
    // renderer's agree once it said stop. The work queued so far is finished before the check is
    // asked: GL work once queued runs to its end (llvmpipe rasterises a pass when a later one reads
    // its target), so a check asked before it would stop the frame one stage later than it seems
    // and leave that stage to delay the frame that answers the input.
    bool stopAsked = false;
    auto interrupted = [&] {
        if (!stopAsked && mInterruptCheck) {
            glFinish();
            stopAsked = mInterruptCheck();
        }
        return stopAsked;
    };
    // What an interrupted frame drew is not kept: redrawn light views and environment cubes are marked
    // stale before they are drawn, and the VPL parts' mean follows only a frame that completed (a
    // frame that does not follow it resets it before drawing over the G-buffer it keeps).
    auto interruptedOutput = [&] {
        FrameOutput out;
        out.width = state.width;
        out.height = state.height;
        out.interrupted = true;
        return out;
    };

    mLightMapsCreated = 0;
    // Maps too large to make within a slice are made in the background while input is asked.
    if (!ensureTargets(state.width, state.height, lightSet.rsmSide, lightSet.shadowSide, views, askedRsmSide,
                       askedShadowSide,
                       mInterruptCheck ? std::function<bool()>(interrupted) : std::function<bool()>()))
        return interruptedOutput();
    ensureTechnique(state.technique, state.width, state.height);
    const Reflections::Decision nonDiffuse =
        mReflections.decide(*mScene, *mSceneGpu, fp, mTechnique->glossyTransport(state.techniqueParams));

    // Frame uniforms.
    shader::FrameUniforms u{};
    float widestTan = 0.0f;
    for (const LightViewModel& v : lightSet.views)
        if (!v.orthographic) widestTan = std::max(widestTan, v.tanHalfFov);
    u.viewProj = frameViewProj(state);
    // Levels of detail: in the camera's view a tolerance in pixels of the whole image, tiles included
    // (lod_pixels); in the light views one in texels of their maps (light_lod_texels, at most one,
    // which the shadow lookup's normal offset covers; offsetting it by the level's error as well was
    // measured worse: docs/interactive.md, "Level of detail").
    const auto lodPixels = static_cast<float>(fp.getFloat("lod_pixels"));
    const LodView lod{state.camera.position,
                      lodErrorPerMetre(lodPixels, state.camera.yfovRadians,
                                       state.window.active() ? state.window.fullHeight : state.height)};
    u.cameraPos = glm::vec4(state.camera.position, 0.0f);
    const bool lightOn = lightSet.any();
    u.viewport = glm::vec4(state.width, state.height, 1.0f / state.width, 1.0f / state.height);
    u.rsmInfo = glm::vec4(lightSet.rsmSide, widestTan > 0.0f ? widestTan : 1.0f, lightSet.shadowSide,
                          fp.getInt("pcf_radius"));
    u.toneInfo =
        glm::vec4(static_cast<float>(std::exp2(frameExposureEv(state))),
                  fp.getEnum("tonemap") == "filmic" ? 1.0f : 0.0f, lightOn ? 1.0f : 0.0f, solidAngleEqual);
    const bool phong = fp.getEnum("specular_lobe") == "phong";
    u.shadingInfo =
        glm::vec4(phong ? 1.0f : 0.0f, fp.getFloat("glossy_split"), nonDiffuse.specular ? 1.0f : 0.0f, 0.0f);
    mDirectCase = !nonDiffuse.specular ? 0 : phong ? 2 : 1;
    mFrameUbo.upload(0, sizeof u, &u);
    mLightUbo.upload(0, sizeof lights, &lights);
    glBindBufferBase(GL_UNIFORM_BUFFER, GIS_UBO_FRAME, mFrameUbo.id());
    glBindBufferBase(GL_UNIFORM_BUFFER, GIS_UBO_LIGHTS, mLightUbo.id());

    mTimer.beginFrame();
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    std::vector<double> viewFlux;
    DrawCount lightDraws;
    // Maps larger than the defaults' are drawn in bands that input can stop (refinement only).
    std::function<bool()> lightBandStop;
    if (mInterruptCheck) lightBandStop = interrupted;
    if (reuseLights) {
        viewFlux = mLightPassFlux;
        mResources.publish("lights.shadow", "shadow_map", mShadow.depth);
        if (readsRsm)
            for (auto [name, texture] : {std::pair{"lights.rsm.position", &mRsm.position},
                                         {"lights.rsm.normal", &mRsm.normal},
                                         {"lights.rsm.flux", &mRsm.flux},
                                         {"lights.rsm.specular", &mRsm.specular}})
                mResources.publish(name, "rsm", *texture);
    } else {
        // Until this frame's maps are whole, no later frame may take them for kept ones.
        mLightPassesValid = false;
        lightDraws += renderShadowMaps(views, lightViewLods(lightSet, lightLodTexels, lightSet.shadowSide),
                                       lightBandStop);
        if (interrupted()) return interruptedOutput();
    }
    // Without a technique that reads them, the RSMs (one pass per light view) are not rendered.
    if (readsRsm && !reuseLights) {
        lightDraws +=
            renderRsms(views, lightViewLods(lightSet, lightLodTexels, lightSet.rsmSide), lightBandStop);
        if (interrupted()) return interruptedOutput();
        measureViewFlux(views);
        // Several views: the VPL split needs the sums before the technique's extraction is dispatched,
        // so they are read now (a small synchronous read; the previous frame's would make a single
        // render depend on the frame before it). One view: the sums only feed the stats, read after
        // the frame's own read-back, when waiting costs nothing.
        if (views > 1) viewFlux = readViewFlux(views);
    } else if (!readsRsm) {
        for (const char* name :
             {"lights.rsm.position", "lights.rsm.normal", "lights.rsm.flux", "lights.rsm.specular"})
            mResources.withdraw(name);
    }
    const TechniqueInfo& techniqueInfo = findTechniqueInfo(state.technique);
    const bool vplParts =
        state.vplPart.active() && techniqueInfo.vplParts && techniqueInfo.vplParts(state.techniqueParams);
    // Decided before the part joins the mean (averageVplPart records it as the last part).
    const bool followsLast = vplParts && followsLastPart(state, u.viewProj);
    // A frame that does not follow the parts in the mean draws over the G-buffer and the eye hierarchy
    // they keep: whatever part comes next starts a new mean.
    if (!followsLast) mPartAverage.averaged = 0;
    // A later VPL part of the same image under the same lights and frame parameters sees the same
    // G-buffer and direct light as the part before: they are kept rather than drawn again.
    const bool keepEyePasses =
        followsLast && reuseLights && state.frameParams.toJson() == mPartAverage.frameParams;
    DrawCount eyeDraws;
    if (keepEyePasses) {
        publishGBuffer();
        mResources.publish("direct", "direct", mScreen.direct);
    } else {
        eyeDraws = renderGBuffer(state.width, state.height, u.viewProj, lod);
        renderDirect();
        if (interrupted()) return interruptedOutput();
    }

    // The technique's indirect passes read the G-buffer, the RSM and the direct light by name.
    Counters counters;
    if (keepEyePasses) counters["vpl_part_kept_gbuffer"] = 1;
    // Frustum culling's measure: triangles the G-buffer and the light views (shadow maps and RSMs,
    // every view; 0 when last frame's are reused) drew and left out.
    counters["triangles_gbuffer"] = static_cast<double>(eyeDraws.drawn);
    counters["triangles_gbuffer_culled"] = static_cast<double>(eyeDraws.culled);
    if (lod.tolerates()) counters["triangles_gbuffer_simplified"] = static_cast<double>(eyeDraws.simplified);
    if (lightLodTexels > 0.0f && !reuseLights)
        counters["triangles_light_views_simplified"] = static_cast<double>(lightDraws.simplified);
    counters["triangles_light_views"] = static_cast<double>(lightDraws.drawn);
    counters["triangles_light_views_culled"] = static_cast<double>(lightDraws.culled);
    counters["draw_runs_gbuffer"] = static_cast<double>(eyeDraws.runs);
    counters["draw_calls_gbuffer"] = static_cast<double>(eyeDraws.calls);
    counters["draw_runs_light_views"] = static_cast<double>(lightDraws.runs);
    counters["draw_calls_light_views"] = static_cast<double>(lightDraws.calls);
    FrameInputs in;
    in.width = state.width;
    in.height = state.height;
    in.resources = &mResources;
    in.rsmSize = lightSet.rsmSide;
    in.rsmSizeAsked = askedRsmSide;
    in.backgroundBytes = mBackgroundBytes;
    in.lightViews = views;
    in.viewFlux = viewFlux;
    in.lights = &lights;
    in.glossy = nonDiffuse.glossy;
    in.glossyMinRoughness = fp.getFloat("glossy_split");
    in.lightEnabled = lightOn;
    in.lightViewsReused = reuseLights;
    in.frame = &u;
    in.drawGeometry = [this](const gl::Program& program, int instances) {
        if (!mSceneCutsOut) {
            mSceneGpu->draw(program, nullptr, instances);
            return;
        }
        const MaterialSlots slots = MaterialSlots::of(program); // once a frame: a few lookups
        mSceneGpu->draw(program, &slots, instances);
    };
    in.sceneCutsOut = mSceneCutsOut;
    in.sceneExtent = std::max(glm::length(mScene->bounds.max - mScene->bounds.min), 1e-3f);
    in.sceneSize = std::max(mScene->bounds.longestSide(), kMinSceneSize);
    in.receiverCapExponent = state.receiverCapExponent;
    if (vplParts) {
        in.vplParts = state.vplPart.count;
        in.vplPart = std::clamp(state.vplPart.index, 0, state.vplPart.count - 1);
        in.sameImageAsLastPart = followsLast;
        if (followsLast) counters["vpl_part_same_image"] = 1;
    }
    if (mInterruptCheck) in.interruptCheck = interrupted;
    const size_t techniqueFirstPass = mTimer.passCount();
    mTechnique->execute(in, state.techniqueParams, mTimer, counters);
    const size_t techniqueEndPass = mTimer.passCount();
    if (interrupted()) return interruptedOutput();
    glBindBufferBase(GL_UNIFORM_BUFFER, GIS_UBO_FRAME, mFrameUbo.id());
    glBindBufferBase(GL_UNIFORM_BUFFER, GIS_UBO_LIGHTS, mLightUbo.id());
    const gl::Texture* indirect = mTechnique->indirect();
    if (indirect && vplParts) indirect = &averageVplPart(state, u.viewProj, followsLast, *indirect, counters);
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
    rin.lightViewsReused = reuseLights;
    rin.envMaxRoughness = nonDiffuse.glossy ? fp.getFloat("glossy_split") : 1.01f;
    if (mInterruptCheck) rin.interruptCheck = interrupted;
    const gl::Texture* reflection = mReflections.execute(nonDiffuse, rin, fp, mTimer, counters);
    if (reflection && interrupted()) return interruptedOutput();
    glBindBufferBase(GL_UNIFORM_BUFFER, GIS_UBO_FRAME, mFrameUbo.id());
    glBindBufferBase(GL_UNIFORM_BUFFER, GIS_UBO_LIGHTS, mLightUbo.id());
    if (reflection)
        mResources.publish("reflection", "reflections", *reflection);
    else
        mResources.withdraw("reflection");

    // glTF occlusion maps darken the indirect light only where no pass computed indirect shadows.
    const bool indirectShadows =
        techniqueInfo.indirectShadows && techniqueInfo.indirectShadows(state.techniqueParams);
    const bool applyOcclusion = mSceneHasOcclusionMaps && !indirectShadows;
    counters["occlusion_maps_applied"] = applyOcclusion ? 1 : 0;
    composite(state.width, state.height, indirect, reflection, applyOcclusion);

    FrameOutput out;
    out.width = state.width;
    out.height = state.height;
    Stopwatch readClock;
    out.rgba8 = readRgba8(mScreen.compositeFbo, 0, state.width, state.height);
    if (wantLinear) out.linear = readRgba32f(mScreen.compositeFbo, 1, state.width, state.height);
    if (wantDirect) out.linearDirect = readRgba32f(mScreen.directFbo, 0, state.width, state.height);
    const double readbackMs = readClock.elapsedMs();
    if (readsRsm && views == 1 && !reuseLights) viewFlux = readViewFlux(views);
    if (mReuseLightPasses && !reuseLights) {
        if (!mLightPassBlock) mLightPassBlock = std::make_unique<shader::LightUniforms>();
        *mLightPassBlock = lights;
        mLightPassKey = lightKey;
        mLightPassShadowSide = lightSet.shadowSide;
        mLightPassRsmSide = lightSet.rsmSide;
        mLightPassLodTexels = lightLodTexels;
        mLightPassFlux = viewFlux;
        mLightPassesValid = true;
    }
    std::vector<gl::PassTiming> passes = mTimer.resolve();
    gl::logErrors("frame");
    mReflections.noteTimings(passes);

    nlohmann::json passJson = nlohmann::json::array();
    double techniqueMs = 0.0;
    for (size_t i = 0; i < passes.size(); ++i) {
        const auto& p = passes[i];
        passJson.push_back({{"name", p.name}, {"gpu_ms", p.gpuMs}, {"cpu_ms", p.cpuMs}});
        if (i >= techniqueFirstPass && i < techniqueEndPass) techniqueMs += p.gpuMs;
    }
    nlohmann::json countJson = nlohmann::json::object();
    countJson["triangles"] = mSceneGpu->triangleCount();
    if (mSceneGpu->instanceCount() > 0) {
        countJson["triangles_stored"] = mSceneGpu->storedTriangleCount();
        countJson["instances"] = mSceneGpu->instanceCount();
    }
    if (mSceneGpu->lodTriangleCount() > 0) countJson["triangles_lod_stored"] = mSceneGpu->lodTriangleCount();
    countJson["pixels"] = state.width * state.height;
    if (reuseLights) countJson["light_views_reused"] = views;
    // Shadow-map and RSM arrays allocated for this frame (none when their sides were kept).
    if (mLightMapsCreated > 0) countJson["light_view_arrays_created"] = mLightMapsCreated;
    for (const auto& [k, v] : counters) countJson[k] = v;
    nlohmann::json params = paramsJson(state);
    out.stats = {
        {"technique", state.technique},       {"size", {state.width, state.height}},
        {"frame_ms", frameClock.elapsedMs()}, {"readback_ms", readbackMs},
        {"technique_ms", techniqueMs},        {"timing", mTimer.usesQueries() ? "gpu_query" : "cpu_finish"},
        {"passes", std::move(passJson)},      {"counts", std::move(countJson)},
        {"params", std::move(params)}};
    if (!state.plan.is_null()) out.stats["plan"] = state.plan;
    out.stats["nondiffuse"] = nonDiffuse.reasons;
    if (nonDiffuse.env && nonDiffuse.reasons.contains("env"))
        out.stats["nondiffuse"]["env"] =
            nonDiffuse.reasons["env"].get<std::string>() + "; " + mReflections.envPlanReason();
    out.stats["lighting"] = lightingStats(state, lightSet, viewFlux);
    // Smaller maps than the parameters ask for (an interactive frame's cap, or maps it kept): what
    // they ask (counts.light_views_reused says whether they were kept).
    if (lightSet.shadowSide != askedShadowSide || (readsRsm && lightSet.rsmSide != askedRsmSide)) {
        out.stats["lighting"]["shadow_side_asked"] = askedShadowSide;
        out.stats["lighting"]["rsm_side_asked"] = askedRsmSide;
    }
    if (!mNotShown.empty()) out.stats["not_shown"] = mNotShown;
    return out;
}

} // namespace gis
