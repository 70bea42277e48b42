// Spotlight shading shared by the deferred direct pass (direct.frag) and forward renders of the scene
// from other viewpoints (environment probe faces, mirrored views: forward.frag). Binds the shadow
// map at unit 4.
#ifndef GIS_LIGHTING_GLSL
#define GIS_LIGHTING_GLSL
#include "render/brdf.glsl"

layout(binding = 4) uniform sampler2DShadow gShadowMap;

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

// Reflected spotlight radiance towards `toViewer` (unit) at a surface point: diffuse rho_d / pi plus
// the specular lobe when `withSpecular`, shadowed. Exactly 0 at the light's position (S.4 case 1).
vec3 spotReflected(vec3 p, vec3 n, vec3 albedo, vec4 spec, vec3 toViewer, bool withSpecular) {
    if (!(gFrame.toneInfo.z > 0.5)) return vec3(0.0);
    vec3 toLight = gFrame.lightPos.xyz - p;
    float d2 = dot(toLight, toLight);
    if (!(d2 > 1e-12)) return vec3(0.0);
    vec3 l = toLight * inversesqrt(d2);
    float cosTheta = max(dot(n, l), 0.0);
    float e = gFrame.lightPos.w * spotFactor(-l) * cosTheta / d2;
    if (!(e > 0.0)) return vec3(0.0);
    vec3 f = albedo * kInvPi;
    if (withSpecular) f += brdfSpecular(spec.rgb, spec.a, int(gFrame.shadingInfo.x), n, l, toViewer);
    return f * gFrame.lightColor.rgb * e * shadowVisibility(p, n, l);
}

#endif
