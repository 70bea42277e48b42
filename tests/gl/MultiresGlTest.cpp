// The shared eye hierarchy and the multiresolution techniques (000, 001 §3.2) on a real GL context.
#include <algorithm>
#include <cmath>
#include <set>

#include "GlTestSupport.h"
#include "analysis/Metrics.h"
#include "gi/common/EyeHierarchy.h"
#include "gi/multires_gather/MultiresGather.h"
#include "gi/multires_splat/MultiresSplat.h"

using namespace gis;
using gis::test::renderScene;
using test::badValues;
using test::counter;
using test::relativeRmseOf;

namespace {

using PatchSet = std::vector<std::array<int, 3>>;

// Covered pixels of the last frame: the coarsest level's coverage counts sum to them (-1 when the
// image is a single level, which lives in the G-buffer rather than the atlas).
double coveredPixels(EyeHierarchy& eye) {
    if (eye.levels().size() < 2) return -1;
    const EyeLevel& c = eye.levels().back();
    std::vector<float> texels(static_cast<size_t>(c.width) * c.height * 4);
    glGetTextureSubImage(eye.geoPosition().id(), 0, c.x, c.y, 0, c.width, c.height, 1, GL_RGBA, GL_FLOAT,
                         static_cast<GLsizei>(texels.size() * sizeof(float)), texels.data());
    double sum = 0;
    for (size_t i = 3; i < texels.size(); i += 4) sum += texels[i];
    return sum;
}

// Receivers must tile the covered pixels exactly once (a cut of the quadtree).
void expectPartition(const PatchSet& set, int width, int height, double covered) {
    std::vector<std::uint8_t> hits(static_cast<size_t>(width) * height, 0);
    double pixels = 0;
    for (const auto& [level, x, y] : set) {
        const int s = 1 << level;
        for (int py = y * s; py < std::min((y + 1) * s, height); ++py)
            for (int px = x * s; px < std::min((x + 1) * s, width); ++px) {
                ASSERT_EQ(hits[static_cast<size_t>(py) * width + px]++, 0)
                    << "pixel " << px << "," << py << " under two receivers";
                ++pixels;
            }
    }
    if (covered >= 0) {
        EXPECT_EQ(pixels, covered);
    }
}

struct SetCase {
    const char* scene;
    int width, height;
    nlohmann::json params;
};

} // namespace

// 001 §3.2.1: the one-pass stencil must select exactly the patches the iterative refinement of 000
// keeps, including the coarsest level (no parent) and the finest (never refined).
TEST(Multires, StencilReceiversEqualIterativeRefinement) {
    const SetCase cases[] = {
        {"builtin:cornell", 128, 128, nlohmann::json::object()},
        {"builtin:cornell", 97, 61, nlohmann::json::object()},
        {"builtin:cornell", 128, 96, {{"diagonal_refine", false}}},
        {"builtin:cornell", 128, 128, {{"depth_threshold", 0.0}, {"normal_threshold", 0.0}}},
        {"builtin:cornell", 128, 128, {{"depth_threshold", 1.0}, {"normal_threshold", 2.0}}},
        {"builtin:cornell", 111, 77, {{"depth_metric", "derivative"}, {"normal_metric", "curvature"}}},
        {"builtin:crease", 128, 128, {{"coarsest_size", 8}, {"normal_threshold", 0.05}}},
        {"builtin:cornell-dense", 96, 96, {{"coarsest_size", 64}}},
        {"builtin:cornell-empty", 16, 16, nlohmann::json::object()}, // one level only
        // 000's geometry shader + transform feedback lists must build the same set.
        {"builtin:cornell", 97, 61, {{"list_builder", "transform_feedback"}}},
        {"builtin:cornell-dense",
         96,
         96,
         {{"list_builder", "transform_feedback"}, {"diagonal_refine", false}}},
    };
    bool sawCoarsest = false, sawFinest = false;
    for (const auto& c : cases) {
        SCOPED_TRACE(std::string(c.scene) + " " + std::to_string(c.width) + "x" + std::to_string(c.height) +
                     " " + c.params.dump());
        renderScene(c.scene, "multires_splat", c.width, c.height, c.params);
        auto* splat = dynamic_cast<MultiresSplat*>(test::sharedRenderer().technique());
        ASSERT_NE(splat, nullptr);
        const PatchSet iterative = splat->readSplatPatches();
        const PatchSet stencil = splat->hierarchy().readReceiverSet();
        EXPECT_EQ(iterative, stencil);
        ASSERT_FALSE(stencil.empty());
        expectPartition(stencil, c.width, c.height, coveredPixels(splat->hierarchy()));
        const int coarsest = static_cast<int>(splat->hierarchy().levels().size()) - 1;
        for (const auto& p : stencil) {
            sawCoarsest |= p[0] == coarsest && coarsest > 0;
            sawFinest |= p[0] == 0;
        }
    }
    EXPECT_TRUE(sawCoarsest && sawFinest) << "the cases must exercise both boundary levels";
}

// The gathers run one invocation per item of the receiver list the stencil pass appends: the list
// must hold each receiver of the stencil exactly once, and the dispatch it sets up must cover it.
TEST(Multires, ReceiverListHoldsEachStencilReceiverOnce) {
    const SetCase cases[] = {
        {"builtin:cornell", 128, 128, nlohmann::json::object()},
        {"builtin:cornell", 97, 61, nlohmann::json::object()},
        {"builtin:cornell", 96, 80, {{"depth_threshold", 0.0}, {"normal_threshold", 0.0}}}, // every pixel
        {"builtin:crease", 128, 128, {{"coarsest_size", 8}, {"normal_threshold", 0.05}}},
        {"builtin:cornell-empty", 16, 16, nlohmann::json::object()}, // one level only
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(std::string(c.scene) + " " + std::to_string(c.width) + "x" + std::to_string(c.height) +
                     " " + c.params.dump());
        nlohmann::json params = c.params;
        params["vpl_grid"] = 4;
        renderScene(c.scene, "multires_gather", c.width, c.height, params);
        auto* gather = dynamic_cast<MultiresGather*>(test::sharedRenderer().technique());
        ASSERT_NE(gather, nullptr);
        shader::EyeReceiverListHeader header{};
        const PatchSet list = gather->hierarchy().readReceiverList(&header);
        const PatchSet stencil = gather->hierarchy().readReceiverSet();
        ASSERT_FALSE(stencil.empty());
        EXPECT_EQ(list, stencil); // both sorted: equal means no receiver missing, doubled or misplaced
        EXPECT_EQ(header.counts.x, list.size());
        const unsigned groups = (header.counts.x + GIS_EYE_RECEIVER_GROUP - 1) / GIS_EYE_RECEIVER_GROUP;
        EXPECT_EQ(header.dispatch, glm::uvec4(groups, 1, 1, 0));
    }
}

// A list of more than GIS_EYE_RECEIVER_MAX_GROUPS_X groups (4,194,240 receivers) is dispatched in rows
// of groups: with every pixel a receiver (thresholds 0, the camera inside the box so that every pixel
// sees a wall) at 2100 x 2048, the gather must still light each receiver once, as the full gather.
TEST(Multires, ReceiverListsLongerThanOneRowOfGroupsRunIn2D) {
    const int w = 2100, h = 2048;
    static_assert(2100 * 2048 > GIS_EYE_RECEIVER_MAX_GROUPS_X * GIS_EYE_RECEIVER_GROUP);
    const auto inside = [](FrameState& s) {
        s.camera.position = {0.0f, 1.0f, 0.95f};
        s.camera.target = {0.0f, 1.0f, -1.0f};
    };
    const nlohmann::json params = {
        {"vpl_grid", 2}, {"kernel", "disk"}, {"depth_threshold", 0.0}, {"normal_threshold", 0.0}};
    FrameOutput gather = renderScene("builtin:cornell", "multires_gather", w, h, params, inside);
    auto* technique = dynamic_cast<MultiresGather*>(test::sharedRenderer().technique());
    ASSERT_NE(technique, nullptr);
    shader::EyeReceiverListHeader header{};
    technique->hierarchy().readReceiverList(&header);
    ASSERT_EQ(header.counts.x, static_cast<unsigned>(w * h)) << "every pixel must be a receiver";
    EXPECT_EQ(header.dispatch.x, GIS_EYE_RECEIVER_MAX_GROUPS_X);
    EXPECT_EQ(header.dispatch.y, 2u);
    FrameOutput full =
        renderScene("builtin:cornell", "rsm_gather", w, h, {{"vpl_grid", 2}, {"kernel", "disk"}}, inside);
    EXPECT_LT(relativeRmseOf(gather, full), 1e-3);
    EXPECT_EQ(badValues(gather), 0u);
    // Back to a small frame: the shared renderer's next tests should not carry this atlas around.
    renderScene("builtin:cornell", "multires_gather", 64, 64, {});
}

// 001 Fig. 9: thresholds of 0 refine every varying patch to single pixels, which is the
// full-resolution gather with the same VPLs.
TEST(Multires, ZeroThresholdsReproduceFullResolutionGather) {
    for (const char* kernel : {"point", "disk"}) {
        SCOPED_TRACE(kernel);
        const nlohmann::json vpl = {{"vpl_grid", 8}, {"kernel", kernel}};
        nlohmann::json zero = vpl;
        zero["depth_threshold"] = 0.0;
        zero["normal_threshold"] = 0.0;
        FrameOutput full = renderScene("builtin:cornell", "rsm_gather", 96, 80, vpl);
        FrameOutput gather = renderScene("builtin:cornell", "multires_gather", 96, 80, zero);
        FrameOutput splat = renderScene("builtin:cornell", "multires_splat", 96, 80, zero);
        EXPECT_LT(relativeRmseOf(gather, full), 1e-3);
        EXPECT_LT(relativeRmseOf(splat, full), 1e-3);
    }
    // More VPLs than one batch holds: the gather adds one dispatch per batch into the same texels.
    static_assert(40 * 40 > GIS_MAX_VPLS_PER_BATCH);
    const nlohmann::json batches = {{"vpl_grid", 40}, {"kernel", "disk"}};
    nlohmann::json zero = batches;
    zero["depth_threshold"] = 0.0;
    zero["normal_threshold"] = 0.0;
    FrameOutput full = renderScene("builtin:cornell", "rsm_gather", 96, 80, batches);
    FrameOutput gather = renderScene("builtin:cornell", "multires_gather", 96, 80, zero);
    EXPECT_GE(counter(gather, "vpl_batches"), 2.0);
    EXPECT_LT(relativeRmseOf(gather, full), 1e-3);
}

// The live view's work cap: a frame whose hierarchy lists more receivers than receiver_share_cap of its
// pixels gathers from the coarser grid the cap leaves (the side scaled by sqrt(cap / share)), and is
// then exactly that grid's frame; a cap at or above the frame's share changes nothing.
TEST(Multires, ReceiverShareCapGathersFromTheGridItLeaves) {
    constexpr int kWidth = 96, kHeight = 80;
    const nlohmann::json base = {{"vpl_grid", 24}};
    const FrameOutput uncapped = renderScene("builtin:cornell", "multires_gather", kWidth, kHeight, base);
    const double share = counter(uncapped, "receivers_total") / (kWidth * kHeight);
    ASSERT_GT(share, 0.01);
    ASSERT_EQ(counter(uncapped, "vpl_count"), 24 * 24);

    nlohmann::json atShare = base;
    atShare["receiver_share_cap"] = std::min(1.0, share * 1.001);
    const FrameOutput same = renderScene("builtin:cornell", "multires_gather", kWidth, kHeight, atShare);
    EXPECT_EQ(counter(same, "receiver_share_capped_vpls"), 0);
    EXPECT_EQ(counter(same, "vpl_count"), 24 * 24);
    EXPECT_EQ(same.linear, uncapped.linear);

    // A quarter of the share (and a hair more, against rounding): half the side.
    nlohmann::json quarter = base;
    quarter["receiver_share_cap"] = share / 4.0 * 1.001;
    const FrameOutput capped = renderScene("builtin:cornell", "multires_gather", kWidth, kHeight, quarter);
    EXPECT_EQ(counter(capped, "receiver_share_capped_vpls"), 144);
    EXPECT_EQ(counter(capped, "vpl_count"), 12 * 12);
    EXPECT_EQ(counter(capped, "receivers_total"), counter(uncapped, "receivers_total"));
    const FrameOutput grid12 =
        renderScene("builtin:cornell", "multires_gather", kWidth, kHeight, {{"vpl_grid", 12}});
    EXPECT_EQ(capped.linear, grid12.linear);
    EXPECT_GT(relativeRmseOf(capped, uncapped), 1e-4) << "a coarser grid must change the image";

    // Far below any share: the budget's floor of 16 VPLs, never fewer; a grid already below it stays.
    nlohmann::json tiny = base;
    tiny["receiver_share_cap"] = 0.001;
    const FrameOutput floor = renderScene("builtin:cornell", "multires_gather", kWidth, kHeight, tiny);
    ASSERT_LT(24 * std::sqrt(0.001 / share), 4.0);
    EXPECT_EQ(counter(floor, "receiver_share_capped_vpls"), 16);
    EXPECT_EQ(counter(floor, "vpl_count"), 16);
    EXPECT_EQ(badValues(floor), 0u);
    tiny["vpl_grid"] = 3;
    const FrameOutput small = renderScene("builtin:cornell", "multires_gather", kWidth, kHeight, tiny);
    EXPECT_EQ(counter(small, "receiver_share_capped_vpls"), 0);
    EXPECT_EQ(counter(small, "vpl_count"), 9);
}

// The same cap on the light-tree techniques: a cap at half the frame's share lowers isr_finest (cost
// linear in the light patches: 4,096 -> at most 2,048, so 32^2) and hier_isr's max_depth (cost as
// leaves^0.4: 4,096 x 0.5^2.5 = 724 leaves at most, so 16^2), and the frame is then exactly that
// setting's.
TEST(Multires, ReceiverShareCapCutsTheLightTreeTechniquesToo) {
    constexpr int kWidth = 96, kHeight = 80;
    struct Case {
        const char* technique;
        nlohmann::json base, expected;
        double cutVpls;
    };
    for (const Case& c : {Case{"isr", {{"isr_finest", 64}}, {{"isr_finest", 32}}, 1024},
                          Case{"hier_isr",
                               {{"max_depth", 64}, {"hier_coarsest", 4}, {"tau", 0.0}},
                               {{"max_depth", 16}, {"hier_coarsest", 4}, {"tau", 0.0}},
                               256}}) {
        SCOPED_TRACE(c.technique);
        const FrameOutput whole = renderScene("builtin:cornell", c.technique, kWidth, kHeight, c.base);
        const double share = counter(whole, "receivers_total") / (kWidth * kHeight);
        ASSERT_GT(share, 0.01);
        nlohmann::json half = c.base;
        half["receiver_share_cap"] = share / 2.0;
        const FrameOutput cut = renderScene("builtin:cornell", c.technique, kWidth, kHeight, half);
        EXPECT_EQ(counter(cut, "receiver_share_capped_vpls"), c.cutVpls);
        const FrameOutput expected = renderScene("builtin:cornell", c.technique, kWidth, kHeight, c.expected);
        EXPECT_EQ(cut.linear, expected.linear);
        EXPECT_GT(relativeRmseOf(cut, whole), 1e-4) << "fewer lights must change the image";
        nlohmann::json above = c.base;
        above["receiver_share_cap"] = std::min(1.0, share * 1.001);
        const FrameOutput same = renderScene("builtin:cornell", c.technique, kWidth, kHeight, above);
        EXPECT_EQ(counter(same, "receiver_share_capped_vpls"), 0);
        EXPECT_EQ(same.linear, whole.linear);
    }
}

// 001: "scattering and gathering give results of equal quality": same VPLs, same receivers, same
// kernel, so the images agree up to the order of floating-point sums.
TEST(Multires, SplatAndGatherAgree) {
    const nlohmann::json params = {{"vpl_grid", 12}, {"kernel", "point"}, {"depth_threshold", 0.2}};
    FrameOutput splat = renderScene("builtin:cornell", "multires_splat", 128, 112, params);
    FrameOutput gather = renderScene("builtin:cornell", "multires_gather", 128, 112, params);
    EXPECT_LT(relativeRmseOf(splat, gather), 1e-5);
    nlohmann::json feedback = params;
    feedback["list_builder"] = "transform_feedback";
    FrameOutput splatTf = renderScene("builtin:cornell", "multires_splat", 128, 112, feedback);
    EXPECT_LT(relativeRmseOf(splatTf, gather), 1e-5);
}

// Default thresholds trade a little error for far fewer receivers.
TEST(Multires, DefaultThresholdsSaveReceiversAtSmallError) {
    FrameOutput full = renderScene("builtin:cornell", "rsm_gather", 128, 128, {{"kernel", "disk"}});
    FrameOutput gather = renderScene("builtin:cornell", "multires_gather", 128, 128);
    const double fraction = gather.stats["counts"]["receiver_fraction"].get<double>();
    EXPECT_LT(fraction, 0.5);
    EXPECT_GT(gather.stats["counts"]["receivers_l0"].get<double>(), 0);
    EXPECT_LT(relativeRmseOf(gather, full), 0.05);
}

// Per-VPL (illumination-driven) refinement: with a Lambertian BRDF it approaches the full gather,
// and a cap far below the demand degrades the image without failing the frame.
TEST(Multires, PerVplRefinementAndCap) {
    const nlohmann::json base = {{"vpl_grid", 8}, {"refinement", "illumination"}};
    FrameOutput full = renderScene("builtin:cornell", "rsm_gather", 96, 96, {{"vpl_grid", 8}});
    FrameOutput perVpl = renderScene("builtin:cornell", "multires_splat", 96, 96, base);
    EXPECT_LT(relativeRmseOf(perVpl, full), 0.05);
    EXPECT_EQ(perVpl.stats["counts"]["subsplat_capped"].get<double>(), 0);

    nlohmann::json capped = base;
    capped["max_subsplats"] = 1024;
    capped["illum_threshold"] = 1e-7;
    FrameOutput small = renderScene("builtin:cornell", "multires_splat", 96, 96, capped);
    EXPECT_GT(small.stats["counts"]["subsplat_capped"].get<double>(), 0);
    EXPECT_LE(small.stats["counts"]["subsplats_total"].get<double>(), 1024);
    for (float v : small.linear) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f);

    nlohmann::json glossy = base;
    glossy["phong_ks"] = 0.8;
    glossy["phong_exponent"] = 200.0;
    FrameOutput shiny = renderScene("builtin:cornell", "multires_splat", 96, 96, glossy);
    EXPECT_GT(relativeRmseOf(shiny, perVpl), 0.01) << "the Phong lobe must change the image";
    for (float v : shiny.linear) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f);
}

// No NaN, Inf or negative radiance on any built-in scene, at an even and an odd size, for every
// multiresolution technique (and with extreme thresholds).
TEST(Multires, StableOnEveryBuiltinScene) {
    const std::pair<int, int> sizes[] = {{512, 512}, {511, 383}};
    const char* scenes[] = {"builtin:cornell", "builtin:cornell-empty", "builtin:crease",
                            "builtin:cornell-dense"};
    for (const char* technique : {"multires_gather", "multires_splat"}) {
        for (const char* scene : scenes)
            for (auto [w, h] : sizes) {
                SCOPED_TRACE(std::string(technique) + " " + scene + " " + std::to_string(w) + "x" +
                             std::to_string(h));
                // The splat draws vpl_grid^2 points per receiver: keep it affordable on llvmpipe.
                nlohmann::json params = std::string(technique) == "multires_splat"
                                            ? nlohmann::json{{"vpl_grid", 6}}
                                            : nlohmann::json::object();
                FrameOutput f = renderScene(scene, technique, w, h, params);
                size_t bad = 0;
                for (float v : f.linear) bad += !(std::isfinite(v) && v >= 0.0f);
                EXPECT_EQ(bad, 0u);
            }
    }
    for (const nlohmann::json& extreme :
         {nlohmann::json{{"depth_threshold", 0.0}, {"normal_threshold", 0.0}, {"coarsest_size", 1}},
          nlohmann::json{{"depth_threshold", 1.0}, {"normal_threshold", 2.0}, {"coarsest_size", 256}},
          nlohmann::json{{"depth_metric", "derivative"},
                         {"depth_derivative_threshold", 0.0},
                         {"kernel", "point"},
                         {"min_distance", 0.0},
                         {"detail_alpha", 1.0}}}) {
        SCOPED_TRACE(extreme.dump());
        FrameOutput f = renderScene("builtin:crease", "multires_gather", 63, 47, extreme);
        for (float v : f.linear) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f);
    }
}

TEST(Multires, LevelLayoutKeepsOddEdges) {
    int aw = 0, ah = 0;
    auto levels = eyeLevelLayout(511, 383, 16, &aw, &ah);
    ASSERT_EQ(levels.size(), 6u); // 511 -> 256 -> 128 -> 64 -> 32 -> 16
    EXPECT_EQ(levels[1].width, 256);
    EXPECT_EQ(levels[1].height, 192);
    EXPECT_EQ(levels.back().width, 16);
    EXPECT_EQ(levels.back().height, 12);
    EXPECT_EQ(aw, 511 + 256);
    EXPECT_GE(ah, 383);
    for (size_t l = 1; l < levels.size(); ++l) {
        EXPECT_EQ(levels[l].x, 511);
        EXPECT_LE(levels[l].y + levels[l].height, ah);
    }
}
