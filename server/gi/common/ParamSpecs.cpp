// The parameter tables the VPL techniques share (declared once: validation, schemas, CLI, client
// panel and sweeps derive from them). GL-free: part of the technique catalog (gi/Catalog.h).
#include "gi/common/ParamSpecs.h"

#include <algorithm>
#include <cmath>

namespace gis {

std::vector<ParamSpec> vplParamSpecs(VplKernel defaultKernel) {
    std::vector<ParamSpec> specs = {
        {.name = "vpl_grid",
         .type = ParamType::Int,
         .defaultValue = 16,
         .min = 1,
         .max = 256,
         .unit = "VPLs per side",
         .help = "VPLs on a regular RSM grid, vpl_grid^2 in total (<= rsm_size)",
         .source = "000 §3.1; 001 Table 1 uses 256 VPLs",
         .logScale = true},
        {.name = "kernel",
         .type = ParamType::Enum,
         .defaultValue = static_cast<double>(defaultKernel),
         .help = "VPL kernel: point with distance clamp (000 Eq. 2) or disk-to-point form factor (001 Eq. 1)",
         .source = "000 Eq. 2; 001 Eq. 1",
         .options = {"point", "disk"}},
        {.name = "min_distance",
         .type = ParamType::Float,
         .defaultValue = 0.05,
         .min = 0.0,
         .max = 0.5,
         .unit = "fraction of scene size",
         .help = "point kernel only: distance clamp of the 1/d^2 falloff (bounds the r->0 singularity), "
                 "relative to the longest side of the scene's bounds (0.05: 0.1 m in a 2 m room)",
         .source = "000 Fig. 13 (value not given; chosen)"},
    };
    for (auto& s : biasCompensationParamSpecs()) specs.push_back(std::move(s));
    return specs;
}

VplKernel vplKernel(const ParamSet& params) {
    return params.getEnum("kernel") == "disk" ? VplKernel::Disk : VplKernel::Point;
}

std::vector<ParamSpec> biasCompensationParamSpecs(double defaultClampB, int defaultIterations) {
    return {
        {.name = "clamp_b",
         .type = ParamType::Float,
         .defaultValue = defaultClampB,
         .min = 0.0,
         .max = 4e4,
         .unit = "1/scene size^2",
         .help =
             "K3 bound b on the VPL geometry term, E = Phi/pi min(G, b) (radius size/sqrt(b) where G > b, "
             "size the longest side of the scene's bounds: 40 is 10/m^2 in a 2 m room); 0 = off, the "
             "technique's own kernel",
         .source = "002 G_b (no value given; digest S.5 item 1)"},
        {.name = "ssbc_iterations",
         .type = ParamType::Int,
         .defaultValue = static_cast<double>(defaultIterations),
         .min = 0,
         .max = kMaxIterations,
         .unit = "steps",
         .help =
             "screen-space bias compensation steps T_r^k on the clamped image (0 = off; needs clamp_b > 0)",
         .source = "002 Eq. 3, §4 (1 to 3)"},
        {.name = "ssbc_solid_angle",
         .type = ParamType::Float,
         .defaultValue = 0.08,
         .min = 0.0,
         .max = 4.0,
         .unit = "sr",
         .help = "refine a compensation sample whose solid angle A cos / d^2 exceeds this",
         .source = "002 §4.2 (0.08 sr)"},
        {.name = "ssbc_discontinuity_angle",
         .type = ParamType::Float,
         .defaultValue = 0.04,
         .min = 0.0,
         .max = 4.0,
         .unit = "sr",
         .help = "refine a sample spanning a discontinuity only above this solid angle",
         .source = "002 §4.2 (about 0.04)"},
        {.name = "ssbc_grazing_angle",
         .type = ParamType::Float,
         .defaultValue = 80.0,
         .min = 1.0,
         .max = 90.0,
         .unit = "deg",
         .help = "normal-view angle beyond which a pixel's area fades quadratically in cos (90 = no fade)",
         .source = "002 §4.3 (80 deg; falloff curve chosen)"},
        {.name = "ssbc_input",
         .type = ParamType::Enum,
         .defaultValue = 0,
         .help = "what step 1 integrates: direct + clamped indirect (002, for multi-bounce VPLs) or the "
                 "direct light only (the exact one-bounce residual of single-bounce VPLs)",
         .source = "002 Eq. 3 (illumination); direct is an engineering option",
         .options = {"illumination", "direct"}},
        {.name = "ssbc_levels",
         .type = ParamType::Int,
         .defaultValue = 7,
         .min = 1,
         .max = 12,
         .unit = "levels",
         .help = "compensation mip levels including full resolution (7: 16^2 coarsest at 1024^2); the image "
                 "does not depend on it, the time does",
         .source = "002 §4.2 uses 64^2 at 1024^2 (5 levels); 7 measured faster here (docs/ssbc.md)"},
        {.name = "ssbc_blur",
         .type = ParamType::Bool,
         .defaultValue = 0,
         .help = "edge-preserving 5x5 cross-bilateral blur of the summed compensation only (normal and "
                 "relative-distance falloffs, covered pixels only, energy conserving) before it is added",
         .source = "002 §4.4 (optional bilateral Gaussian; kernel and falloffs chosen, docs/ssbc.md)"},
        {.name = "ssbc_half_resolution",
         .type = ParamType::Bool,
         .defaultValue = 0,
         .help = "integrate one receiver per 2x2 block (level-1 means) and upsample bilaterally (nearest "
                 "block where all weights vanish); needs ssbc_levels >= 2",
         .source = "002 §5 (bilateral upsampling; nearest-sample fallback instead of recomputation)"},
    };
}

float vplMinDistance(const ParamSet& params, float sceneSize) {
    if (!params.has("min_distance")) return 0.0f;
    const double d = params.getFloat("min_distance") * std::max(sceneSize, kMinSceneSize);
    return std::isfinite(d) ? static_cast<float>(d) : 0.0f;
}

double vplClampB(const ParamSet& params, float sceneSize) {
    if (!params.has("clamp_b")) return 0.0;
    const double size = std::max(sceneSize, kMinSceneSize);
    const double b = params.getFloat("clamp_b") / (size * size);
    return b > 0.0 && std::isfinite(b) ? b : 0.0;
}

float vplInverseClampB(const ParamSet& params, float sceneSize) {
    const double b = vplClampB(params, sceneSize);
    const double inv = b > 0.0 ? 1.0 / b : 0.0;
    return std::isfinite(inv) ? static_cast<float>(inv) : 0.0f;
}

ParamSpec receiverShareCapSpec() {
    return {.name = "receiver_share_cap",
            .type = ParamType::Float,
            .defaultValue = 1.0,
            .min = 0.001,
            .max = 1.0,
            .unit = "receivers per pixel",
            .help =
                "work cap of one frame: where the eye hierarchy selects more receivers than this share of "
                "the pixels, the gather uses fewer VPLs (the VPL knob lowered as the frame budget would), "
                "so that receivers x VPLs stay at the cap's; 1 = never (receivers never outnumber pixels). "
                "The live view sets it from its last frame's share",
            .source = "eng"};
}

void setReceiverShareCap(ParamSet& technique, double share) {
    technique.set("receiver_share_cap", std::clamp(share, 0.001, 1.0));
}

std::vector<ParamSpec> eyeHierarchyParamSpecs() {
    return {
        {.name = "coarsest_size",
         .type = ParamType::Int,
         .defaultValue = 16,
         .min = 1,
         .max = 256,
         .unit = "texels",
         .help = "longer side of the coarsest eye-space level (patches of up to size/coarsest pixels)",
         .source = "000 §3 step 5 and 001 §4: 16^2 at 1024^2"},
        {.name = "depth_metric",
         .type = ParamType::Enum,
         .defaultValue = 0,
         .help = "depth discontinuity test: min-max eye distance or the depth-derivative max-mipmap",
         .source = "000 §3 step 4",
         .options = {"minmax", "derivative"}},
        {.name = "depth_threshold",
         .type = ParamType::Float,
         .defaultValue = 0.1,
         .min = 0.0,
         .max = 1.0,
         .unit = "fraction of depth",
         .help = "min-max metric: refine where (max - min) eye distance exceeds this fraction of the min",
         .source = "000/001 give no value (digest S.5); chosen"},
        {.name = "depth_derivative_threshold",
         .type = ParamType::Float,
         .defaultValue = 0.02,
         .min = 0.0,
         .max = 1.0,
         .unit = "fraction of depth per pixel",
         .help = "derivative metric: refine where |grad d| / d exceeds this (a step of 2% between pixels)",
         .source = "000 §3 step 4 (no value given); chosen"},
        {.name = "normal_metric",
         .type = ParamType::Enum,
         .defaultValue = 0,
         .help = "normal discontinuity test: per-component min-max or the curvature max-mipmap (000 Eq. 1)",
         .source = "000 §3 step 4",
         .options = {"minmax", "curvature"}},
        {.name = "normal_threshold",
         .type = ParamType::Float,
         .defaultValue = 0.25,
         .min = 0.0,
         .max = 2.0,
         .help = "min-max metric: refine where any normal component's range exceeds this",
         .source = "000 Figs. 11-12: 0.2-0.25 (quality) to 1.4-1.5 (speed)"},
        {.name = "curvature_threshold",
         .type = ParamType::Float,
         .defaultValue = 0.1,
         .min = 0.0,
         .max = 2.0,
         .help = "curvature metric: refine where 2 sin(angle/2) between neighbouring normals exceeds this",
         .source = "000 Fig. 12: 0.1 (low) and 0.3 (high)"},
        {.name = "diagonal_refine",
         .type = ParamType::Bool,
         .defaultValue = 1,
         .help = "a discontinuity in a diagonal neighbour also refines (removes blocky artifacts, 2-3% cost)",
         .source = "000 §5.2"},
        {.name = "detail_alpha",
         .type = ParamType::Float,
         .defaultValue = 0.0,
         .min = 0.0,
         .max = 1.0,
         .help = "detail modulation c * (alpha <V,N> + 1 - alpha); 0 = off",
         .source = "000 Eq. 3 (0.5 in Figs. 11-12)"},
    };
}

std::vector<ParamSpec> vplShadowParamSpecs() {
    return {
        {.name = "vpl_shadows",
         .type = ParamType::Bool,
         .defaultValue = 0,
         .help = "indirect visibility: a cube shadow map per VPL (off = no indirect shadows, as 000/001/003)",
         .source = "002 (imperfect shadow maps); exact maps chosen, docs/ssbc.md"},
        {.name = "vpl_shadow_size",
         .type = ParamType::Int,
         .defaultValue = 32,
         .min = 8,
         .max = 256,
         .unit = "texels",
         .help = "side of each cube face of a VPL shadow map",
         .source = "eng"},
        {.name = "vpl_shadow_bias",
         .type = ParamType::Float,
         .defaultValue = 0.02,
         .min = 0.0,
         .max = 0.5,
         .unit = "fraction of distance",
         .help = "receiver offset along its normal and depth tolerance, as a fraction of the VPL distance",
         .source = "eng"},
    };
}

std::vector<ParamSpec> withVplShadowParams(std::vector<ParamSpec> specs) {
    for (auto& s : vplShadowParamSpecs()) specs.push_back(std::move(s));
    return specs;
}

} // namespace gis
