// VPL visibility (cube shadow maps per VPL), the option that lets bias compensation and the VPL
// techniques be compared with indirect shadows on and off.
#include <cmath>
#include <string>

#include "GlTestSupport.h"
#include "analysis/Metrics.h"
#include "reference/ReferenceRenderer.h"
#include "scene/SceneLoader.h"

using namespace gis;
using gis::test::renderScene;

namespace {

double relativeRmseRgba(const std::vector<float>& test, const std::vector<float>& referenceRgb, int w,
                        int h) {
    std::vector<float> rgb(static_cast<size_t>(w) * h * 3);
    for (size_t i = 0; i < static_cast<size_t>(w) * h; ++i)
        for (size_t c = 0; c < 3; ++c) rgb[i * 3 + c] = test[i * 4 + c];
    return relativeRmse(ImageView{rgb.data(), w, h, 3}, ImageView{referenceRgb.data(), w, h, 3},
                        maskFromNonZero(ImageView{referenceRgb.data(), w, h, 3}));
}

/// The empty Cornell room with a horizontal 1.2 m card at mid-height, between the floor's VPLs and the
/// ceiling: opaque, or cut out everywhere (alpha 0 under MASK).
Scene roomWithCard(bool cutOut) {
    Scene s = loadScene("builtin:cornell-empty");
    Mesh card{.name = "card", .material = static_cast<int>(s.materials.size())};
    card.positions = {{-0.6f, 1.0f, -0.6f}, {0.6f, 1.0f, -0.6f}, {0.6f, 1.0f, 0.6f}, {-0.6f, 1.0f, 0.6f}};
    card.normals.assign(4, glm::vec3(0.0f, -1.0f, 0.0f));
    card.texcoords = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    card.indices = {0, 1, 2, 0, 2, 3};
    s.meshes.push_back(card);
    Material m{.name = "card", .baseColor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f)};
    if (cutOut) {
        m.baseColorTexture = static_cast<int>(s.textures.size());
        m.alphaMode = Material::Alpha::Mask;
        s.textures.push_back(
            TextureImage{.width = 1, .height = 1, .rgba = {255, 255, 255, 0}, .name = "clear"});
    }
    s.materials.push_back(m);
    s.updateBounds();
    return s;
}

FrameOutput renderWithVplShadows(const Scene& scene) {
    return renderScene(scene, "rsm_gather", 48, 48, {{"vpl_grid", 8}, {"vpl_shadows", true}});
}

double sum(const std::vector<float>& v) {
    double s = 0;
    for (float x : v) s += x;
    return s;
}

} // namespace

// With visibility the grid-VPL gather moves towards the one-bounce reference (light blocked by the
// boxes) and away from the unoccluded one, and it only ever removes light.
TEST(VplShadows, MoveTheGatherTowardsOneBounceWithVisibility) {
    const int w = 64, h = 64;
    const Scene scene = loadScene("builtin:cornell");
    FrameState state = makeFrameState(scene, "rsm_gather");
    state.width = w;
    state.height = h;
    ReferenceRenderer reference(scene);
    const ReferenceImage occluded = reference.render(state, {.mode = "one-bounce", .spp = 256, .seed = 3});
    const ReferenceImage open =
        reference.render(state, {.mode = "one-bounce-unoccluded", .spp = 256, .seed = 3});

    const FrameOutput plain = renderScene("builtin:cornell", "rsm_gather", w, h, {{"vpl_grid", 8}});
    const FrameOutput shadowed =
        renderScene("builtin:cornell", "rsm_gather", w, h, {{"vpl_grid", 8}, {"vpl_shadows", true}});
    EXPECT_EQ(shadowed.stats["counts"]["vpl_shadowed"].get<double>(), 64);

    const double plainToOccluded = relativeRmseRgba(plain.linear, occluded.rgb, w, h);
    const double shadowedToOccluded = relativeRmseRgba(shadowed.linear, occluded.rgb, w, h);
    const double plainToOpen = relativeRmseRgba(plain.linear, open.rgb, w, h);
    const double shadowedToOpen = relativeRmseRgba(shadowed.linear, open.rgb, w, h);
    std::printf("rel. RMSE vs one-bounce: %.4f -> %.4f; vs unoccluded: %.4f -> %.4f\n", plainToOccluded,
                shadowedToOccluded, plainToOpen, shadowedToOpen);
    EXPECT_LT(shadowedToOccluded, plainToOccluded);
    EXPECT_GT(shadowedToOpen, plainToOpen);

    size_t brighter = 0;
    for (size_t i = 0; i < plain.linear.size(); ++i) {
        ASSERT_TRUE(std::isfinite(shadowed.linear[i]) && shadowed.linear[i] >= 0.0f);
        brighter += shadowed.linear[i] > plain.linear[i] * 1.0001f + 1e-6f;
    }
    EXPECT_EQ(brighter, 0u) << "visibility can only remove light";
    EXPECT_LT(sum(shadowed.linear), sum(plain.linear));
}

// Nothing occludes inside the empty box: shadows may only nibble at creases (the bias).
TEST(VplShadows, EmptyBoxIsNearlyUnchanged) {
    const FrameOutput plain = renderScene("builtin:cornell-empty", "rsm_gather", 64, 48, {{"vpl_grid", 8}});
    const FrameOutput shadowed =
        renderScene("builtin:cornell-empty", "rsm_gather", 64, 48, {{"vpl_grid", 8}, {"vpl_shadows", true}});
    const double change =
        relativeRmse(ImageView{shadowed.linear.data(), 64, 48, 4}, ImageView{plain.linear.data(), 64, 48, 4});
    EXPECT_LT(change, 0.02);
}

// Every built-in scene, extreme settings, and bias compensation on top: finite and non-negative.
TEST(VplShadows, StableWithCompensationAndExtremes) {
    for (const char* scene : {"builtin:cornell", "builtin:crease", "builtin:cornell-dense"}) {
        SCOPED_TRACE(scene);
        for (const nlohmann::json& p :
             {nlohmann::json{
                  {"vpl_grid", 6}, {"vpl_shadows", true}, {"vpl_shadow_size", 8}, {"vpl_shadow_bias", 0.0}},
              nlohmann::json{
                  {"vpl_grid", 6}, {"vpl_shadows", true}, {"vpl_shadow_bias", 0.5}, {"vpl_shadow_size", 16}},
              nlohmann::json{
                  {"vpl_grid", 6}, {"vpl_shadows", true}, {"ssbc_iterations", 1}, {"clamp_b", 40.0}}}) {
            // 65k triangles x 6 faces x VPLs: one configuration of the dense scene is enough.
            if (std::string(scene) == "builtin:cornell-dense" && p.contains("vpl_shadow_size")) continue;
            const FrameOutput f = renderScene(scene, "rsm_gather", 63, 47, p);
            for (float v : f.linear) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f);
        }
    }
}

// A cut-out surface casts no indirect shadow either: the room with a card cut out everywhere renders
// as the empty room (every pass lets it through, the VPLs' cube shadow maps too), while the same card
// opaque darkens the ceiling's indirect light.
TEST(VplShadows, AlphaCutoutsLetIndirectLightThrough) {
    const FrameOutput empty = renderWithVplShadows(loadScene("builtin:cornell-empty"));
    const FrameOutput clear = renderWithVplShadows(roomWithCard(true));
    const FrameOutput opaque = renderWithVplShadows(roomWithCard(false));
    const size_t pixels = 48 * 48;
    const double clearError = test::relativeRmseOf(clear.linear, 4, empty.linear, 4, pixels);
    const double opaqueChange = test::relativeRmseOf(opaque.linear, 4, empty.linear, 4, pixels);
    std::printf("cut-out card against the empty room %.2e; an opaque card changes it by %.3f\n", clearError,
                opaqueChange);
    EXPECT_LT(clearError, 1e-4);
    EXPECT_GT(opaqueChange, 0.05);
    EXPECT_EQ(clear.stats["counts"]["vpl_shadowed"].get<double>(), 64);
}
