#version 450 core
// Depth only: the shadow map needs no colour output.
void main() {}
