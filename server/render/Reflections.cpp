#include "render/Reflections.h"

#include <algorithm>
#include <cmath>

#include "core/Error.h"
#include "render/EnvProbe.h"
#include "render/PlanarMirrors.h"
#include "scene/Brdf.h"
#include "scene/SurfaceAnalysis.h"

namespace gis {
namespace {

std::string count(int n, const char* what) {
    return std::to_string(n) + " " + what;
}

} // namespace

const gl::Texture& ReflectionInputs::get(const std::string& name) const {
    GIS_ASSERT(resources != nullptr);
    return resources->get(name);
}

ForwardProgram ForwardProgram::build() {
    ForwardProgram f;
    // Cutouts always: reflections are drawn far less often than the eye and light views, so one
    // program serves every scene (opaque materials set a negative cutoff and never discard).
    f.program = gl::Program::build(
        {{GL_VERTEX_SHADER, "render/forward.vert"}, {GL_FRAGMENT_SHADER, "render/forward.frag"}},
        {{"GIS_ALPHA_CUTOUT", "1"}});
    f.viewProj = f.program.location("uViewProj");
    f.clipPlane = f.program.location("uClipPlane");
    f.eye = f.program.location("uEye");
    f.shadowMap = f.program.textureUnit("gShadowMap");
    f.materials = MaterialSlots::of(f.program);
    return f;
}

Reflections::Reflections() = default;
Reflections::~Reflections() = default;

Reflections::Decision Reflections::decide(const Scene& scene, SceneGpu& sceneGpu, const ParamSet& fp,
                                          bool techniqueHasGlossy) {
    const float mirrorRoughness = fp.getFloat("mirror_roughness");
    const float split = fp.getFloat("glossy_split");
    const int mirrorDepth = fp.getInt("mirror_depth");
    const bool changed = &scene != mMirrorScene || &sceneGpu != mSceneGpu ||
                         mirrorRoughness != mMirrorRoughness || split != mSplit ||
                         techniqueHasGlossy != mTechniqueGlossy;
    if (changed) {
        mMirrors = findPlanarMirrors(scene, mirrorRoughness);
        mMirrorScene = &scene;
        mSceneGpu = &sceneGpu;
        mMirrorRoughness = mirrorRoughness;
        mSplit = split;
        mTechniqueGlossy = techniqueHasGlossy;
        // Reflector ids for the G-buffer: mirror k -> k + 1, local probe k -> -(k + 1). Local probes
        // go to the largest curved objects that the probe shades (smooth, or any specular one when
        // the technique has no glossy transport).
        std::vector<int> idOfMesh(scene.meshes.size(), 0);
        for (size_t i = 0; i < mMirrors.size(); ++i)
            idOfMesh[static_cast<size_t>(mMirrors[i].mesh)] = static_cast<int>(i) + 1;
        struct Candidate {
            EnvObject object;
            float size = 0.0f;
        };
        std::vector<Candidate> candidates;
        for (size_t i = 0; i < scene.meshes.size(); ++i) {
            const Mesh& mesh = scene.meshes[i];
            const Material* material = meshMaterial(scene, mesh);
            // An instanced mesh is several objects: none gets a probe of its own (the room's serves).
            if (idOfMesh[i] != 0 || mesh.positions.empty() || mesh.instanced() || !material) continue;
            const Material& mat = *material;
            if (!specularWorthAPass(mat, split) || !(mat.roughness < split || !techniqueHasGlossy)) continue;
            const Flatness f = flatness(mesh);
            if (f.flat || !(f.area > 0.0))
                continue; // a plane never reflects itself: the room probe serves it
            candidates.push_back({EnvObject{static_cast<int>(i), glm::vec3(0.5 * (f.lo + f.hi))},
                                  static_cast<float>(glm::length(f.hi - f.lo))});
        }
        std::stable_sort(candidates.begin(), candidates.end(),
                         [](const Candidate& a, const Candidate& b) { return a.size > b.size; });
        mEnvObjects.clear();
        for (size_t k = 0; k < candidates.size() && k < static_cast<size_t>(kMaxLocalProbes); ++k) {
            mEnvObjects.push_back(candidates[k].object);
            idOfMesh[static_cast<size_t>(candidates[k].object.mesh)] = -(static_cast<int>(k) + 1);
        }
        sceneGpu.setSurfaceIds(idOfMesh);
    }
    std::vector<bool> isMirrorMaterialOnly(scene.materials.size(), false);
    int specularMaterials = 0, smooth = 0, rough = 0;
    {
        // A material counts for env/glossy only where a non-mirror mesh uses it.
        std::vector<bool> usedByOther(scene.materials.size(), false);
        std::vector<bool> mirrorMesh(scene.meshes.size(), false);
        if (mirrorDepth > 0)
            for (const MirrorPlane& m : mMirrors) mirrorMesh[static_cast<size_t>(m.mesh)] = true;
        for (size_t i = 0; i < scene.meshes.size(); ++i) {
            const int mat = scene.meshes[i].material;
            if (mat >= 0 && mat < static_cast<int>(scene.materials.size()) && !mirrorMesh[i])
                usedByOther[static_cast<size_t>(mat)] = true;
        }
        for (size_t i = 0; i < scene.materials.size(); ++i) {
            if (!materialSurface(scene.materials[i]).hasSpecular()) continue;
            ++specularMaterials;
            if (!usedByOther[i] || !specularWorthAPass(scene.materials[i], split)) continue;
            if (scene.materials[i].roughness < split || !techniqueHasGlossy)
                ++smooth;
            else
                ++rough;
        }
    }
    Decision d;
    auto resolve = [&](const char* param, bool wanted, const std::string& why, bool& out, const char* key) {
        const std::string mode = fp.getEnum(param);
        if (mode == "on") {
            out = true;
            d.reasons[key] = std::string("on: ") + param + "=on";
        } else if (mode == "off") {
            out = false;
            d.reasons[key] = std::string("off: ") + param + "=off";
        } else {
            out = wanted;
            d.reasons[key] = std::string(wanted ? "on: " : "off: ") + why;
        }
    };
    resolve("effect_specular", specularMaterials > 0,
            specularMaterials > 0 ? count(specularMaterials, "materials with a specular lobe")
                                  : "every material is Lambertian",
            d.specular, "specular");
    resolve("effect_glossy", rough > 0 && techniqueHasGlossy,
            !techniqueHasGlossy ? "the technique has no glossy VPL transport"
            : rough > 0         ? count(rough, "materials at least glossy_split rough")
                                : "no specular material is at least glossy_split rough",
            d.glossy, "glossy");
    resolve("effect_env", smooth > 0,
            smooth > 0 ? count(smooth, "smooth specular materials outside planar mirrors")
                       : "no smooth specular material outside planar mirrors",
            d.env, "env");
    const bool mirrorsWanted = !mMirrors.empty() && mirrorDepth > 0;
    resolve("effect_mirrors", mirrorsWanted,
            mMirrors.empty()   ? "no flat, smooth metallic mesh"
            : mirrorDepth == 0 ? "mirror_depth=0 (the environment probe shades them)"
                               : count(static_cast<int>(mMirrors.size()), "planar mirrors"),
            d.mirrors, "mirrors");
    if (d.mirrors && mMirrors.empty()) {
        d.mirrors = false;
        d.reasons["mirrors"] = "off: the scene has no planar mirror";
    }
    return d;
}

const gl::Texture* Reflections::execute(const Decision& d, ReflectionInputs in, const ParamSet& fp,
                                        gl::PassTimer& timer, Counters& counters) {
    counters["env_probe"] = d.env ? 1 : 0;
    counters["mirrors"] = d.mirrors ? static_cast<double>(mMirrors.size()) : 0.0;
    if (!d.env && !d.mirrors) return nullptr;
    if (in.width != mWidth || in.height != mHeight) {
        mOutput = gl::Texture::create2D(GL_RGBA32F, in.width, in.height);
        mOutputFbo = gl::Framebuffer::of("reflections", {&mOutput});
        mWidth = in.width;
        mHeight = in.height;
    }
    const float zero[4] = {0, 0, 0, 0};
    glClearNamedFramebufferfv(mOutputFbo.id(), GL_COLOR, 0, zero);
    in.mirrors = &mMirrors;
    in.envObjects = &mEnvObjects;
    in.mirrorPass = d.mirrors;
    if (d.env) {
        if (!mEnv) mEnv = std::make_unique<EnvProbe>();
        mEnv->execute(in, fp, mOutputFbo, timer, counters);
    }
    if (d.mirrors) {
        if (!mMirrorPass) mMirrorPass = std::make_unique<PlanarMirrors>();
        mMirrorPass->execute(in, fp, mOutputFbo, timer, counters);
    }
    return &mOutput;
}

void Reflections::noteTimings(const std::vector<gl::PassTiming>& passes) {
    if (mEnv) mEnv->noteTimings(passes);
}

std::string Reflections::envPlanReason() const {
    return mEnv ? mEnv->planReason() : std::string();
}

} // namespace gis
