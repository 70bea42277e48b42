#version 450 core
// 003 §3.3: negative indirect lights. Digest 003.1 step 5 leaves the details open; resolved here:
//  - S_neg at a camera-visible point p (normal n facing the eye) is the irradiance p's back side
//    receives from the positive lights, K4: K1 with cos taken against -n. Light that reaches the
//    back of a visible surface must cross it, so the surface blocks it from whatever lies beyond.
//  - Its direction D is the mean of the directions from p to the lights, weighted by each light's
//    back-side irradiance luminance (003's w_p(l)); Sum w = 0 (no back-lit light) gives no light.
//  - S_neg is evaluated only at the candidate pixels, not as a full texture: the values at the
//    sampled pixels are the same, at candidates x lights instead of pixels x lights cost.
//  - Sampled like the positive lights: candidates are Halton points in the camera's frustum (CPU),
//    and the first N back-lit ones in Halton order become lights. Each candidate stands for
//    Omega_frustum / m of the view, m = candidates examined until N were found.
//  - The negative light at p emits what p blocks: flux = E_back * A, A = (Omega_frustum / m) d^2 /
//    cos(view angle) the visible area it stands for, as a K1 (Lambertian) emitter whose normal is
//    -D, i.e. onward along the blocked light; its flux is stored negated so the gathers subtract it.
#include "common.glsl"
#include "gi/second_order/second_order.glsl"
#include "gi/second_order/k4.glsl"

layout(local_size_x = 256) in;

layout(binding = 0) uniform sampler2D gPosition;
layout(binding = 1) uniform sampler2D gNormal;

layout(std430, binding = 0) buffer Vpls {
    Vpl gVpls[]; // [0, uPositiveCount): positive lights (read); then uNegativeCount slots (written)
};
layout(std430, binding = 1) readonly buffer Candidates {
    ivec4 gCandidates[]; // xy: pixel; z: 1 valid
};

uniform int uPositiveCount;
uniform int uNegativeCount;
uniform int uCandidateCount;
uniform float uFrustumSolidAngle; // sr
uniform float uMinDistance;       // m, the K1 clamp
uniform float uMinCosView;        // clamp of cos(view angle) in the area estimate

shared uint sScan[256];
shared uint sPlaced;
shared uint sExamined;

void main() {
    uint tid = gl_LocalInvocationID.x;
    if (tid == 0u) {
        sPlaced = 0u;
        sExamined = uint(uCandidateCount);
    }
    memoryBarrierShared();
    barrier();

    uint wanted = uint(max(uNegativeCount, 0));
    int chunks = (uCandidateCount + 255) / 256;
    for (int c = 0; c < chunks; ++c) {
        if (sPlaced >= wanted) break; // the same value in every invocation: uniform control flow
        int k = c * 256 + int(tid);
        bool valid = false;
        vec3 position = vec3(0.0), direction = vec3(0.0), blocked = vec3(0.0);
        if (k < uCandidateCount && gCandidates[k].z != 0) {
            vec4 p = texelFetch(gPosition, gCandidates[k].xy, 0);
            vec3 n = texelFetch(gNormal, gCandidates[k].xy, 0).xyz;
            if (p.w >= 0.5) {
                vec3 e = vec3(0.0), weighted = vec3(0.0);
                for (int j = 0; j < uPositiveCount; ++j) {
                    Vpl v = gVpls[j];
                    if (v.position.w < 0.5) continue;
                    vec3 toLight;
                    vec3 ej = backIrradiance(p.xyz, n, v, uMinDistance, toLight);
                    e += ej;
                    weighted += dot(ej, kLuma) * toLight;
                }
                float len2 = dot(weighted, weighted);
                vec3 toEye = gFrame.cameraPos.xyz - p.xyz;
                float eye2 = dot(toEye, toEye);
                if (dot(e, kLuma) > 0.0 && len2 > 1e-30 && eye2 > 1e-20) {
                    float cosView = dot(n, toEye * inversesqrt(eye2));
                    blocked = sanitize(e * (eye2 / max(cosView, uMinCosView))); // W per sr of the view
                    direction = weighted * inversesqrt(len2);
                    position = p.xyz;
                    valid = dot(blocked, kLuma) > 0.0 && !isBad(direction.x + direction.y + direction.z);
                }
            }
        }

        // Inclusive prefix sum of the valid flags keeps the lights in Halton order.
        sScan[tid] = valid ? 1u : 0u;
        memoryBarrierShared();
        barrier();
        for (uint offset = 1u; offset < 256u; offset <<= 1u) {
            uint add = tid >= offset ? sScan[tid - offset] : 0u;
            barrier();
            sScan[tid] += add;
            memoryBarrierShared();
            barrier();
        }
        uint slot = sPlaced + sScan[tid] - 1u;
        if (valid && slot < wanted) {
            Vpl v;
            v.position = vec4(position, 1.0);
            v.normal = vec4(-direction, 0.0);
            v.flux = vec4(-blocked, 1.0);
            gVpls[uPositiveCount + int(slot)] = v;
            if (slot == wanted - 1u) sExamined = uint(k + 1);
        }
        memoryBarrierShared();
        barrier();
        if (tid == 0u) sPlaced = min(sPlaced + sScan[255], wanted);
        memoryBarrierShared();
        barrier();
    }
    memoryBarrierBuffer();
    barrier();

    float omega = uFrustumSolidAngle / float(max(sExamined, 1u));
    for (uint s = tid; s < wanted; s += 256u) {
        int index = uPositiveCount + int(s);
        if (s < sPlaced) {
            gVpls[index].flux.rgb = sanitize(gVpls[index].flux.rgb * omega);
        } else {
            gVpls[index].position = vec4(0.0);
            gVpls[index].normal = vec4(0.0, 1.0, 0.0, 0.0);
            gVpls[index].flux = vec4(0.0);
        }
    }
    if (tid == 0u) {
        gNegativePlaced = sPlaced;
        gActiveVpls = uint(uPositiveCount) + sPlaced;
    }
}
