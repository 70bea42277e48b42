// The catalog entry of `hier_isr` (hierarchical image-space radiosity): its parameter table and capabilities,
// GL-free (gi/Catalog.h). The passes are in HierIsr.cpp.
#include <algorithm>
#include <cmath>

#include "gi/Catalog.h"
#include "gi/common/ParamSpecs.h"

namespace gis {

TechniqueInfo hierIsrInfo() {
    std::vector<ParamSpec> specs = {
        {.name = "tau",
         .type = ParamType::Float,
         .defaultValue = 0.01,
         .min = 0.0,
         .max = 1.0,
         .unit = "fraction of I",
         .help = "refine a light node while its bounded contribution may exceed tau * I (0: full "
                 "traversal, 1: coarsest level only)",
         .source = "001 Eqs. 6-8 (no value given; chosen for <5% error at 1/10 the full gather's time)"},
        {.name = "hier_coarsest",
         .type = ParamType::Int,
         .defaultValue = 16,
         .min = 1,
         .max = 256,
         .unit = "patches per side",
         .help = "where every receiver's traversal starts: the tree level with at most this many patches per "
                 "side",
         .source = "001 §3.5 (16^2)"},
        {.name = "max_depth",
         .type = ParamType::Int,
         .defaultValue = 256,
         .min = 1,
         .max = 1024,
         .unit = "patches per side",
         .help = "finest tree level a traversal visits (maximal traversal depth), clamped to rsm_size",
         .source = "001 §3.5, Figs. 12-13"},
    };
    for (auto& s : eyeHierarchyParamSpecs()) specs.push_back(std::move(s));
    specs.push_back(receiverShareCapSpec());
    for (auto& s : biasCompensationParamSpecs()) specs.push_back(std::move(s));
    TechniqueInfo info{"hier_isr",
                       "hierarchical image-space radiosity: per-receiver cuts through the light tree",
                       "001 §3.5", ParamTable(std::move(specs))};
    // Every RSM texel is a leaf of the light tree: a full traversal reaches rsm_size^2 lights.
    // max_depth (a resolution) caps it: the traversal never goes finer.
    info.vplEstimate = [](const ParamSet& p, const ParamSet& frame) {
        return squared(std::min(frame.getInt("rsm_size"), p.getInt("max_depth")));
    };
    // The count is capped by the finest level a traversal may reach (a power of two, the tree's
    // level sides), and the start level with it.
    info.limitVpls = [](ParamSet& p, long vpls) {
        long side = 1;
        while ((side * 2) * (side * 2) <= vpls) side *= 2;
        if (side < p.getInt("max_depth")) p.set("max_depth", side);
        if (p.getInt("hier_coarsest") > p.getInt("max_depth")) p.set("hier_coarsest", p.getInt("max_depth"));
    };
    // The traversal's time grows far more slowly than the leaves below max_depth: its gather at
    // 288 x 240 (cornell, hier_coarsest 1) took 2.8, 24.7, 58.9 and 87.6 ms at max_depth 4, 16, 64 and
    // 256, 31x over 4,096x the leaves, leaves^0.41 (docs/interactive.md). A linear model fitted on a
    // capped frame never let the frame budget lift the cap (max_depth 4 at 20 ms against 80).
    info.vplCostExponent = 0.4;
    // Near the frame's own leaves the exponent is the traversal's: its visits against those one level
    // coarser would make (the leaf level's left out), a quarter of the leaves. The traversal's work
    // per leaf only falls as the leaves grow (cornell at 288 x 240, hier_coarsest 1: at tau 0.01 the
    // gather grew 11x, 2.3x and 1.6x over three sixteenfold steps from 16 leaves, at tau 0 11x, 12x
    // and 16x), so this exponent, measured one level below, does not under-predict the levels above:
    // at tau 0 the fixed 0.4 had the live view go from 311 leaves to 1,295, a 202 ms frame.
    info.localVplCostExponent = [](const nlohmann::json& counts) {
        const double visited = counts.value("nodes_visited_mean", 0.0);
        const double leaf = counts.value("nodes_visited_leaf_mean", 0.0);
        const double coarser = visited - leaf;
        if (!(visited > 0.0) || !(leaf > 0.0) || !(coarser > 0.0)) return 0.0; // no level to compare
        return std::log(visited / coarser) / std::log(4.0);
    };
    info.capReceiverShare = setReceiverShareCap;
    info.eyeHierarchy = true;
    info.biasCompensation = true;
    info.vplPasses = {"light_tree", "vpl_gather"};
    info.lightViewPasses = {"light_tree"};
    return info;
}

} // namespace gis
