#version 450 core
// Refinement's VPL parts (FrameInputs::vplPart) in contiguous runs: part p of P is the VPLs p, p + P,
// p + 2P, ... of the set, and this pass copies them to start_p, start_p + 1, ... of a second buffer
// (start_p = p floor(N/P) + min(p, N mod P)), so a part's gather reads its VPLs batch by batch through
// the uniform block like a whole set. The glossy data and shadow maps keep the original indices.
#include "common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer VplIn {
    Vpl gVplsIn[];
};
layout(std430, binding = 1) writeonly buffer VplOut {
    Vpl gVplsOut[];
};

uniform int uCount; // N, VPLs in the set
uniform int uParts; // P >= 1

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= uCount) return;
    int part = i % uParts;
    int start = part * (uCount / uParts) + min(part, uCount % uParts);
    gVplsOut[start + i / uParts] = gVplsIn[i];
}
