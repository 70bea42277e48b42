#include "frame/VplBudget.h"

#include "gi/Catalog.h"

namespace gis {

long vplEstimate(const FrameState& state) {
    const TechniqueInfo& info = findTechniqueInfo(state.technique);
    return info.vplEstimate ? info.vplEstimate(state.techniqueParams, state.frameParams) : 0;
}

} // namespace gis
