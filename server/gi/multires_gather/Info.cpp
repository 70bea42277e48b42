// The catalog entry of `multires_gather` (multiresolution gather): its parameter table and capabilities,
// GL-free (gi/Catalog.h). The passes are in MultiresGather.cpp.
#include "gi/Catalog.h"

#include <algorithm>

#include "gi/common/ParamSpecs.h"

namespace gis {

TechniqueInfo multiresGatherInfo() {
    std::vector<ParamSpec> specs = vplParamSpecs(VplKernel::Disk);
    for (auto& s : eyeHierarchyParamSpecs()) specs.push_back(std::move(s));
    specs.push_back({.name = "receiver_share_cap",
                     .type = ParamType::Float,
                     .defaultValue = 1.0,
                     .min = 0.001,
                     .max = 1.0,
                     .unit = "receivers per pixel",
                     .help = "work cap of one frame: where the eye hierarchy selects more receivers than "
                             "this share of the pixels, the gather uses a coarser VPL grid, side scaled "
                             "by sqrt(cap / share), so that receivers x VPLs stay at the cap's; 1 = never "
                             "(receivers never outnumber pixels). The live view sets it from its last "
                             "frame's share",
                     .source = "eng"});
    TechniqueInfo info{"multires_gather", "stencil-selected multiresolution gather from grid VPLs, upsampled",
                       "001 §3.2", ParamTable(std::move(specs))};
    info.vplEstimate = gridVplEstimate;
    info.limitVpls = limitGridVpls;
    info.capReceiverShare = [](ParamSet& technique, double share) {
        technique.set("receiver_share_cap", std::clamp(share, 0.001, 1.0));
    };
    info.eyeHierarchy = true;
    info.biasCompensation = true;
    // The gather's irradiance is linear in the VPLs up to the reconstruction; bias compensation
    // filters the sum in screen space.
    info.vplParts = [](const ParamSet& technique) { return technique.getInt("ssbc_iterations") == 0; };
    return info;
}

} // namespace gis
