#version 450 core
// SSBC level 0 (002 §4.1-4.2): per pixel the world position, the normal, the footprint area A_i with
// the grazing fade (BiasCompensation.h), and the step-0 illumination X_0 = direct + clamped indirect.
#include "common.glsl"
#include "gi/common/ssbc_common.glsl"

layout(local_size_x = GIS_SSBC_GROUP, local_size_y = GIS_SSBC_GROUP) in;

layout(binding = 0) uniform sampler2D gPosition;
layout(binding = 1) uniform sampler2D gNormal;
layout(binding = 2) uniform sampler2D uDirect;   // radiance
layout(binding = 3) uniform sampler2D uIndirect; // the technique's clamped indirect radiance

layout(rgba32f, binding = 0) uniform writeonly image2D uGeoOut;
layout(rgba32f, binding = 1) uniform writeonly image2D uNormalOut;
layout(rgba32f, binding = 2) uniform writeonly image2D uIllumOut;

uniform float uTanHalfFov; // tan(vertical fov / 2) of the eye camera
uniform vec3 uForward;     // unit view direction
uniform float uCosGrazing; // cos of the angle where the fade starts (0: no fade)
uniform int uWithIndirect; // 1: X_0 = direct + clamped indirect (002); 0: direct only (ssbc_input)

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(gFrame.viewport.xy);
    vec4 geo = vec4(0.0), nrm = vec4(0.0), illum = vec4(0.0);
    vec4 stats = vec4(0.0);
    vec4 pos = all(lessThan(p, size)) ? texelFetch(gPosition, p, 0) : vec4(0.0);
    // A non-finite position is a hole, not a sample: it would sit in the level-0 chain (digest S.4 case 5).
    if (pos.w > 0.5 && !any(isnan(pos.xyz)) && !any(isinf(pos.xyz))) {
        vec3 n = texelFetch(gNormal, p, 0).xyz;
        float nl = length(n);
        n = nl > 1e-6 ? n / nl : vec3(0.0, 0.0, 1.0);
        vec3 toEye = gFrame.cameraPos.xyz - pos.xyz;
        float dist2 = dot(toEye, toEye);
        vec3 v = dist2 > 1e-20 ? toEye * inversesqrt(dist2) : -uForward;
        float cosView = abs(dot(n, v));
        float cosOff = max(dot(uForward, -v), 0.0);
        float pixel = 2.0 * uTanHalfFov / max(gFrame.viewport.y, 1.0);
        float omega = pixel * pixel * cosOff * cosOff * cosOff; // solid angle of this pixel (sr)
        // Faded footprint: Omega d^2 / cos above the grazing angle; Omega d^2 cos / cosG^2 beyond it.
        float area = cosView >= uCosGrazing ? omega * dist2 / max(cosView, 1e-6)
                                            : omega * dist2 * cosView / max(uCosGrazing * uCosGrazing, 1e-12);
        area = isBad(area) ? 0.0 : max(area, 0.0);
        vec3 x0 = texelFetch(uDirect, p, 0).rgb;
        vec3 ind = max(sanitize(texelFetch(uIndirect, p, 0).rgb), vec3(0.0));
        x0 = max(sanitize(x0), vec3(0.0)) + (uWithIndirect != 0 ? ind : vec3(0.0));
        geo = vec4(pos.xyz, area);
        nrm = vec4(n, 0.0);
        illum = vec4(x0, 1.0);
        stats = vec4((ind.r + ind.g + ind.b) / 3.0, 0.0, 0.0, 1.0);
    }
    imageStore(uGeoOut, p, geo);
    imageStore(uNormalOut, p, nrm);
    imageStore(uIllumOut, p, illum);
    ssbcGroupSum(stats, 0);
}
