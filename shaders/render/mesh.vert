#version 450 core
#include "common.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inTexcoord;

// 0: eye camera, 1: spotlight (shadow map and RSM)
uniform int uView;

out vec3 vWorldPos;
out vec3 vNormal;
out vec2 vTexcoord;

void main() {
    vWorldPos = inPosition;
    vNormal = inNormal;
    vTexcoord = inTexcoord;
    gl_Position = (uView == 0 ? gFrame.viewProj : gFrame.lightViewProj) * vec4(inPosition, 1.0);
}
