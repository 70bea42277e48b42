#include "render/EnvProbe.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "core/Log.h"
#include "gl/Shader.h"

namespace gis {
namespace {

// Samples per texel of the environment-BRDF table (computed once; 32 x 32 x 1024 lobe samples).
constexpr int kBrdfTableSamples = 1024;

// A cube-map texture owned here (gl::Texture has no cube-map constructor).
struct CubeTexture {
    GLuint id = 0;
    int size = 0, levels = 0;
    CubeTexture() = default;
    CubeTexture(const CubeTexture&) = delete;
    CubeTexture& operator=(const CubeTexture&) = delete;
    ~CubeTexture() { reset(); }
    void reset() {
        if (id) glDeleteTextures(1, &id);
        id = 0;
        size = levels = 0;
    }
    void create(int faceSize, int levelCount) {
        reset();
        glCreateTextures(GL_TEXTURE_CUBE_MAP, 1, &id);
        glTextureStorage2D(id, levelCount, GL_RGBA16F, faceSize, faceSize);
        glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
        glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glTextureParameteri(id, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
        glTextureParameteri(id, GL_TEXTURE_MAX_LEVEL, levelCount - 1);
        size = faceSize;
        levels = levelCount;
    }
};

int log2Floor(int v) {
    return v > 1 ? std::bit_width(static_cast<unsigned>(v)) - 1 : 0;
}

} // namespace

struct EnvProbe::Impl {
    gl::Program forward, prefilter, apply, brdfTable;
    MaterialSlots forwardMaterials;
    gl::Texture lut; ///< kBrdfTableSize^2 RGBA32F: rg GGX (A, B), ba Phong (A, B)
    gl::VertexArray emptyVao;
    CubeTexture source; ///< rendered radiance, full mip chain
    /// Per probe (0: the room probe, 1..: local probes), level k = roughness k / (levels - 1).
    CubeTexture prefiltered[1 + kMaxLocalProbes];
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
    m.forward = gl::Program::build(
        {{GL_VERTEX_SHADER, "render/forward.vert"}, {GL_FRAGMENT_SHADER, "render/forward.frag"}});
    m.forwardMaterials = MaterialSlots::of(m.forward);
    m.prefilter = gl::Program::build({{GL_COMPUTE_SHADER, "render/env_prefilter.comp"}});
    m.apply = gl::Program::build(
        {{GL_VERTEX_SHADER, "render/fullscreen.vert"}, {GL_FRAGMENT_SHADER, "render/env_apply.frag"}});
    m.brdfTable = gl::Program::build({{GL_COMPUTE_SHADER, "render/env_brdf_lut.comp"}});
    m.emptyVao = gl::VertexArray::create();

    // The environment-BRDF table, once.
    m.lut = gl::Texture::create2D(GL_RGBA32F, kBrdfTableSize, kBrdfTableSize);
    m.lut.setFilter(GL_LINEAR, GL_LINEAR);
    glUseProgram(m.brdfTable.id());
    glUniform1i(m.brdfTable.uniform("uSize"), kBrdfTableSize);
    glUniform1i(m.brdfTable.uniform("uSamples"), kBrdfTableSamples);
    glBindImageTexture(0, m.lut.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    const GLuint groups = (kBrdfTableSize + 7) / 8;
    glDispatchCompute(groups, groups, 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    glBindImageTexture(0, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    gl::checkErrors("env probe: BRDF table");
}

EnvProbe::~EnvProbe() = default;

void EnvProbe::execute(const ReflectionInputs& in, const ParamSet& fp, const gl::Framebuffer& target,
                       gl::PassTimer& timer, Counters& counters) {
    Impl& m = *mImpl;
    if (!in.scene || !in.sceneGpu || !in.gPosition || !in.gNormal || !in.gSpecular || in.width <= 0 ||
        in.height <= 0)
        return;
    const int size = std::clamp(fp.getInt("env_size"), 8, 512);
    const int samples = std::clamp(fp.getInt("env_samples"), 1, 256);
    const bool parallax = fp.getEnum("env_parallax") == "box";
    const bool phong = fp.getEnum("specular_lobe") == "phong";
    const int levels = levelCount(size);
    counters["env_size"] = size;
    counters["env_samples"] = samples;
    counters["env_levels"] = levels;

    if (size != m.size) {
        const int sourceLevels = log2Floor(size) + 1;
        m.source.create(size, sourceLevels);
        for (CubeTexture& c : m.prefiltered) c.create(size, levels);
        m.depth = gl::Texture::create2D(GL_DEPTH_COMPONENT32F, size, size);
        m.fboOk = true;
        for (int f = 0; f < 6; ++f) {
            m.faceFbo[f] = gl::Framebuffer::create();
            glNamedFramebufferTextureLayer(m.faceFbo[f].id(), GL_COLOR_ATTACHMENT0, m.source.id, 0, f);
            glNamedFramebufferTexture(m.faceFbo[f].id(), GL_DEPTH_ATTACHMENT, m.depth.id(), 0);
            glNamedFramebufferDrawBuffer(m.faceFbo[f].id(), GL_COLOR_ATTACHMENT0);
            if (glCheckNamedFramebufferStatus(m.faceFbo[f].id(), GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
                m.fboOk = false;
        }
        if (!m.fboOk)
            logWarn("env probe: cube-face framebuffer incomplete at env_size " + std::to_string(size));
        m.size = size;
    }
    if (!m.fboOk) return;

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
    counters["env_probes"] = static_cast<double>(probes.size());
    // Depth range (m): everything in the bounds is within their diagonal of a probe inside them; the
    // near plane at 1e-3 of it (at least 0.1 mm) keeps 32-bit float depth well resolved.
    const float extent = std::max(glm::length(bounds.max - bounds.min), 1e-3f);
    const float zNear = std::max(1e-3f * extent, 1e-4f), zFar = 1.01f * extent + zNear;
    glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    const float zero[4] = {0, 0, 0, 0};
    const float one = 1.0f;

    for (size_t p = 0; p < probes.size(); ++p) {
        const glm::vec3 probe = probes[p].position;
        CubeTexture& prefiltered = m.prefiltered[p];

        // 1. Six faces, then the source mip chain.
        timer.begin(p == 0 ? "env_render" : "env_render_local");
        glDisable(GL_BLEND);
        glDisable(GL_CULL_FACE);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        glViewport(0, 0, size, size);
        glUseProgram(m.forward.id());
        glUniform4f(m.forward.uniform("uClipPlane"), 0.0f, 0.0f, 0.0f, 1.0f);
        glUniform3fv(m.forward.uniform("uEye"), 1, &probe.x);
        if (in.shadowMap) glBindTextureUnit(4, in.shadowMap->id());
        for (int f = 0; f < 6; ++f) {
            glBindFramebuffer(GL_FRAMEBUFFER, m.faceFbo[f].id());
            glClearNamedFramebufferfv(m.faceFbo[f].id(), GL_COLOR, 0, zero);
            glClearNamedFramebufferfv(m.faceFbo[f].id(), GL_DEPTH, 0, &one);
            const glm::mat4 vp = faceViewProj(f, probe, zNear, zFar);
            glUniformMatrix4fv(m.forward.uniform("uViewProj"), 1, GL_FALSE, &vp[0][0]);
            in.sceneGpu->draw(m.forward, &m.forwardMaterials, 1, probes[p].skipMesh);
        }
        glDisable(GL_DEPTH_TEST);
        glGenerateTextureMipmap(m.source.id);
        timer.end();

        // 2. Prefilter: level 0 is the source itself, levels >= 1 one dispatch each.
        timer.begin(p == 0 ? "env_prefilter" : "env_prefilter_local");
        glCopyImageSubData(m.source.id, GL_TEXTURE_CUBE_MAP, 0, 0, 0, 0, prefiltered.id, GL_TEXTURE_CUBE_MAP,
                           0, 0, 0, 0, size, size, 6);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        glUseProgram(m.prefilter.id());
        glBindTextureUnit(0, m.source.id);
        glUniform1i(m.prefilter.uniform("uSamples"), samples);
        glUniform1i(m.prefilter.uniform("uLobe"), phong ? 1 : 0);
        glUniform1f(m.prefilter.uniform("uTexelSolidAngle"),
                    4.0f * 3.14159265f / (6.0f * static_cast<float>(size) * static_cast<float>(size)));
        glUniform1f(m.prefilter.uniform("uMaxSourceLod"), static_cast<float>(m.source.levels - 1));
        for (int k = 1; k < levels; ++k) {
            const int levelSize = std::max(size >> k, 1);
            glUniform1i(m.prefilter.uniform("uSize"), levelSize);
            glUniform1f(m.prefilter.uniform("uRoughness"),
                        static_cast<float>(k) / static_cast<float>(levels - 1));
            glBindImageTexture(0, prefiltered.id, k, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA16F);
            const GLuint groups = static_cast<GLuint>((levelSize + 7) / 8);
            glDispatchCompute(groups, groups, 6);
        }
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
        glBindImageTexture(0, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
        timer.end();
    }

    // 3. Apply over the eye view, added into the target.
    timer.begin("env_apply");
    glBindFramebuffer(GL_FRAMEBUFFER, target.id());
    glViewport(0, 0, in.width, in.height);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    glUseProgram(m.apply.id());
    glBindTextureUnit(0, in.gPosition->id());
    glBindTextureUnit(1, in.gNormal->id());
    glBindTextureUnit(2, in.gSpecular->id());
    glBindTextureUnit(3, m.prefiltered[0].id);
    glBindTextureUnit(5, m.lut.id());
    glUniform3fv(m.apply.uniform("uProbe"), 1, &probes[0].position.x);
    glm::vec3 local[kMaxLocalProbes]{};
    for (int k = 0; k < kMaxLocalProbes; ++k) {
        // Unused units get the room probe: a sampler must never read an incomplete texture.
        const bool used = k + 1 < static_cast<int>(probes.size());
        glBindTextureUnit(6 + k, m.prefiltered[used ? k + 1 : 0].id);
        local[k] = used ? probes[static_cast<size_t>(k) + 1].position : probes[0].position;
    }
    glUniform3fv(m.apply.uniform("uLocalProbe"), kMaxLocalProbes, &local[0].x);
    glUniform1i(m.apply.uniform("uLocalCount"), static_cast<int>(probes.size()) - 1);
    glUniform3fv(m.apply.uniform("uBoxMin"), 1, &bounds.min.x);
    glUniform3fv(m.apply.uniform("uBoxMax"), 1, &bounds.max.x);
    glUniform1i(m.apply.uniform("uParallax"), parallax ? 1 : 0);
    glUniform1f(m.apply.uniform("uMaxRoughness"), in.envMaxRoughness);
    glUniform1f(m.apply.uniform("uMaxLod"), static_cast<float>(levels - 1));
    glUniform1i(m.apply.uniform("uSkipMirrors"), in.mirrorPass ? 1 : 0);
    glBindVertexArray(m.emptyVao.id());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDisable(GL_BLEND);
    timer.end();
    gl::logErrors("env probe");
}

} // namespace gis
