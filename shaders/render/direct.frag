#version 450 core
// Direct light from the spotlight with a PCF-filtered shadow map, plus emission.
#include "common.glsl"

layout(binding = 0) uniform sampler2D gPosition;
layout(binding = 1) uniform sampler2D gNormal;
layout(binding = 2) uniform sampler2D gAlbedo;
layout(binding = 3) uniform sampler2D gEmissive;
layout(binding = 4) uniform sampler2DShadow gShadowMap;

layout(location = 0) out vec4 outRadiance;

float shadowVisibility(vec3 worldPos, vec3 n, vec3 l) {
    // Normal offset of about one shadow texel at this distance hides acne on lit surfaces.
    float dist = length(gFrame.lightPos.xyz - worldPos);
    float texelWorld = 2.0 * gFrame.rsmInfo.y * dist / gFrame.rsmInfo.z;
    float cosTheta = clamp(dot(n, l), 0.0, 1.0);
    vec3 p = worldPos + n * texelWorld * (1.0 + 1.5 * (1.0 - cosTheta));
    vec4 clip = gFrame.lightViewProj * vec4(p, 1.0);
    if (clip.w <= 1e-6) return 0.0;
    vec3 ndc = clip.xyz / clip.w;
    vec3 uvz = ndc * 0.5 + 0.5;
    if (any(lessThan(uvz.xy, vec2(0.0))) || any(greaterThan(uvz.xy, vec2(1.0)))) return 0.0;
    int r = int(gFrame.rsmInfo.w);
    float texel = 1.0 / gFrame.rsmInfo.z;
    float sum = 0.0;
    float count = 0.0;
    for (int y = -r; y <= r; ++y)
        for (int x = -r; x <= r; ++x) {
            sum += texture(gShadowMap, vec3(uvz.xy + vec2(x, y) * texel, uvz.z));
            count += 1.0;
        }
    return sum / count;
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 pos = texelFetch(gPosition, px, 0);
    if (pos.w < 0.5) {
        outRadiance = vec4(0.0);
        return;
    }
    vec3 n = texelFetch(gNormal, px, 0).xyz;
    vec3 albedo = texelFetch(gAlbedo, px, 0).rgb;
    vec3 emissive = texelFetch(gEmissive, px, 0).rgb;
    vec3 radiance = emissive;
    if (gFrame.toneInfo.z > 0.5) {
        vec3 toLight = gFrame.lightPos.xyz - pos.xyz;
        float d2 = dot(toLight, toLight);
        // A receiver at the light's position gets nothing: the 1/d^2 singularity has no meaningful
        // direction there (digest S.4 case 1).
        if (d2 > 1e-12) {
            vec3 l = toLight * inversesqrt(d2);
            float cosTheta = max(dot(n, l), 0.0);
            float e = gFrame.lightPos.w * spotFactor(-l) * cosTheta / d2;
            if (e > 0.0) radiance += albedo * kInvPi * gFrame.lightColor.rgb * e * shadowVisibility(pos.xyz, n, l);
        }
    }
    outRadiance = vec4(max(sanitize(radiance), vec3(0.0)), 1.0);
}
