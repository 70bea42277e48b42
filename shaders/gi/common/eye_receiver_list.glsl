// The eye hierarchy's receiver list (shared/EyeHierarchy.h, EyeHierarchy::build): the stencil pass
// appends every receiver (eyeAppendReceiver, eye_receivers.frag); a receiver pass is a compute program
// that defines GIS_EYE_RECEIVER_PASS before including this file (after common.glsl): one invocation
// per item (eyeReceiver), lit where eyeReceiverGeometry says, adding its light to the illumination
// atlas (eyeAddIllumination).
#include "shared/EyeHierarchy.h"

layout(std430, binding = GIS_SSBO_EYE_RECEIVERS) buffer EyeReceiverList {
    EyeReceiverListHeader gReceiverHeader;
    uint gReceivers[]; // y << 16 | x, atlas texels
};

// The buffer holds one item per atlas texel and each texel is appended at most once; the bound
// only guards a list the host sized wrongly.
void eyeAppendReceiver(ivec2 atlasTexel) {
    uint i = atomicAdd(gReceiverHeader.counts.x, 1u);
    if (i < uint(gReceivers.length())) gReceivers[i] = uint(atlasTexel.x) | (uint(atlasTexel.y) << 16);
}

#ifdef GIS_EYE_RECEIVER_PASS

layout(local_size_x = GIS_EYE_RECEIVER_GROUP) in;

// Read-modify-write by the texel's own invocation only; the host puts an image barrier between
// dispatches (EyeHierarchy::dispatchReceivers), so successive dispatches add in order.
layout(rgba32f, binding = GIS_IMAGE_EYE_ILLUMINATION) uniform image2D uEyeIllumination;

// The first group of this dispatch: 0 for the whole list at once, else the chunk's first
// (EyeHierarchy::dispatchReceivers with a stop check).
uniform uint uEyeReceiverGroupBase;

// This invocation's receiver, false past the list's end (the last group's spare lanes). Groups are
// laid out in rows of gl_NumWorkGroups.x (2D once a list outgrows one dimension).
bool eyeReceiver(out ivec2 atlasTexel) {
    uint group = uEyeReceiverGroupBase + gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint i = group * uint(GIS_EYE_RECEIVER_GROUP) + gl_LocalInvocationID.x;
    atlasTexel = ivec2(0);
    if (i >= min(gReceiverHeader.counts.x, uint(gReceivers.length()))) return false;
    uint item = gReceivers[i];
    atlasTexel = ivec2(int(item & 0xFFFFu), int(item >> 16));
    return true;
}

layout(binding = 0) uniform sampler2D uGeoPosition; // atlas: xyz mean position, w covered pixels
layout(binding = 1) uniform sampler2D uGeoNormal;   // atlas: xyz mean normal
layout(binding = 8) uniform sampler2D gPosition;    // level 0 is the G-buffer itself
layout(binding = 9) uniform sampler2D gNormal;

// Where a receiver is lit: a level-0 texel is its G-buffer pixel, a coarser patch its mean position
// and normal (EyeHierarchy::bindInputs binds both).
void eyeReceiverGeometry(ivec2 atlasTexel, out vec3 position, out vec3 normal) {
    bool pixel = all(lessThan(vec2(atlasTexel), gFrame.viewport.xy));
    position = pixel ? texelFetch(gPosition, atlasTexel, 0).xyz
                     : texelFetch(uGeoPosition, atlasTexel, 0).xyz;
    normal = pixel ? texelFetch(gNormal, atlasTexel, 0).xyz : texelFetch(uGeoNormal, atlasTexel, 0).xyz;
}

// What a receiver pass adds, as the additive blend of a fragment pass did: rgb accumulates, alpha 1
// marks data for the reconstruction.
void eyeAddIllumination(ivec2 atlasTexel, vec3 rgb) {
    vec4 before = imageLoad(uEyeIllumination, atlasTexel);
    imageStore(uEyeIllumination, atlasTexel, vec4(before.rgb + rgb, 1.0));
}

#endif
