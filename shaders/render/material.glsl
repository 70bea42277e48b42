// Per-draw material inputs (set by the scene drawer).
uniform vec4 uBaseColor;      // linear RGBA factor
uniform vec3 uEmissive;       // linear radiance
uniform int uHasTexture;      // 1 when uBaseColorTex holds the base colour texture
uniform vec3 uMetalRoughSpec; // x metallic, y perceptual roughness, z specular factor; all [0, 1]
uniform int uMirrorId;        // reflector id (SceneGpu::setSurfaceIds): mirror k + 1, local probe -(k + 1), 0 none
layout(binding = 0) uniform sampler2D uBaseColorTex; // sRGB texture, decoded by the sampler

// Alpha cutouts (glTF alphaMode MASK, and BLEND approximated at 0.5: scene/Scene.h Material). Only
// programs built with GIS_ALPHA_CUTOUT (for scenes that have such materials) discard, so that the
// others keep early depth tests.
#ifdef GIS_ALPHA_CUTOUT
uniform float uAlphaCutoff; // cut out below this alpha (base colour factor x texture); < 0: opaque
bool materialCutOut(vec2 uv) {
    if (uAlphaCutoff < 0.0) return false;
    float alpha = uBaseColor.a;
    if (uHasTexture == 1) alpha *= texture(uBaseColorTex, uv).a;
    return !(alpha >= uAlphaCutoff); // NaN alpha cuts out
}
#define CUT_OUT(uv) if (materialCutOut(uv)) discard
#else
#define CUT_OUT(uv)
#endif

vec3 materialBaseColor(vec2 uv) {
    vec4 c = uBaseColor;
    if (uHasTexture == 1) c *= texture(uBaseColorTex, uv);
    return clamp(c.rgb, 0.0, 1.0);
}

// scene/Brdf.h's surfaceFrom(): F0 = mix(0.04 s, base, metal).
vec3 materialF0(vec3 base) {
    float metal = clamp(uMetalRoughSpec.x, 0.0, 1.0);
    return mix(vec3(0.04 * clamp(uMetalRoughSpec.z, 0.0, 1.0)), base, metal);
}

// The diffuse albedo rho_d = base (1 - metal) (1 - Favg): what every technique multiplies by.
vec3 materialAlbedo(vec2 uv) {
    vec3 base = materialBaseColor(uv);
    vec3 f0 = materialF0(base);
    float f90 = clamp(50.0 * 0.33 * (f0.r + f0.g + f0.b), 0.0, 1.0);
    vec3 favg = f0 + (vec3(f90) - f0) * (1.0 / 21.0);
    return base * (1.0 - clamp(uMetalRoughSpec.x, 0.0, 1.0)) * (vec3(1.0) - favg);
}

// A unit normal facing the viewer; falls back to the geometric normal when the interpolated one
// is degenerate (NaN or zero length after interpolation).
vec3 safeNormal(vec3 n, vec3 worldPos, vec3 toViewer) {
    float len2 = dot(n, n);
    vec3 geo = cross(dFdx(worldPos), dFdy(worldPos));
    vec3 result;
    if (!(len2 > 1e-12)) {
        float g2 = dot(geo, geo);
        result = g2 > 1e-30 ? geo * inversesqrt(g2) : vec3(0.0, 1.0, 0.0);
    } else {
        result = n * inversesqrt(len2);
    }
    // Two-sided: shade the side the viewer (camera or light) sees.
    return dot(result, toViewer) < 0.0 ? -result : result;
}
