// The technique catalog (gi/Catalog.h) without GL: every capability a technique claims is backed by
// the parameters it declares, and the VPL estimate follows the parameters it names.
#include <gtest/gtest.h>

#include "core/Error.h"
#include "frame/FrameParams.h"
#include "frame/FrameState.h"
#include "frame/VplBudget.h"
#include "gi/Catalog.h"

namespace gis {
namespace {

TEST(Catalog, CapabilitiesAreBackedByTheDeclaredParameters) {
    ASSERT_EQ(techniqueCatalog().size(), 8u);
    for (const TechniqueInfo& info : techniqueCatalog()) {
        const ParamTable& p = info.params;
        EXPECT_EQ(info.vplVisibility, p.find("vpl_shadows") != nullptr) << info.name;
        EXPECT_EQ(info.biasCompensation, p.find("clamp_b") != nullptr && p.find("ssbc_iterations") != nullptr)
            << info.name;
        EXPECT_EQ(info.eyeHierarchy,
                  p.find("coarsest_size") != nullptr && p.find("depth_threshold") != nullptr &&
                      p.find("normal_threshold") != nullptr && p.find("diagonal_refine") != nullptr)
            << info.name;
        EXPECT_EQ(static_cast<bool>(info.vplEstimate), info.name != "none") << info.name;
        // VPL visibility is an indirect shadow: a technique with the knob says when it is on.
        if (info.vplVisibility) {
            EXPECT_TRUE(static_cast<bool>(info.indirectShadows)) << info.name;
        }
        if (info.indirectShadows) {
            ParamSet on(info.params), off(info.params);
            if (p.find("vpl_shadows")) {
                on.set("vpl_shadows", true);
                off.set("vpl_shadows", false);
            }
            if (p.find("negative_count")) off.set("negative_count", 0);
            EXPECT_TRUE(info.indirectShadows(on)) << info.name;
            EXPECT_FALSE(info.indirectShadows(off)) << info.name;
        }
    }
    EXPECT_THROW(findTechniqueInfo("nope"), InputError);
}

TEST(Catalog, VplEstimatesFollowEachTechniquesParameters) {
    auto estimate = [](const std::string& technique, const nlohmann::json& params) {
        FrameState s;
        s.frameParams = ParamSet(frameParamTable());
        setTechnique(s, technique);
        applyParams(s, params, "test");
        return vplEstimate(s);
    };
    EXPECT_EQ(estimate("none", nlohmann::json::object()), 0);
    EXPECT_EQ(estimate("rsm_gather", {{"vpl_grid", 64}}), 64 * 64);
    EXPECT_EQ(estimate("multires_splat", {{"vpl_grid", 256}}), 65536);
    EXPECT_EQ(estimate("isr", {{"isr_finest", 32}}), 32 * 32);
    EXPECT_EQ(estimate("hier_isr", {{"rsm_size", 512}, {"max_depth", 1024}}), 512 * 512)
        << "a full traversal reaches every RSM texel";
    EXPECT_EQ(estimate("hier_isr", {{"rsm_size", 512}, {"max_depth", 64}}), 64 * 64)
        << "or stops at max_depth";
    EXPECT_EQ(estimate("second_order", {{"positive_count", 100}, {"negative_count", 50}}), 150);
}

// The frame budget's VPL cap: after limitVpls(n) a technique renders at most n VPLs (or its
// parameters' minimum), and a cap above the current count changes nothing.
TEST(Catalog, LimitVplsCapsTheEstimateAndNeverRaisesIt) {
    for (const TechniqueInfo& info : techniqueCatalog()) {
        if (!info.limitVpls) continue;
        for (long cap : {16L, 100L, 1000L, 5000L}) {
            FrameState s;
            s.frameParams = ParamSet(frameParamTable());
            setTechnique(s, info.name);
            s.frameParams.set("rsm_size", 1024);
            const long before = vplEstimate(s);
            info.limitVpls(s.techniqueParams, cap);
            const long after = vplEstimate(s);
            EXPECT_LE(after, std::max(cap, 16L)) << info.name << " cap " << cap;
            EXPECT_LE(after, before) << info.name;
            const nlohmann::json kept = s.techniqueParams.toJson();
            info.limitVpls(s.techniqueParams, after + 1000);
            EXPECT_EQ(s.techniqueParams.toJson(), kept)
                << info.name << ": a cap above the count changes nothing";
        }
    }
}

} // namespace
} // namespace gis
