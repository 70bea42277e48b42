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
/// receiver_share_cap, the per-frame work cap of a gather over the eye hierarchy's receivers
/// (TechniqueInfo::capReceiverShare, capVplsForReceivers), and the capability that sets it.
ParamSpec receiverShareCapSpec();
void setReceiverShareCap(ParamSet& technique, double share);

/// vpl_shadows, vpl_shadow_size, vpl_shadow_bias (gi/common/VplShadows.h).
std::vector<ParamSpec> vplShadowParamSpecs();
/// `specs` followed by vplShadowParamSpecs().
std::vector<ParamSpec> withVplShadowParams(std::vector<ParamSpec> specs);

/// Most bias-compensation steps (002: "1 to 3 iterations").
inline constexpr int kMaxIterations = 3;

/// `ssbc`'s K3 bound in 1/size^2: r = size/sqrt(40), 0.32 m in the 2 m Cornell room (docs/ssbc.md).
inline constexpr double kSsbcDefaultClampB = 40.0;

// Distance-like knobs are relative to the scene's size, the longest side of its bounds, so one value
// gives the same image at any unit scale (a CAD export in millimetres, a terrain in kilometres): a
// min_distance of 0.05 is 0.1 m in the 2 m Cornell room and 20 units in a 400-unit bracket. The
// shaders take metres (scene units); these convert, with `sceneSize` the longest side in metres.

/// The floor on a scene size (m) that keeps the conversions finite for an empty or flat scene.
inline constexpr float kMinSceneSize = 1e-6f;
/// `min_distance` (fraction of the scene size) in metres; 0 without the knob.
float vplMinDistance(const ParamSet& params, float sceneSize);
/// `clamp_b` (1/size^2) as K3's bound b in 1/m^2; 0 = off (or no such knob).
double vplClampB(const ParamSet& params, float sceneSize);
/// 1/b in m^2 for vpl_transport.glsl's uVplInvClampB; 0 = off.
float vplInverseClampB(const ParamSet& params, float sceneSize);

} // namespace gis
