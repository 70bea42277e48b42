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

void limitGridVpls(ParamSet& technique, long vpls) {
    const long current = technique.getInt("vpl_grid");
    long side = static_cast<long>(std::floor(std::sqrt(static_cast<double>(std::max(vpls, 1L)))));
    // Rounding may land one off either way for large squares.
    while (side > 1 && side * side > vpls) --side;
    if (side < current) technique.set("vpl_grid", std::max(1L, side));
}

} // namespace gis
