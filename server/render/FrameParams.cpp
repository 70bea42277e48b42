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
        // Non-diffuse surfaces (docs/nondiffuse.md; scene/Brdf.h is the reflection model).
        {.name = "specular_lobe", .type = ParamType::Enum, .defaultValue = 0,
         .help = "glossy lobe of every specular surface: GGX (glTF metallic-roughness) or the normalised Phong "
                 "lobe of 000 (exponent 2/roughness^4 - 2)",
         .source = "glTF 2.0; 000 Fig. 6", .options = {"ggx", "phong"}},
        {.name = "glossy_split", .type = ParamType::Float, .defaultValue = 0.35, .min = 0.0, .max = 1.0,
         .unit = "roughness",
         .help = "surfaces at least this rough take their glossy indirect light from the VPLs (techniques "
                 "with glossy transport); smoother ones from the environment probe or a planar mirror",
         .source = "eng (000: VPL point samples miss sharp highlights)"},
        {.name = "env_size", .type = ParamType::Int, .defaultValue = 128, .min = 8, .max = 512, .unit = "texels",
         .help = "side of each face of the dynamic environment cube map rendered from the probe",
         .source = "004 §2.1", .logScale = true},
        {.name = "env_samples", .type = ParamType::Int, .defaultValue = 32, .min = 1, .max = 256,
         .unit = "samples", .help = "GGX-lobe samples per texel when prefiltering each roughness level",
         .source = "004 §2.2.2", .logScale = true},
        {.name = "env_parallax", .type = ParamType::Enum, .defaultValue = 0,
         .help = "box: intersect reflected rays with the scene bounds before the lookup (parallax "
                 "correction); off: the environment is infinitely distant (004 §2's assumption)",
         .source = "eng", .options = {"box", "off"}},
        {.name = "mirror_depth", .type = ParamType::Int, .defaultValue = 1, .min = 0, .max = 3,
         .unit = "reflections",
         .help = "recursion depth of planar mirrors (a mirror seen in a mirror); 0 shades mirrors with the "
                 "environment probe",
         .source = "004 §5.1"},
        {.name = "mirror_roughness", .type = ParamType::Float, .defaultValue = 0.1, .min = 0.0, .max = 0.5,
         .unit = "roughness",
         .help = "a flat mesh whose material is metallic >= 0.9 and at most this rough is a planar mirror",
         .source = "eng"},
        {.name = "mirror_blur", .type = ParamType::Enum, .defaultValue = 0,
         .help = "on: blur each planar reflection by its material's roughness and the reflected distance "
                 "(004 §5.1.1); off: sharp",
         .source = "004 §5.1.1", .options = {"off", "on"}},
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
        // The non-diffuse effects are resolved by the renderer itself when left at auto: on when the
        // scene has such materials (render/Reflections), narrowed per view by the planner.
        {.name = "effect_specular", .type = ParamType::Enum, .defaultValue = 0,
         .help = "direct specular highlights from the spotlight: auto = on when a material has a specular lobe",
         .source = "eng", .options = {"auto", "on", "off"}},
        {.name = "effect_glossy", .type = ParamType::Enum, .defaultValue = 0,
         .help = "glossy VPL transport (rough specular surfaces): auto = on when such materials exist and the "
                 "technique supports it",
         .source = "000 §3.4", .options = {"auto", "on", "off"}},
        {.name = "effect_env", .type = ParamType::Enum, .defaultValue = 0,
         .help = "dynamic environment-probe reflections (smooth specular surfaces): auto = on when such "
                 "materials exist",
         .source = "004 §2", .options = {"auto", "on", "off"}},
        {.name = "effect_mirrors", .type = ParamType::Enum, .defaultValue = 0,
         .help = "planar mirrors by re-rendering the mirrored view: auto = on when the scene has planar mirrors",
         .source = "004 §5.1", .options = {"auto", "on", "off"}},
    });
    return table;
}

} // namespace gis
