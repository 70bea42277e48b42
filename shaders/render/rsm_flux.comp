#version 450 core
// Reflected flux of each light view's RSM layer, one workgroup per layer: the luminance of the
// summed flux of its valid texels. The VPL budget is split across views in proportion to it
// (gi/common/VplGrid.h), so a dim light does not take VPLs from a bright one.
#include "common.glsl"

layout(local_size_x = 256) in;

layout(binding = 0) uniform sampler2DArray gRsmPosition;
layout(binding = 1) uniform sampler2DArray gRsmFlux;

layout(std430, binding = 0) writeonly buffer ViewFlux {
    float gViewFlux[];
};

uniform int uRsmSize; // texels per side of each layer

shared float sSum[256];

void main() {
    uint tid = gl_LocalInvocationID.x;
    int layer = int(gl_WorkGroupID.x);
    int size = max(uRsmSize, 1);
    float sum = 0.0;
    for (int i = int(tid); i < size * size; i += 256) {
        ivec3 t = ivec3(i % size, i / size, layer);
        if (texelFetch(gRsmPosition, t, 0).w >= 0.5)
            sum += dot(max(sanitize(texelFetch(gRsmFlux, t, 0).rgb), vec3(0.0)), vec3(0.2126, 0.7152, 0.0722));
    }
    sSum[tid] = sum;
    memoryBarrierShared();
    barrier();
    for (uint stride = 128u; stride > 0u; stride >>= 1u) {
        if (tid < stride) sSum[tid] += sSum[tid + stride];
        memoryBarrierShared();
        barrier();
    }
    if (tid == 0u) gViewFlux[layer] = sSum[0];
}
