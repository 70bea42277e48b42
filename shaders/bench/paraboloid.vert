#version 450 core
// gi-bench point-shadows: one hemisphere of a dual-paraboloid shadow map (Brabec et al. 2002). The
// paraboloid's projection is not linear, so the rasteriser's straight edges between projected
// vertices are only right for triangles small against their distance to the light: what the
// benchmark measures against the cube map.
layout(location = 0) in vec3 inPosition;
#include "render/instance.glsl"
uniform mat4 uLightView;   // world -> light space, hemisphere 0 around -z
uniform float uHemisphere; // 1: the -z hemisphere; -1: the +z one
uniform vec2 uDepthRange;  // near, far (m): radial distance mapped to [0, 1]
void main() {
    vec3 v = (uLightView * vec4(placedPosition(inPosition), 1.0)).xyz;
    v.z *= uHemisphere;
    float d = length(v);
    vec3 n = v / max(d, 1e-20);
    gl_ClipDistance[0] = -n.z; // this hemisphere only
    float w = 1.0 - n.z;       // >= 1 on it
    float depth = (d - uDepthRange.x) / max(uDepthRange.y - uDepthRange.x, 1e-20);
    gl_Position = vec4(n.x / w, n.y / w, depth * 2.0 - 1.0, 1.0);
}
