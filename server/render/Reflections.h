// Non-diffuse effects of the frame pipeline (docs/nondiffuse.md): which of them a scene calls for,
// and the reflection passes that add specular indirect light on top of the technique's diffuse
// bounce:
//   - EnvProbe (004 §2.1-2.2): a dynamic cube map from a probe, prefiltered per roughness, for
//     smooth specular surfaces (roughness below glossy_split, or every specular surface when the
//     technique has no glossy VPL transport);
//   - PlanarMirrors (004 §5.1): flat, smooth metallic meshes re-rendered from the mirrored camera.
// Rough specular surfaces take their glossy indirect light from the technique's VPLs instead
// (FrameInputs::glossy), so no light path is counted twice.
//
// Each effect_* frame parameter may force an effect on or off; `auto` decides from the materials
// (this class) and, with effects=auto, from what the view shows (analysis/EffectPlan). The decision
// and its reason are in the frame stats ("nondiffuse").
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/Param.h"
#include "gi/Technique.h"
#include "gl/FrameResources.h"
#include "gl/Objects.h"
#include "gl/PassTimer.h"
#include "render/SceneGpu.h"
#include "scene/SurfaceAnalysis.h"

namespace gis {

namespace shader {
struct FrameUniforms;
}

/// A curved object shaded by the environment probe that gets a local probe of its own, at its
/// centre and blind to the object itself: the room probe sees such an object from outside, so it
/// would reflect its own far side (docs/nondiffuse.md).
struct EnvObject {
    int mesh = -1;          ///< index into Scene::meshes
    glm::vec3 centre{0.0f}; ///< centre of the mesh's bounds (m): the local probe's position
};
inline constexpr int kMaxLocalProbes = 3;

/// What the reflection passes read. Textures are the renderer's, read from the frame's resource
/// table by name (gl/FrameResources.h): gbuffer.position (RGBA32F, w = 1 covered), gbuffer.normal
/// (RGBA16F, w = reflector id: mirror index + 1, local probe -(k + 1), 0 none), gbuffer.specular
/// (RGBA8 rgb F0, a roughness), lights.shadow (the light views' shadow maps, for
/// shaders/render/lighting.glsl) and, when the technique made one, indirect (its eye-view indirect
/// radiance, for the mirrors' reprojection). The frame and light blocks are bound at GIS_UBO_FRAME and
/// GIS_UBO_LIGHTS; `frame` is the frame block's CPU
/// copy.
struct ReflectionInputs {
    int width = 0, height = 0;
    /// Everything the frame produced before the reflections, by name.
    const FrameResources* resources = nullptr;
    const shader::FrameUniforms* frame = nullptr;
    const Scene* scene = nullptr;
    const SceneGpu* sceneGpu = nullptr;
    const std::vector<MirrorPlane>* mirrors = nullptr;
    const std::vector<EnvObject>* envObjects = nullptr; ///< local probes (G-buffer id -(k + 1))
    /// Env reflections apply to covered, non-mirror pixels with a specular lobe and roughness below
    /// this (1.01 when the technique has no glossy transport, so every glossy pixel gets one).
    float envMaxRoughness = 0.35f;
    /// True when the planar-mirror pass shades the mirror pixels (gNormal.w > 0); otherwise the
    /// environment probe shades them too (mirror_depth=0, effect_mirrors=off).
    bool mirrorPass = false;
    /// True when the lights, their shadow maps and the scene are last frame's (FrameRenderer's light
    /// view reuse): the environment probes, lit by them only and not by the camera, may keep theirs.
    bool lightViewsReused = false;
    /// Refinement's interruption (FrameRenderer::setInterruptCheck, as FrameInputs::interruptCheck):
    /// the environment probes ask it between their cubes; empty: they render to the end.
    std::function<bool()> interruptCheck;

    /// Whether the frame should stop here (interruptCheck, when set).
    bool interrupted() const { return interruptCheck && interruptCheck(); }

    /// The resource `name`, or nullptr when the frame did not produce it.
    const gl::Texture* find(const std::string& name) const {
        return resources ? resources->find(name) : nullptr;
    }
    /// The resource `name`; asserts that the frame produced it.
    const gl::Texture& get(const std::string& name) const;
};

/// The program the reflection passes render the scene with from viewpoints other than the eye
/// (shaders/render/forward.*: environment-probe faces, mirrored views), with its uniforms, shadow-map
/// unit and material slots resolved where it is built.
struct ForwardProgram {
    gl::Program program;
    gl::UniformLocation viewProj, clipPlane, eye;
    gl::TextureUnit shadowMap;
    MaterialSlots materials;
    static ForwardProgram build(); ///< compiles: may throw gis::Error
};

class EnvProbe;
class PlanarMirrors;

class Reflections {
public:
    Reflections();
    ~Reflections();

    struct Decision {
        bool specular = false, glossy = false, env = false, mirrors = false;
        nlohmann::json reasons; ///< {"specular": "...", "glossy": ..., "env": ..., "mirrors": ...}
    };
    /// Resolves the effect_* parameters against the scene's materials (and the technique's ability
    /// to carry glossy transport); recomputes the mirror list when the scene or mirror_roughness
    /// changed and marks the mirrors in `sceneGpu`.
    Decision decide(const Scene& scene, SceneGpu& sceneGpu, const ParamSet& frameParams,
                    bool techniqueHasGlossy);

    /// Runs the enabled passes and returns the radiance to add (RGBA32F, width x height), or null
    /// when neither env nor mirrors is on. Never throws after the first frame at a size.
    const gl::Texture* execute(const Decision& decision, ReflectionInputs in, const ParamSet& frameParams,
                               gl::PassTimer& timer, Counters& counters);

    /// After the frame's timings are resolved: the environment probes measure their cost from them.
    void noteTimings(const std::vector<gl::PassTiming>& passes);
    /// The environment probes' last plan in words; empty before they first ran.
    std::string envPlanReason() const;

    const std::vector<MirrorPlane>& mirrors() const { return mMirrors; }
    const std::vector<EnvObject>& envObjects() const { return mEnvObjects; }

private:
    std::unique_ptr<EnvProbe> mEnv;
    std::unique_ptr<PlanarMirrors> mMirrorPass;
    std::vector<MirrorPlane> mMirrors;
    std::vector<EnvObject> mEnvObjects;
    const Scene* mMirrorScene = nullptr;
    const SceneGpu* mSceneGpu = nullptr; ///< the upload the surface ids were set on
    float mMirrorRoughness = -1.0f;
    float mSplit = -1.0f; ///< glossy_split the surface ids were computed for
    bool mTechniqueGlossy = false;
    int mWidth = 0, mHeight = 0;
    gl::Texture mOutput;
    gl::Framebuffer mOutputFbo;
};

} // namespace gis
