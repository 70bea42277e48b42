#version 450 core
// Evaluates one VPL at one subsplat (000 Eq. 2) and adds it to the multiresolution buffer.
#include "common.glsl"
#include "gi/common/eye_hierarchy.glsl"
#include "gi/common/eye_pixel.glsl"
#include "gi/common/eye_patch.glsl"
#include "gi/multires_splat/splat_common.glsl"

flat in uint vVpl;
flat in uint vPatch;

layout(location = 0) out vec4 outLight; // rgb added by blending; alpha 1 marks data

void main() {
    EyePatch p = eyePatch(patchLevel(vPatch), patchTexel(vPatch));
    outLight = vec4(max(sanitize(splatContribution(vVpl, p)), vec3(0.0)), 1.0);
}
