// Parameter tables shared by the VPL techniques, declared once. GL-free (target gis_catalog): the
// technique catalog (gi/Catalog.h) builds every technique's table from these, and the GL passes read
// the values by the names declared here.
#pragma once

#include <vector>

#include "core/Param.h"

namespace gis {

enum class VplKernel { Point = 0, Disk = 1 }; ///< values match GIS_KERNEL_* in vpl_transport.glsl

/// `vpl_grid`, `kernel` (point|disk, default as given), `min_distance` (point kernel only) and the
/// K3 clamp / bias compensation parameters (biasCompensationParamSpecs, all off by default).
std::vector<ParamSpec> vplParamSpecs(VplKernel defaultKernel);
VplKernel vplKernel(const ParamSet& params);

/// clamp_b (K3's bound, 0 = off), ssbc_iterations and the rest of 002's compensation knobs
/// (gi/common/BiasCompensation.h describes them).
std::vector<ParamSpec> biasCompensationParamSpecs(double defaultClampB = 0.0, int defaultIterations = 0);

/// The multiresolution eye hierarchy's knobs: coarsest_size, the depth and normal metrics and
/// thresholds, diagonal_refine (gi/common/EyeHierarchy.h).
std::vector<ParamSpec> eyeHierarchyParamSpecs();

/// vpl_shadows, vpl_shadow_size, vpl_shadow_bias (gi/common/VplShadows.h).
std::vector<ParamSpec> vplShadowParamSpecs();
/// `specs` followed by vplShadowParamSpecs().
std::vector<ParamSpec> withVplShadowParams(std::vector<ParamSpec> specs);

/// Most bias-compensation steps (002: "1 to 3 iterations").
inline constexpr int kMaxIterations = 3;

/// `ssbc`'s K3 bound: 1/m^2, r = 1/sqrt(b) = 0.32 m (docs/ssbc.md).
inline constexpr double kSsbcDefaultClampB = 10.0;

} // namespace gis
