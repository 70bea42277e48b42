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
    static const std::vector<TechniqueEntry> registry = {
        {NoIndirect::info(), [] { return std::make_unique<NoIndirect>(); }},
        {RsmGather::info(), [] { return std::make_unique<RsmGather>(); }},
        {RsmGather::ssbcInfo(), [] { return std::make_unique<RsmGather>(); }},
        {MultiresSplat::info(), [] { return std::make_unique<MultiresSplat>(); }},
        {MultiresGather::info(), [] { return std::make_unique<MultiresGather>(); }},
        {Isr::info(), [] { return std::make_unique<Isr>(); }},
        {HierIsr::info(), [] { return std::make_unique<HierIsr>(); }},
        {SecondOrder::info(), [] { return std::make_unique<SecondOrder>(); }},
    };
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
