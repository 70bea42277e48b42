#version 450 core
#include "common.glsl"
#include "render/instance.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inTexcoord;
layout(location = 3) in vec4 inTangent; // xyz tangent, w bitangent sign; zero without a normal map
layout(location = 4) in vec4 inColor;   // COLOR_0, linear RGBA; white without one

// -1: eye camera; v >= 0: light view v (shadow map and RSM layer v)
uniform int uView;

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
    gl_Position = (uView < 0 ? gFrame.viewProj : gLights.views[uView].viewProj) * vec4(vWorldPos, 1.0);
}
