#include "render/PlanarMirrors.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <glm/gtc/type_ptr.hpp>

#include "gl/ShaderShared.h"

namespace gis {

glm::mat4 mirrorReflection(glm::vec3 point, glm::vec3 normal) {
    const float len2 = glm::dot(normal, normal);
    const glm::vec3 n = len2 > 1e-24f ? normal / std::sqrt(len2) : glm::vec3(0, 1, 0);
    const float d = -glm::dot(n, point); // plane: dot(n, x) + d = 0
    // x' = x - 2 (dot(n, x) + d) n, column-major.
    glm::mat4 r(1.0f);
    for (int c = 0; c < 3; ++c)
        for (int row = 0; row < 3; ++row) r[c][row] -= 2.0f * n[row] * n[c];
    for (int row = 0; row < 3; ++row) r[3][row] = -2.0f * d * n[row];
    return r;
}

int mirrorViewBound(int mirrors, int depth) {
    const int m = std::clamp(mirrors, 0, kMaxMirrors);
    int total = 0, level = m;
    for (int k = 1; k <= std::clamp(depth, 0, kMaxMirrorDepth); ++k) {
        total += level;
        level *= std::max(m - 1, 0);
    }
    return std::min(total, kMaxMirrorViews);
}

namespace {

// A view whose eye is closer to a mirror's plane than this (m), or behind it, gets no reflection in
// that mirror: it sees the mirror's back or only its edge.
constexpr float kMinEyeDistance = 1e-5f;
// The clip plane sits this fraction of the scene's extent in front of the mirror (dimensionless), so
// the mirror itself and geometry coplanar with it are not drawn into its own reflection.
constexpr float kClipOffsetPerExtent = 1e-4f;
// Glossy blur (shaders/render/mirror_blur.frag, same constants): reflected-lobe sigma per GGX alpha
// (radians), the widest kernel sigma (px) and the narrowest worth a pass (px).
constexpr float kLobeSigmaPerAlpha = 1.1f;
constexpr float kMaxBlurSigmaPx = 8.0f;
constexpr float kMinBlurSigmaPx = 0.25f;

// One mirrored view: the chain eye -> m1 -> ... -> mk.
struct View {
    int level = 0;           // k, 1..kMaxMirrorDepth
    int parent = -1;         // index into the view list; -1: the eye
    int mirror = -1;         // index into the mirror list (mk)
    glm::ivec3 chain{0};     // mirror ids (index + 1) m1..mk, 0 beyond k
    glm::mat4 reflect{1.0f}; // R_m1 ... R_mk: world -> the eye's world as seen through the chain
    glm::vec3 eye{0.0f};     // the mirrored camera (m)
    int stencil = 0;         // stencil value of the view at its level, 1..255
};

struct Level {
    gl::Texture radiance, position, mirrorId, depthStencil;
    gl::Framebuffer renderFbo;  // radiance, position, mirror id + depth-stencil
    gl::Framebuffer colorFbo;   // radiance only (indirect, blur output, children's apply)
    gl::Framebuffer stencilFbo; // depth-stencil only
};

} // namespace

struct PlanarMirrors::Impl {
    gl::Program stencil, forward, indirect, blur, apply;
    MaterialSlots forwardMaterials;
    gl::VertexArray emptyVao;
    gl::Query anySamples;
    int width = 0, height = 0;
    std::vector<Level> levels;
    gl::Texture blurTemp;
    gl::Framebuffer blurFbo;

    void ensureTargets(int w, int h, int depth) {
        if (w != width || h != height) {
            levels.clear();
            blurTemp = gl::Texture::create2D(GL_RGBA32F, w, h);
            blurFbo = gl::Framebuffer::create();
            blurFbo.attachColor(0, blurTemp);
            blurFbo.finish(1, "mirror blur");
            width = w;
            height = h;
        }
        while (static_cast<int>(levels.size()) < depth) {
            Level l;
            l.radiance = gl::Texture::create2D(GL_RGBA32F, w, h);
            l.position = gl::Texture::create2D(GL_RGBA32F, w, h);
            l.mirrorId = gl::Texture::create2D(GL_R16F, w, h);
            l.depthStencil = gl::Texture::create2D(GL_DEPTH24_STENCIL8, w, h);
            const std::string label = "mirror level " + std::to_string(levels.size() + 1);
            l.renderFbo = gl::Framebuffer::create();
            l.renderFbo.attachColor(0, l.radiance);
            l.renderFbo.attachColor(1, l.position);
            l.renderFbo.attachColor(2, l.mirrorId);
            l.renderFbo.attachDepthStencil(l.depthStencil);
            l.renderFbo.finish(3, label);
            l.colorFbo = gl::Framebuffer::create();
            l.colorFbo.attachColor(0, l.radiance);
            l.colorFbo.finish(1, label + " colour");
            l.stencilFbo = gl::Framebuffer::create();
            l.stencilFbo.attachDepthStencil(l.depthStencil);
            l.stencilFbo.finish(0, label + " stencil");
            levels.push_back(std::move(l));
        }
    }

    void setRegion(const gl::Program& p, const View& v) const {
        glUniform1i(p.uniform("uLevel"), v.level);
        glUniform3i(p.uniform("uChain"), v.chain.x, v.chain.y, v.chain.z);
    }
};

PlanarMirrors::PlanarMirrors() : mImpl(std::make_unique<Impl>()) {
    const gl::ShaderStage fullscreen{GL_VERTEX_SHADER, "render/fullscreen.vert"};
    mImpl->stencil = gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "render/mirror_stencil.frag"}});
    mImpl->forward = gl::Program::build(
        {{GL_VERTEX_SHADER, "render/forward.vert"}, {GL_FRAGMENT_SHADER, "render/forward.frag"}});
    mImpl->forwardMaterials = MaterialSlots::of(mImpl->forward);
    mImpl->indirect = gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "render/mirror_indirect.frag"}});
    mImpl->blur = gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "render/mirror_blur.frag"}});
    mImpl->apply = gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "render/mirror_apply.frag"}});
    mImpl->emptyVao = gl::VertexArray::create();
    mImpl->anySamples = gl::Query::create(GL_ANY_SAMPLES_PASSED);
    gl::checkErrors("planar mirrors setup");
}

PlanarMirrors::~PlanarMirrors() = default;

void PlanarMirrors::execute(const ReflectionInputs& in, const ParamSet& fp, const gl::Framebuffer& target,
                            gl::PassTimer& timer, Counters& counters) {
    counters["mirror_views"] = 0;
    const int depth = std::clamp(static_cast<int>(fp.getInt("mirror_depth")), 0, kMaxMirrorDepth);
    if (depth == 0 || !in.mirrors || in.mirrors->empty() || !in.frame || !in.sceneGpu || !in.gNormal ||
        !in.gPosition || in.width <= 0 || in.height <= 0)
        return;
    const std::vector<MirrorPlane>& mirrors = *in.mirrors;
    const int mirrorCount = std::min(static_cast<int>(mirrors.size()), kMaxMirrors);
    const bool blurOn = fp.getEnum("mirror_blur") == "on";
    Impl& s = *mImpl;
    s.ensureTargets(in.width, in.height, depth);

    float extent = 1.0f;
    if (in.scene) extent = std::max(glm::length(in.scene->bounds.max - in.scene->bounds.min), 1e-3f);
    const float clipOffset = kClipOffsetPerExtent * extent;
    const glm::vec3 camera(in.frame->cameraPos);
    const glm::mat4 viewProj = in.frame->viewProj;
    // P11 = 1 / tan(fov_y / 2): the length of the view-projection's row 1 (the view's rows are unit).
    const float p11 = glm::length(glm::vec3(viewProj[0][1], viewProj[1][1], viewProj[2][1]));

    std::array<glm::mat4, kMaxMirrors> reflections;
    std::array<glm::vec3, kMaxMirrors> normals;
    for (int i = 0; i < mirrorCount; ++i) {
        const MirrorPlane& m = mirrors[static_cast<size_t>(i)];
        const float n2 = glm::dot(m.normal, m.normal);
        normals[static_cast<size_t>(i)] = n2 > 1e-24f ? m.normal / std::sqrt(n2) : glm::vec3(0, 1, 0);
        reflections[static_cast<size_t>(i)] = mirrorReflection(m.point, normals[static_cast<size_t>(i)]);
    }

    const float zero[4] = {0, 0, 0, 0};
    const float one = 1.0f;
    const GLint zeroStencil = 0;
    glViewport(0, 0, in.width, in.height);
    glDisable(GL_SCISSOR_TEST);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glBindVertexArray(s.emptyVao.id());
    glBindTextureUnit(1, in.gNormal->id());

    // Breadth first: level k's views, their stencil marks and renders, need level k-1's mirror ids.
    std::vector<View> views;
    std::vector<int> previous{-1}; // the eye
    int levelsUsed = 0;
    for (int level = 1; level <= depth && !previous.empty(); ++level) {
        Level& L = s.levels[static_cast<size_t>(level - 1)];
        // Built in two steps: GCC 12 reports a false -Wrestrict for "_" + std::to_string(level).
        std::string suffix;
        if (level > 1) suffix.append("_").append(std::to_string(level));
        // Candidates: every mirror a parent view faces from its front side, except the one it was
        // made by (it cannot see itself), up to the total view bound.
        std::vector<View> candidates;
        for (int parent : previous) {
            const View* pv = parent >= 0 ? &views[static_cast<size_t>(parent)] : nullptr;
            const glm::vec3 eye = pv ? pv->eye : camera;
            for (int i = 0; i < mirrorCount; ++i) {
                if (pv && pv->mirror == i) continue;
                const MirrorPlane& m = mirrors[static_cast<size_t>(i)];
                if (!(glm::dot(eye - m.point, normals[static_cast<size_t>(i)]) > kMinEyeDistance)) continue;
                View v;
                v.level = level;
                v.parent = parent;
                v.mirror = i;
                v.chain = pv ? pv->chain : glm::ivec3(0);
                v.chain[level - 1] = i + 1;
                v.reflect = (pv ? pv->reflect : glm::mat4(1.0f)) * reflections[static_cast<size_t>(i)];
                v.eye = glm::vec3(reflections[static_cast<size_t>(i)] * glm::vec4(eye, 1.0f));
                v.stencil = static_cast<int>(candidates.size()) + 1;
                candidates.push_back(v);
            }
        }
        if (candidates.empty()) break;

        // 1. Stencil: each candidate's pixels get its stencil value; empty views are dropped.
        timer.begin("mirror_stencil" + suffix);
        glDepthMask(GL_TRUE); // clears obey the write masks
        glStencilMask(0xFF);
        for (int i = 0; i < 3; ++i) glClearNamedFramebufferfv(L.renderFbo.id(), GL_COLOR, i, zero);
        glClearNamedFramebufferfi(L.renderFbo.id(), GL_DEPTH_STENCIL, 0, one, zeroStencil);
        glBindFramebuffer(GL_FRAMEBUFFER, L.stencilFbo.id());
        glDisable(GL_DEPTH_TEST);
        glEnable(GL_STENCIL_TEST);
        glStencilMask(0xFF);
        glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
        glUseProgram(s.stencil.id());
        if (level >= 2) glBindTextureUnit(2, s.levels[0].mirrorId.id());
        if (level >= 3) glBindTextureUnit(3, s.levels[1].mirrorId.id());
        std::vector<View> visible;
        for (View& v : candidates) {
            if (static_cast<int>(views.size() + visible.size()) >= kMaxMirrorViews) break;
            glStencilFunc(GL_ALWAYS, v.stencil, 0xFF);
            s.setRegion(s.stencil, v);
            glBeginQuery(GL_ANY_SAMPLES_PASSED, s.anySamples.id());
            glDrawArrays(GL_TRIANGLES, 0, 3);
            glEndQuery(GL_ANY_SAMPLES_PASSED);
            GLuint any = 0;
            glGetQueryObjectuiv(s.anySamples.id(), GL_QUERY_RESULT, &any);
            if (any) visible.push_back(v);
        }
        timer.end();
        if (visible.empty()) break;

        // 2. Render the scene mirrored about each view's chain into its pixels (stencil equal), with
        //    its own depth test and the mirror's front half-space as the clip plane.
        timer.begin("mirror_render" + suffix);
        glBindFramebuffer(GL_FRAMEBUFFER, L.renderFbo.id());
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        glStencilMask(0x00);
        glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
        glEnable(GL_CLIP_DISTANCE0);
        glUseProgram(s.forward.id());
        if (in.shadowMap) glBindTextureUnit(4, in.shadowMap->id());
        const GLint viewProjLoc = s.forward.uniform("uViewProj");
        const GLint clipLoc = s.forward.uniform("uClipPlane");
        const GLint eyeLoc = s.forward.uniform("uEye");
        previous.clear();
        for (View& v : visible) {
            const glm::mat4 vp = viewProj * v.reflect;
            const glm::vec3 n = normals[static_cast<size_t>(v.mirror)];
            const float d = -glm::dot(n, mirrors[static_cast<size_t>(v.mirror)].point) - clipOffset;
            // A reflection flips the winding; culling is off in this renderer, but keep GL's notion
            // of front faces right for anything that enables it.
            const bool odd = (v.level % 2) == 1;
            glFrontFace(odd ? GL_CW : GL_CCW);
            glStencilFunc(GL_EQUAL, v.stencil, 0xFF);
            glUniformMatrix4fv(viewProjLoc, 1, GL_FALSE, glm::value_ptr(vp));
            glUniform4f(clipLoc, n.x, n.y, n.z, d);
            glUniform3f(eyeLoc, v.eye.x, v.eye.y, v.eye.z);
            in.sceneGpu->draw(s.forward, &s.forwardMaterials);
            previous.push_back(static_cast<int>(views.size()));
            views.push_back(v);
        }
        glFrontFace(GL_CCW);
        glDisable(GL_CLIP_DISTANCE0);
        glDisable(GL_STENCIL_TEST);
        glDisable(GL_DEPTH_TEST);
        // Indirect light where the reflected points are also seen by the eye.
        if (in.indirect) {
            glBindFramebuffer(GL_FRAMEBUFFER, L.colorFbo.id());
            glEnable(GL_BLEND);
            glBlendFunc(GL_ONE, GL_ONE);
            glUseProgram(s.indirect.id());
            glBindTextureUnit(5, in.indirect->id());
            glBindTextureUnit(6, in.gPosition->id());
            glBindTextureUnit(7, L.position.id());
            glBindVertexArray(s.emptyVao.id());
            glDrawArrays(GL_TRIANGLES, 0, 3);
            glDisable(GL_BLEND);
        }
        glBindVertexArray(s.emptyVao.id());
        timer.end();
        levelsUsed = level;
    }
    glStencilMask(0xFF);
    counters["mirror_views"] = static_cast<double>(views.size());
    if (views.empty()) return;

    // 3. From the deepest level up: blur (optional) each view's radiance, then add Fresnel x radiance
    //    into its parent (the target at level 1).
    timer.begin("mirror_apply");
    glBindVertexArray(s.emptyVao.id());
    glBindTextureUnit(1, in.gNormal->id());
    if (levelsUsed >= 2) glBindTextureUnit(2, s.levels[0].mirrorId.id());
    if (levelsUsed >= 3) glBindTextureUnit(3, s.levels[1].mirrorId.id());
    for (int level = levelsUsed; level >= 1; --level) {
        Level& L = s.levels[static_cast<size_t>(level - 1)];
        const gl::Texture& parentPos =
            level == 1 ? *in.gPosition : s.levels[static_cast<size_t>(level - 2)].position;
        for (const View& v : views) {
            if (v.level != level) continue;
            const MirrorPlane& m = mirrors[static_cast<size_t>(v.mirror)];
            const glm::vec3 parentEye = v.parent >= 0 ? views[static_cast<size_t>(v.parent)].eye : camera;
            // The widest blur kernel of this view (px): the lobe's spread over the reflected distance d,
            // projected at the virtual depth w >= d cos(off-axis angle); the factor 2 covers off-axis
            // angles up to 60 degrees. Mirrors whose bound is under kMinBlurSigmaPx are not blurred.
            const float lobe =
                std::min(kLobeSigmaPerAlpha * std::max(m.roughness * m.roughness, 2e-3f), 1.2f);
            const float maxSigma =
                std::min(kMaxBlurSigmaPx, 2.0f * std::tan(lobe) * 0.5f * static_cast<float>(in.height) * p11);
            if (blurOn && maxSigma >= kMinBlurSigmaPx) {
                glDisable(GL_BLEND);
                glUseProgram(s.blur.id());
                s.setRegion(s.blur, v);
                glUniform1f(s.blur.uniform("uRoughness"), m.roughness);
                glUniform1f(s.blur.uniform("uMaxSigmaPx"), maxSigma);
                const glm::mat4 vp = viewProj * v.reflect;
                glUniformMatrix4fv(s.blur.uniform("uViewProjChain"), 1, GL_FALSE, glm::value_ptr(vp));
                glBindTextureUnit(6, parentPos.id());
                glBindTextureUnit(7, L.position.id());
                glBindFramebuffer(GL_FRAMEBUFFER, s.blurFbo.id());
                glUniform2i(s.blur.uniform("uDirection"), 1, 0);
                glBindTextureUnit(5, L.radiance.id());
                glDrawArrays(GL_TRIANGLES, 0, 3);
                glBindFramebuffer(GL_FRAMEBUFFER, L.colorFbo.id());
                glUniform2i(s.blur.uniform("uDirection"), 0, 1);
                glBindTextureUnit(5, s.blurTemp.id());
                glDrawArrays(GL_TRIANGLES, 0, 3);
            }
            glBindFramebuffer(GL_FRAMEBUFFER, level == 1
                                                  ? target.id()
                                                  : s.levels[static_cast<size_t>(level - 2)].colorFbo.id());
            glEnable(GL_BLEND);
            glBlendFunc(GL_ONE, GL_ONE);
            glUseProgram(s.apply.id());
            s.setRegion(s.apply, v);
            glUniform3f(s.apply.uniform("uParentEye"), parentEye.x, parentEye.y, parentEye.z);
            const glm::vec3 n = normals[static_cast<size_t>(v.mirror)];
            glUniform3f(s.apply.uniform("uMirrorNormal"), n.x, n.y, n.z);
            glUniform3f(s.apply.uniform("uF0"), m.f0.r, m.f0.g, m.f0.b);
            glBindTextureUnit(5, L.radiance.id());
            glBindTextureUnit(6, parentPos.id());
            glDrawArrays(GL_TRIANGLES, 0, 3);
            glDisable(GL_BLEND);
        }
    }
    timer.end();
    glDisable(GL_BLEND);
}

} // namespace gis
