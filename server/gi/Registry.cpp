#include <algorithm>

#include "core/Error.h"
#include "gi/Technique.h"
#include "gi/hier_isr/HierIsr.h"
#include "gi/isr/Isr.h"
#include "gi/none/NoIndirect.h"
#include "gi/multires_gather/MultiresGather.h"
#include "gi/multires_splat/MultiresSplat.h"
#include "gi/rsm_gather/RsmGather.h"
#include "gi/second_order/SecondOrder.h"

namespace gis {

const std::vector<TechniqueEntry>& techniqueRegistry() {
    // The GL implementation of each catalog entry, by name; every entry must have one.
    static const std::vector<TechniqueEntry> registry = [] {
        const std::vector<std::pair<std::string, std::function<std::unique_ptr<Technique>()>>>
            implementations = {
                {"none", [] { return std::make_unique<NoIndirect>(); }},
                {"rsm_gather", [] { return std::make_unique<RsmGather>(); }},
                {"ssbc", [] { return std::make_unique<RsmGather>(); }},
                {"multires_splat", [] { return std::make_unique<MultiresSplat>(); }},
                {"multires_gather", [] { return std::make_unique<MultiresGather>(); }},
                {"isr", [] { return std::make_unique<Isr>(); }},
                {"hier_isr", [] { return std::make_unique<HierIsr>(); }},
                {"second_order", [] { return std::make_unique<SecondOrder>(); }},
            };
        std::vector<TechniqueEntry> out;
        for (const TechniqueInfo& info : techniqueCatalog()) {
            auto it = std::find_if(implementations.begin(), implementations.end(),
                                   [&](const auto& impl) { return impl.first == info.name; });
            GIS_ASSERT_MSG(it != implementations.end(),
                           "technique '" + info.name + "' has no GL implementation");
            out.push_back({info, it->second});
        }
        GIS_ASSERT(out.size() == implementations.size());
        return out;
    }();
    return registry;
}

const TechniqueEntry& findTechnique(const std::string& name, const std::string& where) {
    for (const auto& e : techniqueRegistry())
        if (e.info.name == name) return e;
    std::string known;
    for (const auto& e : techniqueRegistry()) known += (known.empty() ? "'" : ", '") + e.info.name + "'";
    throw InputError(where, "unknown technique '" + name + "' (known: " + known + ")");
}

} // namespace gis
