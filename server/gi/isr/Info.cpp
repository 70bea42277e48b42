// The catalog entry of `isr` (image-space radiosity): its parameter table and capabilities, GL-free
// (gi/Catalog.h). The passes are in Isr.cpp.
#include <algorithm>

#include "gi/Catalog.h"
#include "gi/common/ParamSpecs.h"

namespace gis {

TechniqueInfo isrInfo() {
    std::vector<ParamSpec> specs = {
        {.name = "isr_coarsest",
         .type = ParamType::Int,
         .defaultValue = 16,
         .min = 1,
         .max = 256,
         .unit = "patches per side",
         .help = "coarsest light patches: the tree level with at most this many patches per side",
         .source = "001 §3.4, Fig. 7 (16^2)"},
        {.name = "isr_finest",
         .type = ParamType::Int,
         .defaultValue = 64,
         .min = 1,
         .max = 256,
         .unit = "patches per side",
         .help = "finest light patches (maximum VPL subdivision), clamped to rsm_size",
         .source = "001 Fig. 10 (64^2)"},
        {.name = "light_depth_threshold",
         .type = ParamType::Float,
         .defaultValue = 0.2,
         .min = 0.0,
         .max = 1.0,
         .unit = "fraction of light distance",
         .help =
             "refine a light patch where (max - min) distance to the light exceeds this fraction of the min",
         .source = "001 §3.4 (no value given; chosen)"},
        {.name = "light_normal_threshold",
         .type = ParamType::Float,
         .defaultValue = 0.25,
         .min = 0.0,
         .max = 2.0,
         .help = "refine a light patch where any normal component's range exceeds this",
         .source = "001 §3.4 (no value given); 000 Figs. 11-12 eye-space quality setting"},
    };
    for (auto& s : eyeHierarchyParamSpecs()) specs.push_back(std::move(s));
    specs.push_back(receiverShareCapSpec());
    for (auto& s : biasCompensationParamSpecs()) specs.push_back(std::move(s));
    TechniqueInfo info{"isr",
                       "image-space radiosity: per-frame light-space patches gathered at stencil receivers",
                       "001 §3.4", ParamTable(std::move(specs))};
    info.vplEstimate = [](const ParamSet& p, const ParamSet&) { return squared(p.getInt("isr_finest")); };
    // The cut never goes finer than isr_finest (nor than the coarsest level, isr_coarsest).
    info.limitVpls = [](ParamSet& p, long vpls) {
        long side = p.getInt("isr_finest");
        while (side > 1 && side * side > vpls) side = side / 2;
        p.set("isr_finest", std::max(1L, side));
        if (p.getInt("isr_coarsest") > side) p.set("isr_coarsest", side);
    };
    info.capReceiverShare = setReceiverShareCap;
    info.eyeHierarchy = true;
    info.biasCompensation = true;
    info.vplPasses = {"light_tree", "vpl_gather"};
    info.lightViewPasses = {"light_tree"};
    return info;
}

} // namespace gis
