#include "gi/Catalog.h"

#include <algorithm>
#include <cmath>

#include "core/Error.h"

namespace gis {

const std::vector<TechniqueInfo>& techniqueCatalog() {
    static const std::vector<TechniqueInfo> catalog = {noIndirectInfo(),    rsmGatherInfo(),      ssbcInfo(),
                                                       multiresSplatInfo(), multiresGatherInfo(), isrInfo(),
                                                       hierIsrInfo(),       secondOrderInfo()};
    return catalog;
}

const TechniqueInfo& findTechniqueInfo(const std::string& name, const std::string& where) {
    for (const auto& info : techniqueCatalog())
        if (info.name == name) return info;
    std::string known;
    for (const auto& info : techniqueCatalog()) known += (known.empty() ? "'" : ", '") + info.name + "'";
    throw InputError(where, "unknown technique '" + name + "' (known: " + known + ")");
}

} // namespace gis

namespace gis {

double usableVplCostExponent(double exponent) {
    return std::isfinite(exponent) ? std::clamp(exponent, 0.05, 1.0) : 1.0;
}

double frameVplCostExponent(const TechniqueInfo& info, const nlohmann::json& counts) {
    if (info.localVplCostExponent && counts.is_object()) {
        const double local = info.localVplCostExponent(counts);
        if (std::isfinite(local) && local > 0.0) return usableVplCostExponent(local);
    }
    return usableVplCostExponent(info.vplCostExponent);
}

long capVplsForReceivers(const TechniqueInfo& info, ParamSet& technique, long estimate, double pixels,
                         double receivers, double exponent) {
    if (!info.limitVpls || !technique.has("receiver_share_cap") || estimate <= 0) return 0;
    const double shareCap = technique.getFloat("receiver_share_cap");
    if (!(shareCap < 1.0) || !(pixels > 0.0) || !(receivers > shareCap * pixels)) return 0;
    constexpr long kFloorVpls = 16;
    const double e = usableVplCostExponent(exponent > 0.0 ? exponent : info.vplCostExponent);
    const double workShare = shareCap * pixels / receivers; // (0, 1)
    const long allowed =
        std::max(std::min(estimate, kFloorVpls),
                 static_cast<long>(std::floor(static_cast<double>(estimate) * std::pow(workShare, 1.0 / e))));
    if (allowed >= estimate) return 0;
    info.limitVpls(technique, allowed);
    return allowed;
}

void limitGridVpls(ParamSet& technique, long vpls) {
    const long current = technique.getInt("vpl_grid");
    long side = static_cast<long>(std::floor(std::sqrt(static_cast<double>(std::max(vpls, 1L)))));
    // Rounding may land one off either way for large squares.
    while (side > 1 && side * side > vpls) --side;
    if (side < current) technique.set("vpl_grid", std::max(1L, side));
}

} // namespace gis
