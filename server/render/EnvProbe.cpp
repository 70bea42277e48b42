#include "render/EnvProbe.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <span>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "core/Log.h"
#include "gl/Pass.h"
#include "gl/ShaderShared.h"
#include "gl/Shader.h"
#include "render/EnvProbeBudget.h"

namespace gis {
namespace {

// Samples per texel of the environment-BRDF table (computed once; 32 x 32 x 1024 lobe samples).
constexpr int kBrdfTableSamples = 1024;

// The probe passes' timer names (the room probe's, a local probe's): noteTimings() sums them.
constexpr const char* kRenderPass[2] = {"env_render", "env_render_local"};
constexpr const char* kPrefilterPass[2] = {"env_prefilter", "env_prefilter_local"};

int log2Floor(int v) {
    return v > 1 ? std::bit_width(static_cast<unsigned>(v)) - 1 : 0;
}

} // namespace

struct EnvProbe::Impl {
    ForwardProgram forward;
    /// What the prefiltered cubes were asked for (probes, sizes, budget, shading switches, the
    /// scene); with the light views reused and the same key, a frame keeps them and their plan.
    std::string cubesKey;
    /// The probes' measured cost (env_budget_ms), for the scene and the prefilter's samples it was
    /// measured with.
    EnvProbeCostModel cost;
    std::pair<const void*, std::size_t> costScene{nullptr, 0};
    int costSamples = 0;
    EnvProbePlan plan;
    /// Set by a frame that rendered its cubes: what noteTimings() attributes the pass times to.
    int renderedSize = 0, renderedProbes = 0;
    long rendersSeen = 0;
    /// shaders/render/env_prefilter.comp: one roughness level of a cube from the source's mips.
    struct PrefilterPass {
        gl::Program program;
        gl::TextureUnit source;
        gl::ImageUnit dest;
        gl::UniformLocation size, roughness, samples, lobe, texelSolidAngle, maxSourceLod;
    } prefilter;
    /// shaders/render/env_apply.frag: prefiltered radiance x split-sum Fresnel over the eye view.
    struct ApplyPass {
        gl::Program program;
        gl::TextureUnit position, normal, specular, env, envBrdf;
        gl::TextureUnit local[kMaxLocalProbes];
        gl::UniformLocation probe, localProbe, localCount, boxMin, boxMax, parallax, maxRoughness, maxLod,
            skipMirrors;
    } apply;
    /// shaders/render/env_brdf_lut.comp: the environment-BRDF table, once.
    struct BrdfTablePass {
        gl::Program program;
        gl::ImageUnit lut;
        gl::UniformLocation size, samples;
    } brdfTable;
    gl::Texture lut; ///< kBrdfTableSize^2 RGBA32F: rg GGX (A, B), ba Phong (A, B)
    gl::VertexArray emptyVao;
    gl::Texture source; ///< rendered radiance cube, full mip chain
    /// Per probe (0: the room probe, 1..: local probes), level k = roughness k / (levels - 1).
    gl::Texture prefiltered[1 + kMaxLocalProbes];
    gl::Texture depth; ///< env_size^2, shared by the six faces
    gl::Framebuffer faceFbo[6];
    bool fboOk = false;
    int size = 0;
};

int EnvProbe::levelCount(int envSize) {
    return std::clamp(log2Floor(std::max(envSize, 1)) + 1, 1, kMaxLevels);
}

glm::mat4 EnvProbe::faceViewProj(int face, const glm::vec3& probe, float zNear, float zFar) {
    // The GL cube-map convention (OpenGL 4.5 §8.13): face images are stored with s to the right and
    // t downwards as seen from the centre, so each face's camera looks down its axis with "up" along
    // -t. A render with these cameras is read back by samplerCube in the same directions.
    static const glm::vec3 kDir[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    static const glm::vec3 kUp[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
    const int f = std::clamp(face, 0, 5);
    const glm::mat4 view = glm::lookAt(probe, probe + kDir[f], kUp[f]);
    return glm::perspective(glm::radians(90.0f), 1.0f, zNear, zFar) * view;
}

EnvProbe::EnvProbe() : mImpl(std::make_unique<Impl>()) {
    Impl& m = *mImpl;
    m.forward = ForwardProgram::build();
    // Filtered cube lookups across face edges, for every later frame (nothing turns it off).
    glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);

    Impl::PrefilterPass& f = m.prefilter;
    f.program = gl::Program::build({{GL_COMPUTE_SHADER, "render/env_prefilter.comp"}});
    f.source = f.program.textureUnit("uSource");
    f.dest = f.program.imageUnit("uDest");
    f.size = f.program.location("uSize");
    f.roughness = f.program.location("uRoughness");
    f.samples = f.program.location("uSamples");
    f.lobe = f.program.location("uLobe");
    f.texelSolidAngle = f.program.location("uTexelSolidAngle");
    f.maxSourceLod = f.program.location("uMaxSourceLod");

    Impl::ApplyPass& a = m.apply;
    a.program = gl::Program::build(
        {{GL_VERTEX_SHADER, "render/fullscreen.vert"}, {GL_FRAGMENT_SHADER, "render/env_apply.frag"}});
    a.position = a.program.textureUnit("gPosition");
    a.normal = a.program.textureUnit("gNormal");
    a.specular = a.program.textureUnit("gSpecular");
    a.env = a.program.textureUnit("uEnv");
    a.envBrdf = a.program.textureUnit("uEnvBrdf");
    for (int k = 0; k < kMaxLocalProbes; ++k)
        a.local[k] = a.program.textureUnit("uLocal" + std::to_string(k));
    a.probe = a.program.location("uProbe");
    a.localProbe = a.program.location("uLocalProbe");
    a.localCount = a.program.location("uLocalCount");
    a.boxMin = a.program.location("uBoxMin");
    a.boxMax = a.program.location("uBoxMax");
    a.parallax = a.program.location("uParallax");
    a.maxRoughness = a.program.location("uMaxRoughness");
    a.maxLod = a.program.location("uMaxLod");
    a.skipMirrors = a.program.location("uSkipMirrors");

    Impl::BrdfTablePass& b = m.brdfTable;
    b.program = gl::Program::build({{GL_COMPUTE_SHADER, "render/env_brdf_lut.comp"}});
    b.lut = b.program.imageUnit("uLut");
    b.size = b.program.location("uSize");
    b.samples = b.program.location("uSamples");
    m.emptyVao = gl::VertexArray::create();

    // The environment-BRDF table, once.
    m.lut = gl::Texture::create2D(GL_RGBA32F, kBrdfTableSize, kBrdfTableSize);
    m.lut.setFilter(GL_LINEAR, GL_LINEAR);
    {
        gl::Pass pass("env_brdf_table");
        const int groups = (kBrdfTableSize + 7) / 8;
        pass.use(b.program)
            .set(b.size, kBrdfTableSize)
            .set(b.samples, kBrdfTableSamples)
            .image(b.lut, m.lut, GL_WRITE_ONLY, GL_RGBA32F)
            .dispatch(groups, groups)
            .barrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    }
    gl::checkErrors("env probe: BRDF table");
}

EnvProbe::~EnvProbe() = default;

void EnvProbe::execute(const ReflectionInputs& in, const ParamSet& fp, const gl::Framebuffer& target,
                       gl::PassTimer& timer, Counters& counters) {
    Impl& m = *mImpl;
    const gl::Texture* gPosition = in.find("gbuffer.position");
    const gl::Texture* gNormal = in.find("gbuffer.normal");
    const gl::Texture* gSpecular = in.find("gbuffer.specular");
    const gl::Texture* shadowMap = in.find("lights.shadow");
    if (!in.scene || !in.sceneGpu || !gPosition || !gNormal || !gSpecular || in.width <= 0 || in.height <= 0)
        return;
    const int requestedSize = std::clamp(fp.getInt("env_size"), 8, 512);
    const int samples = std::clamp(fp.getInt("env_samples"), 1, 256);
    const bool parallax = fp.getEnum("env_parallax") == "box";
    const bool phong = fp.getEnum("specular_lobe") == "phong";
    const double budgetMs = fp.getFloat("env_budget_ms");
    m.renderedSize = m.renderedProbes = 0;

    const Bounds& bounds = in.scene->bounds;
    // Probe 0 sees the whole scene from the centre of the bounds; probe k >= 1 sits at the centre
    // of local object k - 1 and does not draw it (ReflectionInputs::envObjects).
    struct ProbeSpec {
        glm::vec3 position;
        int skipMesh;
    };
    std::vector<ProbeSpec> probes{{probePosition(bounds), -1}};
    if (in.envObjects)
        for (const EnvObject& o : *in.envObjects)
            if (static_cast<int>(probes.size()) < 1 + kMaxLocalProbes) probes.push_back({o.centre, o.mesh});
    const int wantedProbes = static_cast<int>(probes.size());

    std::ostringstream keyText;
    keyText << in.scene << '/' << requestedSize << '/' << samples << '/' << phong << '/' << budgetMs;
    for (const ProbeSpec& p : probes)
        keyText << '/' << p.position.x << ',' << p.position.y << ',' << p.position.z << ',' << p.skipMesh;
    if (in.frame)
        keyText << '/' << in.frame->rsmInfo.z << '/' << in.frame->rsmInfo.w << '/' << in.frame->toneInfo.z
                << '/' << in.frame->shadingInfo.x << '/' << in.frame->shadingInfo.z;
    const std::string key = keyText.str();
    const bool keepCubes = in.lightViewsReused && key == m.cubesKey && m.plan.size == m.size && m.fboOk;
    m.cubesKey = key;
    if (!keepCubes) {
        // The cost model belongs to one scene (its draws are most of a probe's cost). The plan
        // changes only here, when the cubes are rendered anyway.
        // The upload identifies the scene (a new scene gets a new upload; its triangle count guards
        // against an address reused after the old one was freed).
        const std::pair<const void*, std::size_t> sceneId{in.sceneGpu, in.sceneGpu->triangleCount()};
        // The prefilter's cost grows with its samples (up to 8x between the default 32 and 256), which
        // the model's face sizes do not show: measured afresh when they change.
        if (m.costScene != sceneId || m.costSamples != samples) {
            m.cost.clear();
            m.costScene = sceneId;
            m.costSamples = samples;
        }
        m.plan = planEnvProbes(requestedSize, wantedProbes, budgetMs, m.cost);
    }
    probes.resize(static_cast<size_t>(std::clamp(m.plan.probes, 1, wantedProbes)));
    const int size = std::clamp(m.plan.size, 8, 512);
    const int levels = levelCount(size);
    counters["env_size"] = size;
    counters["env_size_requested"] = requestedSize;
    counters["env_samples"] = samples;
    counters["env_levels"] = levels;
    counters["env_probes"] = static_cast<double>(probes.size());
    counters["env_probes_wanted"] = wantedProbes;
    counters["env_budget_ms"] = budgetMs;
    if (m.plan.predictedMs >= 0.0) counters["env_predicted_ms"] = m.plan.predictedMs;
    counters["env_cubes_reused"] = keepCubes ? 1 : 0;

    if (size != m.size) {
        m.source = gl::Texture::createCube(GL_RGBA16F, size, log2Floor(size) + 1);
        for (gl::Texture& c : m.prefiltered) c = gl::Texture::createCube(GL_RGBA16F, size, levels);
        m.depth = gl::Texture::create2D(GL_DEPTH_COMPONENT32F, size, size);
        m.fboOk = true;
        for (int f = 0; f < 6; ++f) {
            m.faceFbo[f] = gl::Framebuffer::create();
            m.faceFbo[f].attachColorLayer(0, m.source, f);
            m.faceFbo[f].attachDepth(m.depth);
            if (!m.faceFbo[f].tryFinish(1)) m.fboOk = false;
        }
        if (!m.fboOk)
            logWarn("env probe: cube-face framebuffer incomplete at env_size " + std::to_string(size));
        m.size = size;
    }
    if (!m.fboOk) return;
    // The first render also compiles the forward program's variants (llvmpipe compiles on first
    // draw): not a measurement of what the next one will cost.
    if (!keepCubes && m.rendersSeen++ > 0) {
        m.renderedSize = size;
        m.renderedProbes = static_cast<int>(probes.size());
    }
    // Depth range (m): everything in the bounds is within their diagonal of a probe inside them; the
    // near plane at 1e-3 of it (at least 0.1 mm) keeps 32-bit float depth well resolved.
    const float extent = std::max(glm::length(bounds.max - bounds.min), 1e-3f);
    const float zNear = std::max(1e-3f * extent, 1e-4f), zFar = 1.01f * extent + zNear;

    // Input may stop the frame between a probe's faces and its prefilter and between probes (the
    // first tile after a light change renders them, up to the whole frame target in the final step):
    // cubes left half rendered must not be kept, so the next frame renders them all again.
    auto stopped = [&] {
        if (!in.interrupted()) return false;
        m.cubesKey.clear();
        return true;
    };
    for (size_t p = 0; p < probes.size() && !keepCubes; ++p) {
        if (p > 0 && stopped()) return;
        const glm::vec3 probe = probes[p].position;
        const gl::Texture& prefiltered = m.prefiltered[p];

        // 1. Six faces, then the source mip chain.
        {
            const ForwardProgram& fw = m.forward;
            gl::Pass pass(timer, kRenderPass[p == 0 ? 0 : 1]);
            pass.depthTest(GL_LESS)
                .use(fw.program)
                .set(fw.clipPlane, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f))
                .set(fw.eye, probe)
                .texture(fw.shadowMap, shadowMap);
            for (int f = 0; f < 6; ++f) {
                pass.target(m.faceFbo[f], size, size).clearColor(1).clearDepth();
                const glm::mat4 face = faceViewProj(f, probe, zNear, zFar);
                pass.set(fw.viewProj, face);
                const DrawCount drawn =
                    in.sceneGpu->draw(fw.program, &fw.materials, 1, probes[p].skipMesh, &face, true);
                counters["triangles_env"] += static_cast<double>(drawn.drawn);
                counters["triangles_env_culled"] += static_cast<double>(drawn.culled);
                counters["draw_calls_env"] += static_cast<double>(drawn.calls);
            }
            m.source.generateMipmap();
        }
        if (stopped()) return;

        // 2. Prefilter: level 0 is the source itself, levels >= 1 one dispatch each.
        {
            const Impl::PrefilterPass& f = m.prefilter;
            gl::Pass pass(timer, kPrefilterPass[p == 0 ? 0 : 1]);
            glCopyImageSubData(m.source.id(), GL_TEXTURE_CUBE_MAP, 0, 0, 0, 0, prefiltered.id(),
                               GL_TEXTURE_CUBE_MAP, 0, 0, 0, 0, size, size, 6);
            pass.barrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT)
                .use(f.program)
                .texture(f.source, m.source)
                .set(f.samples, samples)
                .set(f.lobe, phong ? 1 : 0)
                .set(f.texelSolidAngle,
                     4.0f * 3.14159265f / (6.0f * static_cast<float>(size) * static_cast<float>(size)))
                .set(f.maxSourceLod, static_cast<float>(m.source.levels() - 1));
            for (int k = 1; k < levels; ++k) {
                const int levelSize = std::max(size >> k, 1);
                const int groups = (levelSize + 7) / 8;
                pass.set(f.size, levelSize)
                    .set(f.roughness, static_cast<float>(k) / static_cast<float>(levels - 1))
                    .imageLayered(f.dest, prefiltered, GL_WRITE_ONLY, GL_RGBA16F, k)
                    .dispatch(groups, groups, 6);
            }
            pass.barrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
        }
    }

    // 3. Apply over the eye view, added into the target.
    const Impl::ApplyPass& a = m.apply;
    gl::Pass pass(timer, "env_apply");
    pass.target(target, in.width, in.height)
        .blendAdd()
        .use(a.program)
        .texture(a.position, *gPosition)
        .texture(a.normal, *gNormal)
        .texture(a.specular, *gSpecular)
        .texture(a.env, m.prefiltered[0])
        .texture(a.envBrdf, m.lut);
    glm::vec3 local[kMaxLocalProbes]{};
    for (int k = 0; k < kMaxLocalProbes; ++k) {
        // Unused units get the room probe: a sampler must never read an incomplete texture.
        const bool used = k + 1 < static_cast<int>(probes.size());
        pass.texture(a.local[k], m.prefiltered[used ? k + 1 : 0]);
        local[k] = used ? probes[static_cast<size_t>(k) + 1].position : probes[0].position;
    }
    pass.set(a.probe, probes[0].position)
        .set(a.localProbe, std::span<const glm::vec3>(local))
        .set(a.localCount, static_cast<int>(probes.size()) - 1)
        .set(a.boxMin, bounds.min)
        .set(a.boxMax, bounds.max)
        .set(a.parallax, parallax ? 1 : 0)
        .set(a.maxRoughness, in.envMaxRoughness)
        .set(a.maxLod, static_cast<float>(levels - 1))
        .set(a.skipMirrors, in.mirrorPass ? 1 : 0);
    pass.drawFullscreen(m.emptyVao);
}

void EnvProbe::noteTimings(const std::vector<gl::PassTiming>& passes) {
    Impl& m = *mImpl;
    if (m.renderedProbes <= 0) return;
    double ms = 0.0;
    for (const gl::PassTiming& p : passes)
        for (int k = 0; k < 2; ++k)
            if (p.name == kRenderPass[k] || p.name == kPrefilterPass[k]) ms += p.gpuMs;
    m.cost.record(m.renderedSize, m.renderedProbes, ms);
    m.renderedSize = m.renderedProbes = 0;
}

const std::string& EnvProbe::planReason() const {
    return mImpl->plan.reason;
}

} // namespace gis
