// Planar mirrors (004 §5.1, render/PlanarMirrors.h): the reflection lands where the mirrored geometry
// projects, nothing outside a mirror changes, mirror_depth recursion, no NaN or negative values at
// grazing angles or from behind a mirror, the glossy blur keeps the energy, and the reflection
// matrix's algebra.
#include <cmath>
#include <functional>
#include <map>

#include "GlTestSupport.h"
#include "render/PlanarMirrors.h"

using namespace gis;
using test::badValues;
using test::counter;
using test::hasPass;
using test::relativeRmseOf;

namespace {

// Renders `scene` with the technique and parameters at w x h; `edit` may change the frame state.
FrameOutput renderWith(const std::shared_ptr<Scene>& scene, const std::string& technique, int w, int h,
                       const nlohmann::json& params, const std::function<void(FrameState&)>& edit = {}) {
    test::sharedContext();
    FrameRenderer& renderer = test::sharedRenderer();
    if (renderer.scene() != scene.get()) renderer.setScene(scene);
    FrameState state = makeFrameState(*scene, technique);
    state.width = w;
    state.height = h;
    if (!params.is_null()) applyParams(state, params, "test");
    if (edit) edit(state);
    return renderer.render(state, true);
}

std::shared_ptr<Scene> gallery() {
    static std::shared_ptr<Scene> scene = std::make_shared<Scene>(loadScene("builtin:gallery"));
    return scene;
}

int meshIndex(const Scene& scene, const std::string& name) {
    for (size_t i = 0; i < scene.meshes.size(); ++i)
        if (scene.meshes[i].name == name) return static_cast<int>(i);
    return -1;
}

// The gallery with its mirror's material made this rough (other meshes unchanged).
std::shared_ptr<Scene> roughGallery(float roughness) {
    static std::map<float, std::shared_ptr<Scene>> scenes;
    auto& s = scenes[roughness];
    if (!s) {
        s = std::make_shared<Scene>(loadScene("builtin:gallery"));
        const int mirror = meshIndex(*s, "mirror");
        s->materials[static_cast<size_t>(s->meshes[static_cast<size_t>(mirror)].material)].roughness =
            roughness;
    }
    return s;
}

// The gallery with two more mirrors, on the left and right walls facing each other, so that mirrors
// see each other (recursion); view it with insideCamera().
std::shared_ptr<Scene> facingMirrorGallery() {
    static std::shared_ptr<Scene> scene;
    if (!scene) {
        Scene s = loadScene("builtin:gallery");
        const Mesh back = s.meshes[static_cast<size_t>(meshIndex(s, "mirror"))];
        for (float side : {-1.0f, 1.0f}) {
            Mesh m = back;
            m.name = side < 0 ? "mirror_left" : "mirror_right";
            // Back-wall mirror (x in [-0.6, 0.6], y in [0.35, 1.55], z = -0.98) onto a side wall.
            for (glm::vec3& p : m.positions)
                p = glm::vec3(0.98f * side, 1.0f + 1.3f * (p.y - 0.95f), 1.5f * p.x);
            for (glm::vec3& n : m.normals) n = glm::vec3(-side, 0.0f, 0.0f);
            s.meshes.push_back(m);
        }
        finalizeScene(s, "facing-mirror gallery");
        scene = std::make_shared<Scene>(std::move(s));
    }
    return scene;
}

// Inside the room, looking obliquely at the left mirror (which shows the right one, and so on).
void insideCamera(FrameState& s) {
    s.camera.position = {0.3f, 1.0f, 0.9f};
    s.camera.target = {-0.98f, 1.0f, -0.3f};
}

const nlohmann::json kBase = {{"effect_env", "off"}};

nlohmann::json with(nlohmann::json p, const nlohmann::json& extra) {
    for (auto it = extra.begin(); it != extra.end(); ++it) p[it.key()] = it.value();
    return p;
}

const float* pixel(const FrameOutput& f, int x, int y) {
    return &f.linear[(static_cast<size_t>(y) * static_cast<size_t>(f.width) + static_cast<size_t>(x)) * 4];
}

double count(const FrameOutput& f, const char* name) {
    return f.stats["counts"].value(name, -1.0);
}

// The mirror's screen rectangle (pixels, top-left origin) from its mesh's corners.
struct Rect {
    int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
    bool contains(int x, int y) const { return x >= x0 && x <= x1 && y >= y0 && y <= y1; }
};
Rect screenRect(const Scene& scene, const std::string& mesh, int w, int h, int grow) {
    Rect r{1 << 30, 1 << 30, -(1 << 30), -(1 << 30)};
    for (const glm::vec3& p : scene.meshes[static_cast<size_t>(meshIndex(scene, mesh))].positions) {
        const glm::ivec2 q = test::projectToPixel(scene, p, w, h);
        r.x0 = std::min(r.x0, q.x - grow);
        r.y0 = std::min(r.y0, q.y - grow);
        r.x1 = std::max(r.x1, q.x + grow);
        r.y1 = std::max(r.y1, q.y + grow);
    }
    return r;
}

glm::dvec3 meanOver(const FrameOutput& f, const Rect& r) {
    glm::dvec3 sum(0.0);
    int n = 0;
    for (int y = std::max(r.y0, 0); y <= std::min(r.y1, f.height - 1); ++y)
        for (int x = std::max(r.x0, 0); x <= std::min(r.x1, f.width - 1); ++x) {
            const float* p = pixel(f, x, y);
            sum += glm::dvec3(p[0], p[1], p[2]);
            ++n;
        }
    return n > 0 ? sum / static_cast<double>(n) : sum;
}

bool cyanDominant(const float* p) {
    return p[1] > 0.02f && p[1] > 3.0f * p[0] && p[2] > 3.0f * p[0];
}

} // namespace

TEST(PlanarMirrorMath, ReflectionIsAnInvolutionWithDeterminantMinusOne) {
    const glm::vec3 point(0.2f, -0.4f, 1.5f), normal(0.3f, 0.9f, -0.2f);
    const glm::mat4 r = mirrorReflection(point, normal);
    EXPECT_NEAR(glm::determinant(r), -1.0f, 1e-5f);
    const glm::mat4 rr = r * r;
    for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 4; ++k) EXPECT_NEAR(rr[c][k], c == k ? 1.0f : 0.0f, 1e-5f);
    const glm::vec3 onPlane = glm::vec3(r * glm::vec4(point, 1.0f));
    EXPECT_NEAR(glm::length(onPlane - point), 0.0f, 1e-5f);
    const glm::vec3 n = glm::normalize(normal);
    const glm::vec3 front = point + 0.7f * n;
    EXPECT_NEAR(glm::length(glm::vec3(r * glm::vec4(front, 1.0f)) - (point - 0.7f * n)), 0.0f, 1e-5f);
    // A zero normal falls back to +y instead of producing NaN.
    const glm::mat4 z = mirrorReflection(point, glm::vec3(0.0f));
    for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 4; ++k) EXPECT_TRUE(std::isfinite(z[c][k]));
}

TEST(PlanarMirrorMath, ViewBoundCountsChainsWithoutRepeatsAndIsCapped) {
    EXPECT_EQ(mirrorViewBound(1, 3), 1); // a mirror cannot see itself
    EXPECT_EQ(mirrorViewBound(2, 3), 6);
    EXPECT_EQ(mirrorViewBound(3, 2), 3 + 6);
    EXPECT_EQ(mirrorViewBound(4, 3), kMaxMirrorViews); // 4 + 12 + 36, capped
    EXPECT_EQ(mirrorViewBound(4, 0), 0);
}

TEST(PlanarMirrorGl, MirrorShowsTheMarkerWhereItsReflectionProjects) {
    const int w = 256, h = 256;
    auto scene = gallery();
    const FrameOutput on = renderWith(scene, "none", w, h, with(kBase, {{"effect_mirrors", "on"}}));
    const FrameOutput off = renderWith(scene, "none", w, h, with(kBase, {{"effect_mirrors", "off"}}));
    ASSERT_EQ(test::sharedRenderer().mirrors().size(), 1u);
    const MirrorPlane& m = test::sharedRenderer().mirrors().front();
    EXPECT_NEAR(m.normal.z, 1.0f, 1e-4f);
    EXPECT_EQ(count(on, "mirror_views"), 1.0);
    EXPECT_TRUE(hasPass(on, "mirror_stencil"));
    EXPECT_TRUE(hasPass(on, "mirror_render"));
    EXPECT_TRUE(hasPass(on, "mirror_apply"));

    // The marker's top-face centre (its centre itself is hidden below the mirror's lower edge),
    // mirrored about the plane and projected with the eye camera.
    const glm::vec3 top(0.5f, 0.2f, 0.55f);
    const glm::vec3 mirrored = top - 2.0f * glm::dot(top - m.point, m.normal) * m.normal;
    const glm::ivec2 q = test::projectToPixel(*scene, mirrored, w, h);
    const Rect mirrorRect = screenRect(*scene, "mirror", w, h, 0);
    ASSERT_TRUE(mirrorRect.contains(q.x, q.y)) << q.x << "," << q.y;
    int cyanOn = 0, cyanOff = 0;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            cyanOn += cyanDominant(pixel(on, q.x + dx, q.y + dy)) ? 1 : 0;
            cyanOff += cyanDominant(pixel(off, q.x + dx, q.y + dy)) ? 1 : 0;
        }
    EXPECT_GE(cyanOn, 3) << "at " << q.x << "," << q.y;
    EXPECT_EQ(cyanOff, 0);
    // The marker's true image is far from its reflection: the pass must not put cyan there twice,
    // and no pixel outside the mirror's rectangle changes at all.
    const Rect grown = screenRect(*scene, "mirror", w, h, 1);
    int changedInside = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float* a = pixel(on, x, y);
            const float* b = pixel(off, x, y);
            const bool same = a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
            if (!grown.contains(x, y)) {
                ASSERT_TRUE(same) << "pixel " << x << "," << y << " outside the mirror changed";
            } else if (!same) {
                ++changedInside;
            }
        }
    // The gallery's front is open: most of the mirror reflects the void, the rest changes.
    EXPECT_GT(changedInside, 50);
    EXPECT_EQ(badValues(on), 0u);
}

TEST(PlanarMirrorGl, DepthZeroTurnsMirrorsOffAndOneMirrorNeverRecurses) {
    const int w = 96, h = 96;
    auto scene = gallery();
    const FrameOutput d0 = renderWith(scene, "none", w, h, with(kBase, {{"mirror_depth", 0}}));
    const FrameOutput d1 = renderWith(scene, "none", w, h, with(kBase, {{"mirror_depth", 1}}));
    const FrameOutput d3 = renderWith(scene, "none", w, h, with(kBase, {{"mirror_depth", 3}}));
    const FrameOutput off = renderWith(scene, "none", w, h, with(kBase, {{"effect_mirrors", "off"}}));
    EXPECT_EQ(count(d0, "mirror_views"), -1.0); // the pass did not run
    EXPECT_EQ(count(d1, "mirror_views"), 1.0);
    EXPECT_EQ(count(d3, "mirror_views"), 1.0); // a mirror cannot see itself
    EXPECT_EQ(d0.linear, off.linear);
    EXPECT_NE(d0.linear, d1.linear);
    EXPECT_EQ(d1.linear, d3.linear);
    const Rect r = screenRect(*scene, "mirror", w, h, -2);
    const glm::dvec3 m0 = meanOver(d0, r), m1 = meanOver(d1, r);
    EXPECT_GT(m1.x + m1.y + m1.z, 1.2 * (m0.x + m0.y + m0.z)) << "the mirror is darker without reflections";
}

TEST(PlanarMirrorGl, NestedMirrorsRecurseWithinTheBound) {
    const int w = 96, h = 96;
    auto scene = facingMirrorGallery();
    double previousViews = 0, previousEnergy = 0;
    for (int depth = 1; depth <= 3; ++depth) {
        const FrameOutput f =
            renderWith(scene, "none", w, h, with(kBase, {{"mirror_depth", depth}}), insideCamera);
        ASSERT_EQ(test::sharedRenderer().mirrors().size(), 3u);
        const double views = count(f, "mirror_views");
        EXPECT_LE(views, mirrorViewBound(3, depth));
        EXPECT_GT(views, previousViews) << "depth " << depth;
        double energy = 0;
        for (size_t i = 0; i < f.linear.size(); i += 4)
            energy += f.linear[i] + f.linear[i + 1] + f.linear[i + 2];
        EXPECT_GT(energy, previousEnergy) << "depth " << depth;
        EXPECT_EQ(badValues(f), 0u);
        if (depth >= 2) {
            EXPECT_TRUE(hasPass(f, "mirror_render_2"));
        }
        if (depth >= 3) {
            EXPECT_TRUE(hasPass(f, "mirror_render_3"));
        }
        previousViews = views;
        previousEnergy = energy;
    }
}

TEST(PlanarMirrorGl, GrazingAndBehindTheMirrorStayFinite) {
    const int w = 64, h = 64;
    auto scene = gallery();
    const nlohmann::json p = with(kBase, {{"mirror_depth", 2}, {"mirror_blur", "on"}});
    // Camera 5 mm in front of the mirror's plane, looking along it.
    auto grazing = [](FrameState& s) {
        s.camera.position = {-0.9f, 1.0f, -0.975f};
        s.camera.target = {0.9f, 0.95f, -0.98f};
        s.camera.znear = 0.001f;
    };
    const FrameOutput g = renderWith(scene, "none", w, h, p, grazing);
    EXPECT_EQ(badValues(g), 0u);
    // Exactly in the plane: no view (the eye faces only the mirror's edge).
    auto inPlane = [](FrameState& s) {
        s.camera.position = {-0.9f, 1.0f, -0.98f};
        s.camera.target = {0.9f, 0.95f, -0.98f};
        s.camera.znear = 0.001f;
    };
    const FrameOutput ip = renderWith(scene, "none", w, h, p, inPlane);
    EXPECT_EQ(badValues(ip), 0u);
    EXPECT_EQ(count(ip, "mirror_views"), 0.0);
    // Between the mirror and the wall, looking at the mirror's back: no reflection is added.
    auto behind = [](FrameState& s) {
        s.camera.position = {0.1f, 1.0f, -0.995f};
        s.camera.target = {0.1f, 0.9f, 0.0f};
        s.camera.znear = 0.001f;
    };
    const FrameOutput b = renderWith(scene, "none", w, h, p, behind);
    const FrameOutput bOff =
        renderWith(scene, "none", w, h, with(kBase, {{"effect_mirrors", "off"}}), behind);
    EXPECT_EQ(badValues(b), 0u);
    EXPECT_EQ(count(b, "mirror_views"), 0.0);
    EXPECT_EQ(b.linear, bOff.linear);
}

TEST(PlanarMirrorGl, GlossyBlurKeepsTheMirrorsEnergy) {
    const int w = 128, h = 128;
    auto scene = roughGallery(0.3f);
    const nlohmann::json p = with(kBase, {{"mirror_roughness", 0.5}});
    const FrameOutput sharp = renderWith(scene, "none", w, h, with(p, {{"mirror_blur", "off"}}));
    const FrameOutput blurred = renderWith(scene, "none", w, h, with(p, {{"mirror_blur", "on"}}));
    ASSERT_EQ(count(sharp, "mirror_views"), 1.0);
    EXPECT_EQ(badValues(blurred), 0u);
    const Rect r = screenRect(*scene, "mirror", w, h, -2);
    const glm::dvec3 a = meanOver(sharp, r), b = meanOver(blurred, r);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(b[c], a[c], 0.04 * a[c] + 1e-6) << "channel " << c;
    // It did blur: the horizontal gradients inside the mirror shrink.
    auto roughness = [&](const FrameOutput& f) {
        double g = 0;
        for (int y = r.y0; y <= r.y1; ++y)
            for (int x = r.x0; x < r.x1; ++x) g += std::abs(pixel(f, x + 1, y)[1] - pixel(f, x, y)[1]);
        return g;
    };
    EXPECT_LT(roughness(blurred), 0.8 * roughness(sharp));
    // A smooth mirror is not blurred at all (its lobe is under a quarter pixel wide).
    const FrameOutput smoothSharp =
        renderWith(gallery(), "none", w, h, with(kBase, {{"mirror_blur", "off"}}));
    const FrameOutput smoothBlur = renderWith(gallery(), "none", w, h, with(kBase, {{"mirror_blur", "on"}}));
    EXPECT_EQ(smoothSharp.linear, smoothBlur.linear);
}

TEST(PlanarMirrorGl, ReflectedPointsSeenByTheEyeGetItsIndirectLight) {
    const int w = 64, h = 64;
    auto scene = gallery();
    const FrameOutput none = renderWith(scene, "none", w, h, kBase);
    const FrameOutput gi = renderWith(scene, "rsm_gather", w, h, with(kBase, {{"vpl_grid", 8}}));
    const Rect r = screenRect(*scene, "mirror", w, h, -2);
    const glm::dvec3 a = meanOver(none, r), b = meanOver(gi, r);
    // The mirror's own diffuse albedo is 0 (metallic 1): what the technique adds there is reflected.
    EXPECT_GT(b.x + b.y + b.z, 1.05 * (a.x + a.y + a.z));
    EXPECT_EQ(badValues(gi), 0u);
}
