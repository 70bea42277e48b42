#version 450 core
// gi-bench point-shadows: a cube face of a point light's shadow map (a plain perspective view).
layout(location = 0) in vec3 inPosition;
#include "render/instance.glsl"
uniform mat4 uViewProj;
void main() {
    gl_Position = uViewProj * vec4(placedPosition(inPosition), 1.0);
}
