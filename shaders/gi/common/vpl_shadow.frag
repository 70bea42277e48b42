#version 450 core
// Stores the distance from the VPL (not the projective depth), so lookups compare distances. Built
// with GIS_ALPHA_CUTOUT (scenes with cut-out materials), a cut-out fragment casts no indirect shadow.
#include "render/material.glsl"

in vec3 vFromVpl;
in vec2 vTexcoord;
uniform float uFar; // m
void main() {
    CUT_OUT(vTexcoord);
    gl_FragDepth = clamp(length(vFromVpl) / uFar, 0.0, 1.0);
}
