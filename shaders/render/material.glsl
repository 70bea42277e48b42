// Per-draw material inputs (set by the scene drawer).
uniform vec4 uBaseColor;      // linear RGBA factor
uniform vec3 uEmissive;       // linear radiance
uniform int uHasTexture;      // 1 when uBaseColorTex holds the base colour texture
layout(binding = 0) uniform sampler2D uBaseColorTex; // sRGB texture, decoded by the sampler

vec3 materialAlbedo(vec2 uv) {
    vec4 c = uBaseColor;
    if (uHasTexture == 1) c *= texture(uBaseColorTex, uv);
    return clamp(c.rgb, 0.0, 1.0);
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
