#include "render/PlanarMirrors.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "gl/Pass.h"
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

/// The uniforms and samplers of shaders/render/mirror_region.glsl in one program.
struct RegionSlots {
    gl::UniformLocation level, chain;
    gl::TextureUnit idEye, id1, id2;
    static RegionSlots of(const gl::Program& p) {
        return {p.location("uLevel"), p.location("uChain"), p.textureUnit("gMirrorIdEye"),
                p.textureUnit("gMirrorId1"), p.textureUnit("gMirrorId2")};
    }
};

} // namespace

struct PlanarMirrors::Impl {
    /// shaders/render/mirror_stencil.frag: marks one view's pixels.
    struct StencilPass {
        gl::Program program;
        RegionSlots region;
    } stencil;
    ForwardProgram forward;
    /// shaders/render/mirror_indirect.frag: the eye's indirect light at reflected points it also sees.
    struct IndirectPass {
        gl::Program program;
        gl::TextureUnit indirect, position, viewPosition;
    } indirect;
    /// shaders/render/mirror_blur.frag: one direction of a view's glossy blur.
    struct BlurPass {
        gl::Program program;
        RegionSlots region;
        gl::TextureUnit source, mirrorPosition, reflectPosition;
        gl::UniformLocation direction, roughness, viewProjChain, maxSigmaPx;
    } blur;
    /// shaders/render/mirror_apply.frag: Fresnel x a view's radiance, added into its parent.
    struct ApplyPass {
        gl::Program program;
        RegionSlots region;
        gl::TextureUnit reflected, mirrorPosition;
        gl::UniformLocation parentEye, mirrorNormal, f0;
    } apply;
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
            blurFbo = gl::Framebuffer::of("mirror blur", {&blurTemp});
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
            l.renderFbo =
                gl::Framebuffer::of(label, {&l.radiance, &l.position, &l.mirrorId}, &l.depthStencil);
            l.colorFbo = gl::Framebuffer::of(label + " colour", {&l.radiance});
            l.stencilFbo = gl::Framebuffer::of(label + " stencil", {}, &l.depthStencil);
            levels.push_back(std::move(l));
        }
    }

    /// Selects view `v`'s pixels in a program reading mirror_region.glsl: its chain, and the mirror
    /// ids of the eye and of the levels above it.
    void setRegion(gl::Pass& pass, const RegionSlots& r, const View& v, const gl::Texture& eyeIds) const {
        pass.set(r.level, v.level).set(r.chain, v.chain).texture(r.idEye, eyeIds);
        if (v.level >= 2) pass.texture(r.id1, levels[0].mirrorId);
        if (v.level >= 3) pass.texture(r.id2, levels[1].mirrorId);
    }
};

PlanarMirrors::PlanarMirrors() : mImpl(std::make_unique<Impl>()) {
    Impl& s = *mImpl;
    const gl::ShaderStage fullscreen{GL_VERTEX_SHADER, "render/fullscreen.vert"};
    s.stencil.program = gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "render/mirror_stencil.frag"}});
    s.stencil.region = RegionSlots::of(s.stencil.program);
    s.forward = ForwardProgram::build();

    Impl::IndirectPass& i = s.indirect;
    i.program = gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "render/mirror_indirect.frag"}});
    i.indirect = i.program.textureUnit("gIndirect");
    i.position = i.program.textureUnit("gPosition");
    i.viewPosition = i.program.textureUnit("gViewPos");

    Impl::BlurPass& b = s.blur;
    b.program = gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "render/mirror_blur.frag"}});
    b.region = RegionSlots::of(b.program);
    b.source = b.program.textureUnit("gSource");
    b.mirrorPosition = b.program.textureUnit("gMirrorPos");
    b.reflectPosition = b.program.textureUnit("gReflectPos");
    b.direction = b.program.location("uDirection");
    b.roughness = b.program.location("uRoughness");
    b.viewProjChain = b.program.location("uViewProjChain");
    b.maxSigmaPx = b.program.location("uMaxSigmaPx");

    Impl::ApplyPass& a = s.apply;
    a.program = gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "render/mirror_apply.frag"}});
    a.region = RegionSlots::of(a.program);
    a.reflected = a.program.textureUnit("gReflected");
    a.mirrorPosition = a.program.textureUnit("gMirrorPos");
    a.parentEye = a.program.location("uParentEye");
    a.mirrorNormal = a.program.location("uMirrorNormal");
    a.f0 = a.program.location("uF0");

    s.emptyVao = gl::VertexArray::create();
    s.anySamples = gl::Query::create(GL_ANY_SAMPLES_PASSED);
    gl::checkErrors("planar mirrors setup");
}

PlanarMirrors::~PlanarMirrors() = default;

void PlanarMirrors::execute(const ReflectionInputs& in, const ParamSet& fp, const gl::Framebuffer& target,
                            gl::PassTimer& timer, Counters& counters) {
    counters["mirror_views"] = 0;
    const int depth = std::clamp(static_cast<int>(fp.getInt("mirror_depth")), 0, kMaxMirrorDepth);
    const gl::Texture* gPosition = in.find("gbuffer.position");
    const gl::Texture* gNormal = in.find("gbuffer.normal");
    const gl::Texture* shadowMap = in.find("lights.shadow");
    if (depth == 0 || !in.mirrors || in.mirrors->empty() || !in.frame || !in.sceneGpu || !gNormal ||
        !gPosition || in.width <= 0 || in.height <= 0)
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

    const int w = in.width, h = in.height;
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
        std::vector<View> visible;
        {
            const Impl::StencilPass& st = s.stencil;
            gl::Pass pass(timer, "mirror_stencil" + suffix);
            pass.target(L.renderFbo, w, h).clearColor(3).clearDepthStencil(1.0f, 0);
            pass.target(L.stencilFbo, w, h).stencilTest(true).use(st.program);
            for (View& v : candidates) {
                if (static_cast<int>(views.size() + visible.size()) >= kMaxMirrorViews) break;
                pass.stencilFunc(GL_ALWAYS, v.stencil);
                s.setRegion(pass, st.region, v, *gNormal);
                if (pass.drawFullscreenAnySamples(s.emptyVao, s.anySamples)) visible.push_back(v);
            }
        }
        if (visible.empty()) break;

        // 2. Render the scene mirrored about each view's chain into its pixels (stencil equal), with
        //    its own depth test and the mirror's front half-space as the clip plane.
        gl::Pass render(timer, "mirror_render" + suffix);
        previous.clear();
        {
            const ForwardProgram& fw = s.forward;
            gl::Pass sub("mirror_views");
            sub.target(L.renderFbo, w, h)
                .depthTest(GL_LESS)
                .stencilTest(false)
                .clipDistance(0)
                .use(fw.program)
                .texture(fw.shadowMap, shadowMap);
            for (View& v : visible) {
                const glm::vec3 n = normals[static_cast<size_t>(v.mirror)];
                const float d = -glm::dot(n, mirrors[static_cast<size_t>(v.mirror)].point) - clipOffset;
                // A reflection flips the winding; culling is off in this renderer, but keep GL's notion
                // of front faces right for anything that enables it.
                const bool odd = (v.level % 2) == 1;
                const glm::mat4 reflected = viewProj * v.reflect;
                sub.frontFace(odd ? GL_CW : GL_CCW)
                    .stencilFunc(GL_EQUAL, v.stencil)
                    .set(fw.viewProj, reflected)
                    .set(fw.clipPlane, glm::vec4(n, d))
                    .set(fw.eye, v.eye);
                // Single-sided materials are culled from behind here too: frontFace above keeps
                // "behind" right in the mirrored view.
                in.sceneGpu->draw(fw.program, &fw.materials, 1, -1, &reflected, true);
                previous.push_back(static_cast<int>(views.size()));
                views.push_back(v);
            }
        }
        // Indirect light where the reflected points are also seen by the eye.
        if (const gl::Texture* indirect = in.find("indirect")) {
            const Impl::IndirectPass& ip = s.indirect;
            gl::Pass sub("mirror_indirect");
            sub.target(L.colorFbo, w, h)
                .blendAdd()
                .use(ip.program)
                .texture(ip.indirect, *indirect)
                .texture(ip.position, *gPosition)
                .texture(ip.viewPosition, L.position);
            sub.drawFullscreen(s.emptyVao);
        }
        levelsUsed = level;
    }
    counters["mirror_views"] = static_cast<double>(views.size());
    if (views.empty()) return;

    // 3. From the deepest level up: blur (optional) each view's radiance, then add Fresnel x radiance
    //    into its parent (the target at level 1).
    gl::Pass pass(timer, "mirror_apply");
    for (int level = levelsUsed; level >= 1; --level) {
        Level& L = s.levels[static_cast<size_t>(level - 1)];
        const gl::Texture& parentPos =
            level == 1 ? *gPosition : s.levels[static_cast<size_t>(level - 2)].position;
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
                // Horizontal into the blur target, then vertical back into the view's radiance.
                const Impl::BlurPass& b = s.blur;
                gl::Pass sub("mirror_blur");
                sub.use(b.program)
                    .set(b.roughness, m.roughness)
                    .set(b.maxSigmaPx, maxSigma)
                    .set(b.viewProjChain, viewProj * v.reflect)
                    .texture(b.mirrorPosition, parentPos)
                    .texture(b.reflectPosition, L.position);
                s.setRegion(sub, b.region, v, *gNormal);
                sub.target(s.blurFbo, w, h).set(b.direction, glm::ivec2(1, 0)).texture(b.source, L.radiance);
                sub.drawFullscreen(s.emptyVao);
                sub.target(L.colorFbo, w, h).set(b.direction, glm::ivec2(0, 1)).texture(b.source, s.blurTemp);
                sub.drawFullscreen(s.emptyVao);
            }
            const Impl::ApplyPass& a = s.apply;
            gl::Pass sub("mirror_add");
            sub.target(level == 1 ? target : s.levels[static_cast<size_t>(level - 2)].colorFbo, w, h)
                .blendAdd()
                .use(a.program)
                .set(a.parentEye, parentEye)
                .set(a.mirrorNormal, normals[static_cast<size_t>(v.mirror)])
                .set(a.f0, m.f0)
                .texture(a.reflected, L.radiance)
                .texture(a.mirrorPosition, parentPos);
            s.setRegion(sub, a.region, v, *gNormal);
            sub.drawFullscreen(s.emptyVao);
        }
    }
}

} // namespace gis
