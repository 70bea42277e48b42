// The catalog entry of `multires_gather` (multiresolution gather): its parameter table and capabilities,
// GL-free (gi/Catalog.h). The passes are in MultiresGather.cpp.
#include "gi/Catalog.h"

#include "gi/common/ParamSpecs.h"

namespace gis {

TechniqueInfo multiresGatherInfo() {
    std::vector<ParamSpec> specs = vplParamSpecs(VplKernel::Disk);
    for (auto& s : eyeHierarchyParamSpecs()) specs.push_back(std::move(s));
    specs.push_back(receiverShareCapSpec());
    TechniqueInfo info{"multires_gather", "stencil-selected multiresolution gather from grid VPLs, upsampled",
                       "001 §3.2", ParamTable(std::move(specs))};
    info.vplEstimate = gridVplEstimate;
    info.limitVpls = limitGridVpls;
    info.capReceiverShare = setReceiverShareCap;
    info.eyeHierarchy = true;
    info.biasCompensation = true;
    // The gather's irradiance is linear in the VPLs up to the reconstruction; bias compensation
    // filters the sum in screen space.
    info.vplParts = [](const ParamSet& technique) { return technique.getInt("ssbc_iterations") == 0; };
    info.vplPasses = {"vpl_gather"};
    return info;
}

} // namespace gis
