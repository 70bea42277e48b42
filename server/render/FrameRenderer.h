// The frame pipeline (DESIGN.md §3): a shadow map and an RSM per light view (frame/LightModel.h),
// eye G-buffer, direct light from every light, the technique's indirect passes, composite with tone
// mapping, read-back.
//
// Threading: one FrameRenderer per GL context, used on the thread where that context is current.
// Errors: construction, setScene() and the first render() after a technique or size change may
// throw gis::Error (shader compile, allocation: setup boundaries); steady-state frames never throw.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "frame/FrameState.h"
#include "frame/LightModel.h"
#include "gi/Technique.h"
#include "gl/Background.h"
#include "gl/FrameResources.h"
#include "gl/Objects.h"
#include "gl/RecentTargets.h"
#include "gl/PassTimer.h"
#include "gl/Shader.h"
#include "gl/ShaderShared.h"
#include "render/Reflections.h"
#include "render/SceneGpu.h"

namespace gis {

/// The light block (gLights in shaders/shared/FrameData.h) of a light set: every light's position and
/// intensity, axis and outer cone, colour and inner cone, type, range and views, and every view's
/// projection, which lightIncidence(), the shadow lookups and the light passes read.
void writeLightUniforms(const LightSetModel& set, shader::LightUniforms& u);

/// The stats' `lighting` object: where the lights came from, which are rendered (id, name, type,
/// views, and with the views' measured RSM flux `viewFlux` their reflected flux), which are skipped
/// and why, the view sizes, and a warning when no light is rendered or a rendered one reaches no
/// surface.
nlohmann::json lightingStats(const FrameState& state, const LightSetModel& set,
                             const std::vector<double>& viewFlux);

struct FrameOutput {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgba8; ///< tone-mapped sRGB, rows top to bottom
    std::vector<float> linear;       ///< linear RGBA radiance, rows top to bottom (when requested)
    /// The direct pass alone (direct light and emission), linear RGBA like `linear` (when requested):
    /// linear minus this is the technique's indirect light and reflections.
    std::vector<float> linearDirect;
    /// render() stopped between two stages because its interrupt check said so
    /// (FrameRenderer::setInterruptCheck): no image, no stats.
    bool interrupted = false;
    /// The stats object documented in protocol/PROTOCOL.md: technique, size, frame_ms, passes,
    /// counts, params.
    nlohmann::json stats;
};

class FrameRenderer {
public:
    explicit FrameRenderer(bool useTimerQueries = true);
    ~FrameRenderer();
    /// Uploads `scene`; `prepared` (SceneGpu::prepare of the same scene, built off this thread) spares
    /// the render thread the CPU half of the upload.
    void setScene(std::shared_ptr<const Scene> scene,
                  std::shared_ptr<const SceneGpu::Prepared> prepared = nullptr);
    /// Shows `scene` with its upload already done (a staged SceneGpu whose complete() is true).
    void setScene(std::shared_ptr<const Scene> scene, std::unique_ptr<SceneGpu> uploaded);
    const Scene* scene() const { return mScene.get(); }
    /// Renders one frame. `wantLinear` also reads back the linear radiance (EXR output, metrics),
    /// `wantDirect` the direct pass's (indirect-only metrics).
    FrameOutput render(const FrameState& state, bool wantLinear = false, bool wantDirect = false);
    /// Keep the light views' shadow maps and RSMs while the lights, the scene and the RSM settings stay
    /// the same (the stats' counts then have `light_views_reused`). Off by default, so that benchmarks
    /// and tests time every pass of every frame; the service turns it on.
    void setReuseLightPasses(bool reuse) { mReuseLightPasses = reuse; }
    /// Whether a frame of `state` would keep the light views an earlier frame drew (the same lights and
    /// light-view parameters, and maps no larger than it asks for; FrameState::LightViewCap decides
    /// the rest): the frame budget predicts a frame that draws them again with their cost.
    bool keepsLightViews(const FrameState& state);
    /// Refinement's interruption: while `check` is set, render() asks it between its stages (after the
    /// shadow maps, the RSMs, the eye passes, the technique and the reflections, and inside a technique
    /// or the environment probes where they ask, FrameInputs::interrupted, ReflectionInputs::interrupted),
    /// each time once the GL work queued so far is done (glFinish), and stops at the first true,
    /// returning an `interrupted` output. What the frame began is not kept
    /// for the next (redrawn light views, environment cubes; the VPL parts' mean is not added to); GL
    /// work already issued still runs. Empty (the default): every frame runs to the end.
    void setInterruptCheck(std::function<bool()> check) { mInterruptCheck = std::move(check); }
    /// While the check is set, light maps and light-tree buffers of at least `bytes` are made on a
    /// helper thread, the check asked every millisecond until they are (gl/Background.h; default
    /// gl::kBackgroundBytes). Tests that count the checks set it past what they make.
    void setBackgroundBytes(double bytes) { mBackgroundBytes = bytes; }
    /// Test hook: light maps whose making started in the background so far.
    int lightMapsStartedInBackground() const { return mShadowMaker.starts() + mRsmMaker.starts(); }
    /// Levels of detail (lod_pixels): on demand (the default) the first frame that asks for them builds
    /// them on this thread (CLI renders, benchmarks, tests); a session turns that off, builds them on a
    /// thread of its own and hands them in with setSceneLevels (until then its frames draw every
    /// triangle).
    void setLevelsOnDemand(bool onDemand) { mLevelsOnDemand = onDemand; }
    /// `levels` (SceneGpu::prepareLevels of the current scene) for the scene's draws.
    void setSceneLevels(std::shared_ptr<const SceneGpu::LodSet> levels);
    bool sceneHasLevels() const;
    /// Whether `state` draws anything at a level of detail (lod_pixels or light_lod_texels above 0):
    /// what makes levels worth building.
    static bool wantsLevels(const FrameState& state);

    /// The technique of the last frame (tests inspect its intermediate buffers); may be null.
    Technique* technique() { return mTechnique.get(); }
    /// The planar mirrors of the current scene (after the first frame).
    const std::vector<MirrorPlane>& mirrors() const { return mReflections.mirrors(); }
    /// What the last frame produced, by name (gl/FrameResources.h; `gi-render --list-resources`).
    const FrameResources& resources() const { return mResources; }

private:
    /// The light maps and screen targets for the frame. `asked`: the light views' sides before an
    /// interactive frame's cap, whose maps stay kept whatever their size. With `stop` (refinement),
    /// large maps are made in the background while it is asked (gl/Background.h); false when it said
    /// stop first; the next frame takes what was being made (shadow maps made before the stop are
    /// already in place).
    bool ensureTargets(int width, int height, int rsmSide, int shadowSide, int views, int askedRsmSide,
                       int askedShadowSide, const std::function<bool()>& stop);
    void ensureTechnique(const std::string& name, int width, int height);
    // The frame's stages, in order; each publishes what it writes in mResources.
    /// `lods`: each view's tolerance for levels of detail (empty: every triangle).
    /// `stop` (may be empty) is asked between the pieces of maps larger than the defaults' (lightViewBands):
    /// true leaves them incomplete (not kept, LightPasses) and returns.
    /// light_lod_texels as this frame's light views are drawn with it (0 without levels of detail).
    float lightLodTexelsOf(const FrameState& state) const;
    /// What kept light views must have been drawn with besides the lights (mLightPassKey): the RSM's
    /// solid-angle rule and whether the RSMs were drawn.
    static glm::vec2 lightPassKey(const FrameState& state);
    /// The kept light views as a frame of `state` with the light block `lights` sees them.
    KeptLightViews keptLightViews(const FrameState& state, const shader::LightUniforms& lights) const;
    DrawCount renderShadowMaps(int views, std::span<const LodView> lods, const std::function<bool()>& stop);
    DrawCount renderRsms(int views, std::span<const LodView> lods, const std::function<bool()>& stop);
    /// Sums the reflected flux luminance of every view's RSM on the GPU (pass "rsm_flux").
    void measureViewFlux(int views);
    /// Those sums, read back (waits for the pass); empty without views.
    std::vector<double> readViewFlux(int views) const;
    DrawCount renderGBuffer(int width, int height, const glm::mat4& viewProj, const LodView& lod);
    void renderDirect();
    /// `applyOcclusion`: multiply the indirect light by the G-buffer's occlusion (glTF occlusion maps).
    void composite(int width, int height, const gl::Texture* indirect, const gl::Texture* reflection,
                   bool applyOcclusion);
    /// Folds one VPL part's indirect light into the running mean of the parts before it
    /// (FrameState::VplPart) and returns that mean; `followsLast`: followsLastPart() before this part.
    const gl::Texture& averageVplPart(const FrameState& state, const glm::mat4& viewProj, bool followsLast,
                                      const gl::Texture& part, Counters& counters);
    static std::array<int, 7> partKey(const FrameState& state);
    /// Whether `state` is the next VPL part of the image whose parts are in the mean.
    bool followsLastPart(const FrameState& state, const glm::mat4& viewProj) const;

    std::shared_ptr<const Scene> mScene;
    bool mLevelsOnDemand = true;
    nlohmann::json mNotShown; ///< stats.not_shown of mScene (an empty array: nothing to say)
    std::unique_ptr<SceneGpu> mSceneGpu;
    gl::PassTimer mTimer;
    FrameResources mResources;

    /// A scene-drawing program and its view selector (mesh.vert: 0 camera, 1 light).
    struct MeshPass {
        gl::Program program;
        gl::UniformLocation view;
        MaterialSlots materials;
    };
    /// Which material uniforms a mesh pass reads: none (depth only), those it uses, or all of them
    /// (the G-buffer, where a missing one is a misspelling).
    enum class MeshMaterials { None, Used, All };
    /// `plain`: built with GIS_MATERIAL_PLAIN (no maps, no vertex colours; shaders/render/material.glsl).
    static MeshPass buildMeshPass(const char* fragment, MeshMaterials materials, bool cutout,
                                  bool plain = false);
    MeshPass mShadowPass;
    /// The RSM and G-buffer with the materials' maps, and plain ones for scenes whose materials have
    /// no maps and whose meshes no vertex colours (mScenePlain: the maps' code compiled out, which
    /// llvmpipe would run for every fragment). Each pair is built with the first scene that needs it.
    struct MaterialPasses {
        MeshPass rsm, gbuffer;
    };
    std::unique_ptr<MaterialPasses> mMappedPasses, mPlainPasses;
    bool mScenePlain = false;
    /// The same passes built with GIS_ALPHA_CUTOUT, for scenes with cut-out materials (built with
    /// the first such scene; discarding fragments costs the others their early depth test).
    struct CutoutPasses {
        MeshPass shadow, rsm, gbuffer;
    };
    std::unique_ptr<CutoutPasses> mCutoutPasses;
    bool mSceneCutsOut = false;
    bool mSceneHasOcclusionMaps = false; ///< a material has a glTF occlusion texture
    const MeshPass& shadowPass() const { return mSceneCutsOut ? mCutoutPasses->shadow : mShadowPass; }
    const MaterialPasses& materialPasses() const { return mScenePlain ? *mPlainPasses : *mMappedPasses; }
    const MeshPass& rsmPass() const { return mSceneCutsOut ? mCutoutPasses->rsm : materialPasses().rsm; }
    const MeshPass& gbufferPass() const {
        return mSceneCutsOut ? mCutoutPasses->gbuffer : materialPasses().gbuffer;
    }
    struct DirectPass {
        gl::Program program;
        gl::TextureUnit position, normal, albedo, emissive, shadow, specular;
    };
    /// The direct pass per specular case (shaders/render/lighting.glsl, GIS_SPECULAR): none, GGX,
    /// Phong. The frame's uniforms choose mDirectCase.
    std::array<DirectPass, 3> mDirectPasses;
    size_t mDirectCase = 0;
    struct CompositePass {
        gl::Program program;
        gl::TextureUnit direct, indirect, reflection, albedo;
        gl::UniformLocation hasIndirect, applyOcclusion;
    };
    /// Without and with reflections (GIS_COMPOSITE_REFLECTION in composite.frag).
    std::array<CompositePass, 2> mCompositePasses;
    struct FluxPass {
        gl::Program program;
        gl::UniformLocation rsmSize;
        gl::TextureUnit position, flux;
        gl::BlockBinding sums;
    } mFluxPass;
    gl::Buffer mFrameUbo, mLightUbo, mFluxSums;
    /// CPU copy of the light block (47 KB: kept, not reallocated per frame); FrameInputs::lights.
    std::unique_ptr<shader::LightUniforms> mLightBlock;
    gl::VertexArray mEmptyVao;

    int mWidth = 0, mHeight = 0, mRsmSize = 0, mShadowSize = 0, mShadowLayers = 0, mRsmLayers = 0;
    // One layer per light view; one framebuffer per layer.
    // Light maps: textures made by makeTextures (any thread sharing the context's objects: see
    // gl/Background.h), framebuffers attached by attach (the renderer's context).
    struct ShadowMaps {
        gl::Texture depth;
        std::vector<gl::Framebuffer> fbos;
        static ShadowMaps makeTextures(int side, int layers);
        void attach();
        static double bytes(int side, int layers) { return 4.0 * side * side * layers; }
    };
    struct Rsms {
        gl::Texture position, normal, flux, specular, depth;
        std::vector<gl::Framebuffer> fbos;
        static Rsms makeTextures(int side, int layers);
        void attach();
        /// Position and flux RGBA32F, normal RGBA16F, specular RGBA8, depth 32F: 48 bytes a texel.
        static double bytes(int side, int layers) { return 48.0 * side * side * layers; }
    };
    /// Maps of (side, layers) `shape`, made in the background with `stop` (see ensureTargets).
    template <class Maps>
    std::optional<Maps> makeLightMaps(gl::BackgroundMaker<std::pair<int, int>, Maps>& maker,
                                      std::pair<int, int> shape, const std::function<bool()>& stop);
    ShadowMaps mShadow;
    Rsms mRsm;
    /// The maps of the other side last drawn (gl/RecentTargets.h), keyed by side and layers: an
    /// interactive frame's capped light views (FrameState::LightViewCap) and a refinement step's
    /// asked ones alternate, and allocating them again held the step's first tile (about 40 ms for a
    /// 4096^2 shadow array on llvmpipe, docs/interactive.md). At most one, of at most
    /// kKeptLightMapBytes, or of the asked maps' size (ensureTargets).
    static constexpr double kKeptLightMapBytes = 128.0 * 1024.0 * 1024.0;
    gl::RecentTargets<std::pair<int, int>, ShadowMaps> mOtherShadow{1, kKeptLightMapBytes};
    gl::RecentTargets<std::pair<int, int>, Rsms> mOtherRsm{1, kKeptLightMapBytes};
    gl::BackgroundMaker<std::pair<int, int>, ShadowMaps> mShadowMaker{"shadow maps"};
    gl::BackgroundMaker<std::pair<int, int>, Rsms> mRsmMaker{"reflective shadow maps"};
    int mLightMapsCreated = 0; ///< arrays ensureTargets created for this frame (counts)
    double mBackgroundBytes = static_cast<double>(gl::kBackgroundBytes); ///< setBackgroundBytes
    /// What is sized to the frame: G-buffer, direct light, composite.
    struct ScreenTargets {
        gl::Texture gPosition, gNormal, gAlbedo, gEmissive, gSpecular, gDepth;
        gl::Framebuffer gBufferFbo;
        gl::Texture direct;
        gl::Framebuffer directFbo;
        gl::Texture display, linear;
        gl::Framebuffer compositeFbo;
        static ScreenTargets create(int width, int height);
    };
    ScreenTargets mScreen;
    /// The targets of the last few other sizes (gl/RecentTargets.h): at most 4, 512k pixels together.
    gl::RecentTargets<std::pair<int, int>, ScreenTargets> mRecentScreens{4, 512.0 * 1024.0};

    /// The mean of the VPL parts of one image so far, allocated by the first part.
    struct PartAverage {
        gl::Program program;
        gl::TextureUnit part;
        gl::UniformLocation weight;
        gl::Texture mean;
        gl::Framebuffer fbo;
        int width = 0, height = 0;
        int averaged = 0; ///< parts in the mean
        /// What the parts in the mean rendered: a part adds to them only with the same image.
        std::array<int, 7> key{};
        /// The camera and technique parameters of the parts in the mean.
        glm::mat4 viewProj{0.0f};
        nlohmann::json techniqueParams;
        nlohmann::json frameParams; ///< with the light block: whether the G-buffer and direct light hold
    } mPartAverage;
    /// Publishes the G-buffer's textures as this frame's (after drawing them, or keeping them).
    void publishGBuffer();

    Reflections mReflections;

    std::function<bool()> mInterruptCheck;

    bool mReuseLightPasses = false;
    bool mLightPassesValid = false; ///< the maps hold mLightPassBlock's views
    std::unique_ptr<shader::LightUniforms> mLightPassBlock;
    glm::vec2 mLightPassKey{0.0f}; ///< the solid-angle rule and whether the RSMs were drawn
    int mLightPassShadowSide = 0;  ///< the kept maps' sides
    int mLightPassRsmSide = 0;
    std::unique_ptr<shader::LightUniforms> mQueryLightBlock; ///< keepsLightViews' scratch block
    float mLightPassLodTexels = 0.0f; ///< the texels of level-of-detail error the maps were drawn with
    std::vector<double> mLightPassFlux;

    std::string mTechniqueName;
    std::unique_ptr<Technique> mTechnique;
    int mTechniqueWidth = 0, mTechniqueHeight = 0;
};

} // namespace gis
