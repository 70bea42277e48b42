// Uniform-block layouts shared by C++ and GLSL (std140). Rules: only vec4/mat4 members (no bool,
// no bare vec3), sizes multiples of 16 bytes (static_assert on the C++ side), binding points here.
// C++ includes this through render/ShaderShared.h; GLSL through #include "shared/FrameData.h".
#ifndef GIS_SHARED_FRAME_DATA_H
#define GIS_SHARED_FRAME_DATA_H

#define GIS_UBO_FRAME 0
#define GIS_UBO_VPLS 1
#define GIS_MAX_VPLS_PER_BATCH 1024

struct FrameUniforms {
    mat4 viewProj;       // world -> eye clip space
    mat4 lightViewProj;  // world -> spotlight clip space (shadow map and RSM)
    vec4 cameraPos;      // xyz: eye position (m); w: unused
    vec4 lightPos;       // xyz: spotlight position (m); w: intensity (cd)
    vec4 lightDir;       // xyz: unit direction the spot points along; w: cos(outer cone)
    vec4 lightColor;     // rgb: linear colour; w: cos(inner cone)
    vec4 viewport;       // x: width, y: height (px); z: 1/width; w: 1/height
    vec4 rsmInfo;        // x: RSM size (texels); y: tan(half fov) of the light frustum; z: shadow map size; w: PCF radius (texels)
    vec4 toneInfo;       // x: exposure scale 2^EV; y: operator (0 linear, 1 filmic); z: light enabled (0/1); w: RSM texel solid angle (0 exact, 1 equal)
    vec4 shadingInfo;    // x: specular lobe (GIS_LOBE_GGX 0, GIS_LOBE_PHONG 1); y: glossy_split roughness; z: direct specular (0/1); w: unused
};

// One virtual point light: a diffuse emitter of reflected flux at an RSM sample.
struct Vpl {
    vec4 position;  // xyz: world position (m); w: 1 valid, 0 empty (contributes nothing)
    vec4 normal;    // xyz: unit surface normal; w: disk area A (m^2, 001 Eq. 3)
    vec4 flux;      // rgb: reflected flux (W, in the renderer's intensity units); w: texels merged
};

// Glossy data of a grid VPL (glossy VPL transport, docs/nondiffuse.md), indexed like the Vpl buffer.
struct VplGlossy {
    vec4 specular;  // rgb: F0, a: perceptual roughness; means over the cell's specular texels weighted by their incident flux
    vec4 incident;  // rgb: flux arriving on the cell's specular texels (W, before any reflectance); a: 1 when there are any
};

#endif
