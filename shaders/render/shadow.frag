#version 450 core
// Depth only: the shadow map needs no colour output. Built with GIS_ALPHA_CUTOUT (scenes with
// cut-out materials), a cut-out fragment casts no shadow.
#include "render/material.glsl"

in vec2 vTexcoord;

void main() {
    CUT_OUT(vTexcoord);
}
