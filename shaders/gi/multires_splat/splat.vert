#version 450 core
// Subsplats drawn as points (000 §3 step 7: points were 5% faster than quads): one point on its
// patch's texel of the flattened multiresolution buffer. Geometry refinement draws the one list
// instanced once per VPL; per-VPL refinement names its VPL in the item.
#include "common.glsl"
#include "gi/common/eye_hierarchy.glsl"

#if GIS_ITEM_ATTRIBUTE
layout(location = 0) in uvec2 aItem; // transform-feedback lists are drawn as vertex buffers
#else
layout(std430, binding = 5) readonly buffer SplatList { uvec2 gSplat[]; };
#endif

uniform ivec2 uAtlasSize;
uniform int uPerVpl;

flat out uint vVpl;
flat out uint vPatch;

void main() {
#if GIS_ITEM_ATTRIBUTE
    uvec2 item = aItem;
#else
    uvec2 item = gSplat[gl_VertexID];
#endif
    vVpl = uPerVpl != 0 ? item.x : uint(gl_InstanceID);
    vPatch = item.y;
    ivec2 t = ivec2(int(item.y & 0x3FFFu), int((item.y >> 14) & 0x3FFFu));
    ivec2 a = eyeAtlas(int(item.y >> 28), t);
    gl_Position = vec4((vec2(a) + 0.5) / vec2(uAtlasSize) * 2.0 - 1.0, 0.0, 1.0);
    gl_PointSize = 1.0;
}
