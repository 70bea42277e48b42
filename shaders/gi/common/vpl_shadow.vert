#version 450 core
#extension GL_ARB_shader_viewport_layer_array : require
// Cube shadow maps of all VPLs in one instanced draw: instance i renders face i % 6 of VPL
// uFirstVpl + i / 6 into layer i (vertex-shader layer selection).
#include "shared/FrameData.h"
#include "gi/common/vpl_shadow.glsl"
#include "render/instance.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 2) in vec2 inTexcoord; // for alpha cutouts (vpl_shadow.frag)
layout(location = 4) in vec4 inColor;    // COLOR_0: multiplies the base colour's alpha
layout(std430, binding = 0) readonly buffer VplBuffer {
    Vpl gVpls[];
};
uniform int uFirstVpl;
uniform float uFar; // m

out vec3 vFromVpl;
out vec2 vTexcoord;
out vec4 vColor;

void main() {
    int face = gl_InstanceID % 6;
    vec3 p = placedPosition(inPosition) - gVpls[uFirstVpl + gl_InstanceID / 6].position.xyz;
    vFromVpl = p;
    vTexcoord = inTexcoord;
    vColor = inColor;
    // (u, v, depth along the face axis), matching vplCubeFace.
    vec3 q = face == 0 ? vec3(p.yz, p.x) : face == 1 ? vec3(p.yz, -p.x) : face == 2 ? vec3(p.xz, p.y)
           : face == 3 ? vec3(p.xz, -p.y) : face == 4 ? vec3(p.xy, p.z) : vec3(p.xy, -p.z);
    float n = 1e-4 * uFar, f = uFar;
    gl_Position = vec4(q.x, q.y, (q.z * (f + n) - 2.0 * f * n) / (f - n), q.z);
    gl_Layer = gl_InstanceID;
}
