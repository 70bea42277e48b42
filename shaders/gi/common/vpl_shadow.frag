#version 450 core
// Stores the distance from the VPL (not the projective depth), so lookups compare distances.
in vec3 vFromVpl;
uniform float uFar; // m
void main() { gl_FragDepth = clamp(length(vFromVpl) / uFar, 0.0, 1.0); }
