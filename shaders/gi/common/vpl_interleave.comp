#version 450 core
// Refinement's VPL parts (FrameInputs::vplPart) in a contiguous run: part p of P is the VPLs p, p + P,
// p + 2P, ... of the set, copied to 0, 1, 2, ... of a second buffer, so the part's gather reads its
// VPLs batch by batch (gi/common/vpl_batch.glsl) like a whole set. The glossy data and shadow maps keep
// the set's indices.
#include "common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer VplIn {
    Vpl gVplsIn[];
};
layout(std430, binding = 1) writeonly buffer VplOut {
    Vpl gVplsOut[];
};

uniform int uPartCount; // VPLs in the part
uniform int uPart;      // p
uniform int uParts;     // P >= 1

void main() {
    int k = int(gl_GlobalInvocationID.x);
    if (k >= uPartCount) return;
    gVplsOut[k] = gVplsIn[uPart + k * uParts];
}
