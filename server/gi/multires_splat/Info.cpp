// The catalog entry of `multires_splat` (multiresolution splatting): its parameter table and capabilities,
// GL-free (gi/Catalog.h). The passes are in MultiresSplat.cpp.
#include "gi/Catalog.h"
#include "gi/common/ParamSpecs.h"

namespace gis {

TechniqueInfo multiresSplatInfo() {
    std::vector<ParamSpec> specs = vplParamSpecs(VplKernel::Point);
    for (auto& s : eyeHierarchyParamSpecs()) specs.push_back(std::move(s));
    specs.push_back({.name = "refinement",
                     .type = ParamType::Enum,
                     .defaultValue = 0,
                     .help = "subsplat refinement: once per frame on geometry (diffuse) or per VPL on "
                             "illumination differences (any BRDF)",
                     .source = "000 §3.3 / §3.3.1",
                     .options = {"geometry", "illumination"}});
    specs.push_back(
        {.name = "illum_threshold",
         .type = ParamType::Float,
         .defaultValue = 1e-4,
         .min = 1e-7,
         .max = 1.0,
         .unit = "W/(m^2 sr)",
         .help = "per-VPL refinement: subdivide where one VPL's radiance differs by more than this",
         .source = "000 §3.3.1 (T, value not given; chosen)",
         .logScale = true});
    specs.push_back({.name = "phong_ks",
                     .type = ParamType::Float,
                     .defaultValue = 0.0,
                     .min = 0.0,
                     .max = 1.0,
                     .help =
                         "per-VPL refinement: specular weight of the receivers' normalised Phong BRDF (0 = "
                         "Lambertian)",
                     .source = "000 Fig. 6 (Phong Buddha)"});
    specs.push_back({.name = "phong_exponent",
                     .type = ParamType::Float,
                     .defaultValue = 32.0,
                     .min = 1.0,
                     .max = 1000.0,
                     .help = "per-VPL refinement: Phong exponent of the receivers' BRDF",
                     .source = "eng",
                     .logScale = true});
    specs.push_back({.name = "list_builder",
                     .type = ParamType::Enum,
                     .defaultValue = 1,
                     .help = "how geometry refinement builds the subsplat lists: compute append buffers or a "
                             "geometry shader with transform feedback (000; measured faster here). Per-VPL "
                             "refinement always uses compute",
                     .source = "000 §3 step 5 (transform feedback); measured in docs/multires.md",
                     .options = {"compute", "transform_feedback"}});
    specs.push_back({.name = "max_subsplats",
                     .type = ParamType::Int,
                     .defaultValue = 4 << 20,
                     .min = 1024,
                     .max = 16 << 20,
                     .unit = "items",
                     .help = "capacity of each subsplat list (8 bytes an item); items beyond it are splatted "
                             "unrefined and counted",
                     .source = "000 Table 1 (N/A entries: excessive memory)",
                     .logScale = true});
    // Glossy transport needs per-VPL (illumination) refinement: the geometry list splats irradiance,
    // correct for diffuse receivers only.
    TechniqueInfo info{"multires_splat", "iteratively refined subsplats splatted from grid VPLs, upsampled",
                       "000 §3", ParamTable(std::move(specs)),
                       [](const ParamSet& params) { return params.getEnum("refinement") == "illumination"; }};
    info.vplEstimate = gridVplEstimate;
    info.limitVpls = limitGridVpls;
    info.eyeHierarchy = true;
    info.biasCompensation = true;
    info.vplPasses = {"subsplat_splat"};
    return info;
}

} // namespace gis
