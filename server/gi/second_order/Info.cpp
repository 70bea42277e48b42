// The catalog entry of `second_order` (second-order illumination with negative lights): its parameter table
// and capabilities, GL-free (gi/Catalog.h). The passes are in SecondOrder.cpp.
#include <algorithm>
#include <cmath>

#include "gi/Catalog.h"
#include "gi/common/ParamSpecs.h"
#include "gi/second_order/Limits.h"

namespace gis {

using second_order::kMaxNegative;
using second_order::kMaxPositive;
using second_order::kNoFixupThreshold;

TechniqueInfo secondOrderInfo() {
    std::vector<ParamSpec> specs = {
        {.name = "positive_count",
         .type = ParamType::Int,
         .defaultValue = 256,
         .min = 0,
         .max = kMaxPositive,
         .unit = "lights",
         .help = "indirect lights: the first Halton sphere points inside the spot cone, looked up in the RSM",
         .source = "003 §3.1, Table 1 (100-450)"},
        {.name = "negative_count",
         .type = ParamType::Int,
         .defaultValue = 128,
         .min = 0,
         .max = kMaxNegative,
         .unit = "lights",
         .help =
             "negative indirect lights placed on back-lit camera-visible points (0 = no indirect shadows)",
         .source = "003 §3.3, Table 1 (half the positive count)"},
        {.name = "discontinuity_threshold",
         .type = ParamType::Float,
         .defaultValue = 0.05,
         .min = 0.0,
         .max = kNoFixupThreshold,
         .unit = "",
         .help = "full-resolution fix-up where 1 - n.n' or plane distance / eye distance to a low-res "
                 "neighbour reaches this; 0 = all full resolution, 2 = no fix-up",
         .source = "003 §3.5 (no value given; chosen, docs/second_order.md)"},
        {.name = "lowres_factor",
         .type = ParamType::Int,
         .defaultValue = 2,
         .min = 1,
         .max = 8,
         .unit = "px per side",
         .help = "full-resolution pixels per low-resolution texel side",
         .source = "003 §3.5 (2x2)"},
        {.name = "min_distance",
         .type = ParamType::Float,
         .defaultValue = 0.05,
         .min = 0.0,
         .max = 0.5,
         .unit = "fraction of scene size",
         .help = "distance clamp of the 1/d^2 falloff of positive and negative lights, relative to the "
                 "longest side of the scene's bounds (0.05: 0.1 m in a 2 m room)",
         .source = "003 §3.2 (no clamp given; chosen as for the other point kernels)"},
    };
    for (auto& s : biasCompensationParamSpecs()) specs.push_back(std::move(s));
    TechniqueInfo info{"second_order",
                       "Halton indirect lights with negative lights for indirect shadows, low-res + fix-up",
                       "003 §3.1-3.5", ParamTable(std::move(specs))};
    info.vplEstimate = [](const ParamSet& p, const ParamSet&) {
        return static_cast<long>(p.getInt("positive_count")) + p.getInt("negative_count");
    };
    // Negative lights shadow what the positive ones light: both shrink in proportion.
    info.limitVpls = [](ParamSet& p, long vpls) {
        const long positive = p.getInt("positive_count"), negative = p.getInt("negative_count");
        if (positive + negative <= vpls || positive + negative <= 0) return;
        const double f = static_cast<double>(std::max(vpls, 1L)) / static_cast<double>(positive + negative);
        const ParamSpec* spec = p.table().find("positive_count");
        const long minPositive = spec ? static_cast<long>(spec->min) : 1;
        p.set("positive_count", std::max(minPositive, static_cast<long>(std::floor(positive * f))));
        const ParamSpec* nspec = p.table().find("negative_count");
        const long minNegative = nspec ? static_cast<long>(nspec->min) : 0;
        p.set("negative_count", std::max(minNegative, static_cast<long>(std::floor(negative * f))));
    };
    info.biasCompensation = true;
    info.viewSampled = true;
    info.indirectShadows = [](const ParamSet& p) { return p.getInt("negative_count") > 0; };
    info.vplPasses = {"lowres_gather", "fixup_gather"};
    return info;
}

} // namespace gis
