#include "render/FrameParams.h"

namespace gis {

const ParamTable& frameParamTable() {
    static const ParamTable table({
        {.name = "exposure", .type = ParamType::Float, .defaultValue = 0.0, .min = -10.0, .max = 10.0,
         .unit = "EV", .help = "exposure compensation before tone mapping (scale 2^EV)", .source = "eng"},
        {.name = "tonemap", .type = ParamType::Enum, .defaultValue = 0, .help = "tone-mapping operator",
         .source = "eng", .options = {"filmic", "linear"}},
        {.name = "shadow_map_size", .type = ParamType::Int, .defaultValue = 1024, .min = 128, .max = 4096,
         .unit = "texels", .help = "side of the spotlight's shadow map", .source = "eng"},
        {.name = "pcf_radius", .type = ParamType::Int, .defaultValue = 1, .min = 0, .max = 3, .unit = "texels",
         .help = "soft-shadow filter radius: (2r+1)^2 shadow-map taps", .source = "eng"},
        {.name = "rsm_size", .type = ParamType::Int, .defaultValue = 256, .min = 16, .max = 1024, .unit = "texels",
         .help = "side of the reflective shadow map (VPL candidates)", .source = "001 §4 (256^2)"},
        {.name = "rsm_solid_angle", .type = ParamType::Enum, .defaultValue = 0,
         .help = "solid angle per RSM texel: exact (cos^3 law) or equal for every texel (001 Eq. 4; biased, "
                 "000 Fig. 13)",
         .source = "001 Eq. 4", .options = {"exact", "equal"}},
    });
    return table;
}

} // namespace gis
