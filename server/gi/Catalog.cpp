#include "gi/Catalog.h"

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
