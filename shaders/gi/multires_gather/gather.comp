#version 450 core
// Multiresolution gather (001 §3.2.2) over the receiver list: one invocation per receiver of the
// flattened multiresolution buffer (the one-pass stencil's receivers, eye_receiver_list.glsl), one
// dispatch per batch of VPLs; each receiver sums the irradiance of every VPL in the batch (the VPL
// cache is the compact VPL buffer, read as texels: gi/common/vpl_batch.glsl) at its mean position
// and normal. Irradiance only: the albedo is applied per pixel after reconstruction. A VPL part
// (refinement, FrameInputs::vplPart) gathers the batches of its own VPLs (vpl_interleave.comp),
// scaled by the number of parts uVplScale.
#define GIS_EYE_RECEIVER_PASS
#include "common.glsl"
#include "gi/common/eye_receiver_list.glsl"
#include "gi/common/vpl_transport.glsl"
#include "gi/common/vpl_batch.glsl"

uniform int uVplCount;
uniform float uVplScale = 1.0; // the number of VPL parts (1 without parts, and when not set)
uniform float uMinDistance; // m, point kernel only

void main() {
    ivec2 a;
    if (!eyeReceiver(a)) return;
    vec3 pos, n;
    eyeReceiverGeometry(a, pos, n);
    vec3 e = vec3(0.0);
#define GATHER_TERM(i) vplIrradianceSelected(pos, n, batchVpl(i), uMinDistance)
    GIS_SUM_OVER_BATCH(e, uVplCount, GATHER_TERM)
    eyeAddIllumination(a, max(sanitize(e * uVplScale), vec3(0.0)));
}
