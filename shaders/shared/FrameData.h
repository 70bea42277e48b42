// Uniform-block layouts shared by C++ and GLSL (std140). Rules: only vec4/mat4 members (no bool,
// no bare vec3), sizes multiples of 16 bytes (static_assert on the C++ side), binding points here.
// C++ includes this through render/ShaderShared.h; GLSL through #include "shared/FrameData.h".
#ifndef GIS_SHARED_FRAME_DATA_H
#define GIS_SHARED_FRAME_DATA_H

#define GIS_UBO_FRAME 0
#define GIS_UBO_LIGHTS 5
// The gathers' VPL batch: a buffer texture at this texture unit (gi/common/vpl_batch.glsl).
#define GIS_TEXTURE_VPLS 15
#define GIS_MAX_VPLS_PER_BATCH 1024

// Punctual lights (glTF KHR_lights_punctual) and the views their shadow maps and RSMs are rendered
// from: a spot light has one perspective view, a point light six (cube faces, 90 degrees each), a
// directional light one orthographic view fitted to the scene's bounds (frame/LightModel.h).
#define GIS_MAX_LIGHTS 64
#define GIS_MAX_LIGHT_VIEWS (GIS_MAX_LIGHTS * 6)
#define GIS_LIGHT_SPOT 0
#define GIS_LIGHT_POINT 1
#define GIS_LIGHT_DIRECTIONAL 2

struct FrameUniforms {
    mat4 viewProj;  // world -> eye clip space
    vec4 cameraPos; // xyz: eye position (m); w: unused
    vec4 viewport;  // x: width, y: height (px); z: 1/width; w: 1/height
    vec4 rsmInfo;   // x: RSM side per light view (texels); y: tan(half fov) of the widest perspective light
                    // view (1 without one); z: shadow-map side per light view; w: PCF radius (texels)
    vec4 toneInfo;  // x: exposure scale 2^EV; y: operator (0 linear, 1 filmic); z: any light on (0/1); w: RSM
                    // texel solid angle (0 exact, 1 equal)
    vec4 shadingInfo; // x: specular lobe (GIS_LOBE_GGX 0, GIS_LOBE_PHONG 1); y: glossy_split roughness; z:
                      // direct specular (0/1); w: unused
};

// One light as the shaders see it. Intensity is radiometric in the renderer's units: candela for
// spot and point lights, lux for directional ones, times the colour (docs/lights.md).
struct GpuLight {
    vec4 position;  // xyz: position (m; spot and point); w: intensity (cd, or lux for directional)
    vec4 direction; // xyz: unit direction the light points along (spot, directional); w: cos(outer cone)
    vec4 color;     // rgb: linear colour >= 0; w: cos(inner cone)
    vec4 info;      // x: type (GIS_LIGHT_*); y: range (m, 0 = infinite); z: first view index; w: view count
};

// One shadow-map and RSM layer: the same layer index in every light-view array texture.
struct LightView {
    mat4 viewProj; // world -> clip space of this view
    vec4 eye;  // xyz: centre of projection (perspective) or the centre of the near plane (orthographic); w:
               // light index
    vec4 info; // x: 0 perspective, 1 orthographic; y: tan(half fov) (perspective) or half-width (m,
               // orthographic); z: axis of the view (cube face 0..5, 0 otherwise); w: unused
    vec4 axis; // xyz: unit forward direction of the view; w: unused
};

struct LightUniforms {
    GpuLight lights[GIS_MAX_LIGHTS];
    LightView views[GIS_MAX_LIGHT_VIEWS];
    ivec4 counts; // x: lights; y: views; z, w: unused
};

// One virtual point light: a diffuse emitter of reflected flux at an RSM sample.
struct Vpl {
    vec4 position; // xyz: world position (m); w: 1 valid, 0 empty (contributes nothing)
    vec4 normal;   // xyz: unit surface normal; w: disk area A (m^2, 001 Eq. 3)
    vec4 flux;     // rgb: reflected flux (W, in the renderer's intensity units); w: texels merged
};

// Glossy data of a grid VPL (glossy VPL transport, docs/nondiffuse.md), indexed like the Vpl buffer.
struct VplGlossy {
    vec4 specular; // rgb: F0, a: perceptual roughness; means over the cell's specular texels weighted by
                   // their incident flux
    vec4 incident; // rgb: flux arriving on the cell's specular texels (W, before any reflectance); a: 1 +
                   // index of the light it came from when there are any, 0 otherwise
};

#endif
