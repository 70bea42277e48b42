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
        // Effect planning (analysis/EffectPlan.h, docs/effects.md). `manual` is the default so every
        // technique's parameters, and so the default images, stay as they were; `auto` lets the planner
        // switch off effects the scene and view do not call for. The renderer ignores these knobs: the
        // caller plans and applies before rendering (gi-render does; gi-server does not yet).
        {.name = "effects", .type = ParamType::Enum, .defaultValue = 0,
         .help = "effect planning: manual (the technique's parameters decide) or auto (measured per scene "
                 "and view; gi-render --explain)",
         .source = "eng", .options = {"manual", "auto"}},
        {.name = "effect_direct", .type = ParamType::Enum, .defaultValue = 0,
         .help = "force the spotlight off, or leave it to the planner (on keeps it as it is)", .source = "eng",
         .options = {"auto", "on", "off"}},
        {.name = "effect_indirect", .type = ParamType::Enum, .defaultValue = 0,
         .help = "force the diffuse bounce (the technique's indirect passes) on or off", .source = "eng",
         .options = {"auto", "on", "off"}},
        {.name = "effect_occlusion", .type = ParamType::Enum, .defaultValue = 0,
         .help = "force indirect visibility (vpl_shadows) on or off", .source = "eng",
         .options = {"auto", "on", "off"}},
        {.name = "effect_compensation", .type = ParamType::Enum, .defaultValue = 0,
         .help = "force bias compensation of clamp_b (ssbc_iterations 1 or 0) on or off", .source = "eng",
         .options = {"auto", "on", "off"}},
    });
    return table;
}

} // namespace gis
