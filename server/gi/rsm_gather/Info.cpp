// The catalog entries of `rsm_gather` (000's grid-VPL gather) and `ssbc` (002's configuration of the
// same pipeline): parameter tables and capabilities, GL-free (gi/Catalog.h). The passes are in
// RsmGather.cpp.
#include "gi/Catalog.h"
#include "gi/common/ParamSpecs.h"

namespace gis {

namespace {

/// The gather sums each VPL's (clamped) light; bias compensation filters the sum in screen space,
/// which an average of partial sums would not reproduce.
bool gatherVplParts(const ParamSet& technique) {
    return technique.getInt("ssbc_iterations") == 0;
}

/// Its indirect shadows: the VPLs' cube shadow maps, when on.
bool vplShadowsOn(const ParamSet& p) {
    return p.getBool("vpl_shadows");
}

} // namespace

TechniqueInfo rsmGatherInfo() {
    TechniqueInfo info{"rsm_gather", "full-resolution gather from VPLs on a regular RSM grid",
                       "000 §3, Eq. 2", ParamTable(withVplShadowParams(vplParamSpecs(VplKernel::Point))),
                       [](const ParamSet&) { return true; }};
    info.vplEstimate = gridVplEstimate;
    info.limitVpls = limitGridVpls;
    info.vplVisibility = true;
    info.indirectShadows = vplShadowsOn;
    info.biasCompensation = true;
    info.vplParts = gatherVplParts;
    info.vplPasses = {"vpl_gather"};
    return info;
}

TechniqueInfo ssbcInfo() {
    // 002's configuration on rsm_gather's pipeline: the K3 clamp on and one compensation step
    // (docs/ssbc.md). Only the defaults differ, so `rsm_gather --param clamp_b=..,ssbc_iterations=1`
    // renders the same image.
    std::vector<ParamSpec> specs = withVplShadowParams(vplParamSpecs(VplKernel::Point));
    for (auto& s : specs) {
        if (s.name == "clamp_b") s.defaultValue = kSsbcDefaultClampB;
        if (s.name == "ssbc_iterations") s.defaultValue = 1;
    }
    TechniqueInfo info{"ssbc", "clamped grid-VPL gather (K3) with screen-space bias compensation", "002 §3-4",
                       ParamTable(std::move(specs)), [](const ParamSet&) { return true; }};
    info.vplEstimate = gridVplEstimate;
    info.limitVpls = limitGridVpls;
    info.vplVisibility = true;
    info.indirectShadows = vplShadowsOn;
    info.biasCompensation = true;
    info.vplParts = gatherVplParts;
    info.vplPasses = {"vpl_gather"};
    return info;
}

} // namespace gis
