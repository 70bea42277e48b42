#version 450 core
// Forward render of the scene from a viewpoint other than the eye camera (environment-probe faces,
// mirrored views): world position through uViewProj, with one user clip plane.
#include "common.glsl"
#include "render/instance.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inTexcoord;
layout(location = 3) in vec4 inTangent; // xyz tangent, w bitangent sign; zero without a normal map
layout(location = 4) in vec4 inColor;   // COLOR_0, linear RGBA; white without one

uniform mat4 uViewProj;  // world -> clip space of this view
uniform vec4 uClipPlane; // keeps dot(xyz, p) + w >= 0 (a mirror's front side); (0, 0, 0, 1) keeps all

out vec3 vWorldPos;
out vec3 vNormal;
out vec2 vTexcoord;
out vec4 vTangent;
out vec4 vColor;

void main() {
    vWorldPos = placedPosition(inPosition);
    vNormal = placedNormal(inNormal);
    vTexcoord = inTexcoord;
    vTangent = placedTangent(inTangent);
    vColor = inColor;
    gl_ClipDistance[0] = dot(uClipPlane.xyz, vWorldPos) + uClipPlane.w;
    gl_Position = uViewProj * vec4(vWorldPos, 1.0);
}
