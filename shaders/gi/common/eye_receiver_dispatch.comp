#version 450 core
// After the stencil pass (one invocation): the receiver passes' indirect dispatch from the count the
// stencil pass appended, so the host never waits for it.
#include "gi/common/eye_receiver_list.glsl"

layout(local_size_x = 1) in;

void main() {
    uint count = min(gReceiverHeader.counts.x, uint(gReceivers.length()));
    uint groups = (count + uint(GIS_EYE_RECEIVER_GROUP) - 1u) / uint(GIS_EYE_RECEIVER_GROUP);
    uint x = min(groups, GIS_EYE_RECEIVER_MAX_GROUPS_X);
    uint y = x > 0u ? (groups + x - 1u) / x : 1u;
    gReceiverHeader.dispatch = uvec4(x, y, 1u, 0u);
}
