// Per-draw material inputs (set by the scene drawer).

// GIS_MATERIAL_PLAIN: a program for scenes with no texture maps and no vertex colours
// (FrameRenderer's plain passes). llvmpipe runs both sides of a branch even on a uniform, so the
// maps' code (a tangent frame, five texture lookups) would cost every fragment of such a scene; the
// plain program compiles it out, and the uniforms it no longer reads are skipped by the drawer.
#ifdef GIS_MATERIAL_PLAIN
#define GIS_MATERIAL_HAS(flag) false
#else
#define GIS_MATERIAL_HAS(flag) (flag == 1)
#endif
uniform vec4 uBaseColor;      // linear RGBA factor
uniform vec3 uEmissive;       // linear radiance
uniform int uHasTexture;      // 1 when uBaseColorTex holds the base colour texture
uniform vec3 uMetalRoughSpec; // x metallic, y perceptual roughness, z specular factor; all [0, 1]
uniform int uMirrorId;        // reflector id (SceneGpu::setSurfaceIds): mirror k + 1, local probe -(k + 1), 0 none
layout(binding = 0) uniform sampler2D uBaseColorTex; // sRGB texture, decoded by the sampler
in vec4 vColor; // the mesh's COLOR_0 (linear RGBA): multiplies the base colour where uHasVertexColor is 1
uniform int uHasVertexColor;
// The base colour factor times the vertex colour, where the mesh has one (others skip the multiply,
// which is not exact in every interpolation of a constant white).
vec4 materialFactor() {
    return GIS_MATERIAL_HAS(uHasVertexColor) ? uBaseColor * vColor : uBaseColor;
}
// glTF metallicRoughnessTexture (linear: b scales metallic, g roughness) and emissiveTexture (sRGB),
// on the base colour texture's coordinates; unit 1 and 2.
uniform int uHasMetalRoughTex;
uniform int uHasEmissiveTex;
layout(binding = 1) uniform sampler2D uMetalRoughTex;
layout(binding = 2) uniform sampler2D uEmissiveTex;

// glTF occlusionTexture (linear, red channel) with its strength, unit 4: 1 + strength (r - 1), in
// [0, 1]; 1 without a map. The G-buffer keeps it for the composite (albedo alpha).
uniform int uHasOcclusionTex;
uniform float uOcclusionStrength;
layout(binding = 4) uniform sampler2D uOcclusionTex;
float materialOcclusion(vec2 uv) {
    if (!GIS_MATERIAL_HAS(uHasOcclusionTex)) return 1.0;
    float ao = 1.0 + uOcclusionStrength * (texture(uOcclusionTex, uv).r - 1.0);
    return isnan(ao) ? 1.0 : clamp(ao, 0.0, 1.0);
}

// glTF normalTexture (linear, tangent space: rgb * 2 - 1, x and y scaled by uNormalScale), unit 3.
uniform int uHasNormalTex;
uniform float uNormalScale;
layout(binding = 3) uniform sampler2D uNormalTex;

// The shading normal with the normal map applied. `n` is the unit normal already turned to face the
// viewer (safeNormal), `interpolated` the mesh's own normal before that: the map perturbs the mesh's
// side and the result is turned as n was, as the reference does (reference/RayScene.cpp). Unchanged
// without a map or a usable tangent.
vec3 materialNormal(vec3 n, vec3 interpolated, vec4 tangent, vec2 uv) {
    if (!GIS_MATERIAL_HAS(uHasNormalTex)) return n;
    float side = dot(n, interpolated) < 0.0 ? -1.0 : 1.0;
    vec3 base = side * n;
    vec3 t = tangent.xyz - base * dot(base, tangent.xyz);
    float t2 = dot(t, t);
    // Relative to the tangent's own length, which a placement's scale changes (render/instance.glsl).
    if (!(t2 > 1e-12 * dot(tangent.xyz, tangent.xyz))) return n;
    t *= inversesqrt(t2);
    vec3 b = cross(base, t) * (tangent.w < 0.0 ? -1.0 : 1.0);
    vec3 m = texture(uNormalTex, uv).xyz * 2.0 - 1.0;
    m.xy *= uNormalScale;
    vec3 r = t * m.x + b * m.y + base * m.z;
    float r2 = dot(r, r);
    return r2 > 1e-12 && !isnan(r2) ? side * r * inversesqrt(r2) : n;
}

// x metallic, y perceptual roughness, z specular factor; each in [0, 1].
vec3 materialMetalRoughSpec(vec2 uv) {
    vec3 m = uMetalRoughSpec;
    if (GIS_MATERIAL_HAS(uHasMetalRoughTex)) {
        vec4 t = texture(uMetalRoughTex, uv);
        m.x *= t.b;
        m.y *= t.g;
    }
    return clamp(m, 0.0, 1.0);
}

vec3 materialEmissive(vec2 uv) {
    vec3 e = uEmissive;
    if (GIS_MATERIAL_HAS(uHasEmissiveTex)) e *= texture(uEmissiveTex, uv).rgb;
    return e;
}

// Alpha cutouts (glTF alphaMode MASK, and BLEND approximated at 0.5: scene/Scene.h Material). Only
// programs built with GIS_ALPHA_CUTOUT (for scenes that have such materials) discard, so that the
// others keep early depth tests.
#ifdef GIS_ALPHA_CUTOUT
uniform float uAlphaCutoff; // cut out below this alpha (base colour factor x texture); < 0: opaque
bool materialCutOut(vec2 uv) {
    if (uAlphaCutoff < 0.0) return false;
    float alpha = materialFactor().a;
    if (GIS_MATERIAL_HAS(uHasTexture)) alpha *= texture(uBaseColorTex, uv).a;
    return !(alpha >= uAlphaCutoff); // NaN alpha cuts out
}
#define CUT_OUT(uv) if (materialCutOut(uv)) discard
#else
#define CUT_OUT(uv)
#endif

vec3 materialBaseColor(vec2 uv) {
    vec4 c = materialFactor();
    if (GIS_MATERIAL_HAS(uHasTexture)) c *= texture(uBaseColorTex, uv);
    return clamp(c.rgb, 0.0, 1.0);
}

// scene/Brdf.h's surfaceFrom(): F0 = mix(0.04 s, base, metal); `mrs` from materialMetalRoughSpec().
vec3 materialF0(vec3 base, vec3 mrs) {
    return mix(vec3(0.04 * mrs.z), base, mrs.x);
}

// The diffuse albedo rho_d = base (1 - metal) (1 - Favg): what every technique multiplies by.
vec3 materialAlbedo(vec2 uv) {
    vec3 base = materialBaseColor(uv);
    vec3 mrs = materialMetalRoughSpec(uv);
    vec3 f0 = materialF0(base, mrs);
    float f90 = clamp(50.0 * 0.33 * (f0.r + f0.g + f0.b), 0.0, 1.0);
    vec3 favg = f0 + (vec3(f90) - f0) * (1.0 / 21.0);
    return base * (1.0 - mrs.x) * (vec3(1.0) - favg);
}

// F0 and perceptual roughness (the G-buffer's and RSM's specular target).
vec4 materialSpecular(vec2 uv) {
    vec3 mrs = materialMetalRoughSpec(uv);
    return vec4(materialF0(materialBaseColor(uv), mrs), mrs.y);
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
