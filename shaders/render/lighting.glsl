// Punctual-light shading shared by the deferred direct pass (direct.frag) and forward renders of the
// scene from other viewpoints (environment probe faces, mirrored views: forward.frag): every light of
// the frame (spot, point, directional), each with its shadow map. Binds the light-view shadow maps
// (one layer per light view, shared/FrameData.h) at unit 4.
#ifndef GIS_LIGHTING_GLSL
#define GIS_LIGHTING_GLSL
#include "render/brdf.glsl"

layout(binding = 4) uniform sampler2DArrayShadow gShadowMap;

// The specular lobe a program evaluates. llvmpipe runs both sides of every branch, even one on a
// uniform that is the same for all fragments (a uniform-false branch around the upsample's edge
// weights cost as much as running them), so a pass drawn over every pixel is built per case instead
// of testing gFrame.shadingInfo: the direct pass has a program with no specular lobe, one with GGX
// and one with Phong (FrameRenderer's mDirectPasses). Programs drawn rarely (reflections) keep the
// per-frame test.
#define GIS_SPECULAR_PER_FRAME -1 // both lobes compiled, chosen by gFrame.shadingInfo
#define GIS_SPECULAR_OFF -2       // diffuse only
#ifndef GIS_SPECULAR
#define GIS_SPECULAR GIS_SPECULAR_PER_FRAME
#endif

// The view of light i that sees direction `fromLight`: its only view, or for a point light the cube
// face of the direction's major axis (+X, -X, +Y, -Y, +Z, -Z).
int shadowViewOf(int i, vec3 fromLight) {
    int first = int(gLights.lights[i].info.z + 0.5);
    if (lightType(i) != GIS_LIGHT_POINT) return first;
    vec3 a = abs(fromLight);
    if (a.x >= a.y && a.x >= a.z) return first + (fromLight.x >= 0.0 ? 0 : 1);
    if (a.y >= a.z) return first + (fromLight.y >= 0.0 ? 2 : 3);
    return first + (fromLight.z >= 0.0 ? 4 : 5);
}

// Weight and position (texel units) of tap k of 0..r along one axis of pcfFiltered: the pair of
// texels i0 - r + 2k and the one after, weighted (1 - f, 1) for the first pair, (1, f) for the last
// and (1, 1) between, as one bilinear tap placed at the pair's weighted centre.
vec2 pcfPairTap(int k, int r, float i0, float f) {
    float first = k == 0 ? 1.0 - f : 1.0;
    float second = k == r ? f : 1.0;
    float weight = r == 0 ? 1.0 : first + second; // >= 1: each pair holds a texel of weight 1
    return vec2(weight, i0 - float(r) + 2.0 * float(k) + 0.5 + second / weight);
}

// Mean of the (2r + 1)^2 hardware 2x2-PCF taps at whole-texel offsets around uv in layer `layer`,
// in (r + 1)^2 taps. The taps weigh the (2r + 2)^2 texels under them separably, with per-axis
// weights (1 - f, 1, ..., 1, f) where f is uv's fraction past the texel centre below; neighbouring
// pairs of texels are one bilinear tap each, so the filter is the same (up to the filtering's
// rounding) in 4 taps instead of 9 at r = 1. Clamping to the edge maps each texel alike in both.
// r = 0 is the loop's single tap at uv itself (weight 1, the pair being the texel and the next one
// weighted 1 - f and f), not a branch of its own: llvmpipe would take that tap for every r.
float pcfFiltered(vec3 uvz, float layer, int r, float side) {
    r = max(r, 0);
    vec2 t = uvz.xy * side - 0.5;
    vec2 i0 = floor(t);
    vec2 f = t - i0;
    float sum = 0.0;
    for (int y = 0; y <= r; ++y) {
        vec2 ty = pcfPairTap(y, r, i0.y, f.y);
        for (int x = 0; x <= r; ++x) {
            vec2 tx = pcfPairTap(x, r, i0.x, f.x);
            sum += tx.x * ty.x * texture(gShadowMap, vec4(vec2(tx.y, ty.y) / side, layer, uvz.z));
        }
    }
    float taps = float(2 * r + 1);
    return min(sum / (taps * taps), 1.0); // the weights' float sum may round a whole tap to 1 + 1 ulp
}

// Fraction of light i reaching p (PCF over (2r + 1)^2 texel offsets, pcfFiltered). `l` is the unit
// direction to the light.
float shadowVisibility(int i, vec3 worldPos, vec3 n, vec3 l) {
    int v = shadowViewOf(i, -l);
    LightView view = gLights.views[v];
    bool ortho = view.info.x > 0.5;
    // Normal offset of about one shadow texel at this distance hides acne on lit surfaces: the texel's
    // world size is 2 t d / N for a perspective view, 2 w / N for an orthographic one (w its half-width).
    float texelWorld = ortho ? 2.0 * view.info.y / gFrame.rsmInfo.z
                             : 2.0 * view.info.y * length(view.eye.xyz - worldPos) / gFrame.rsmInfo.z;
    float cosTheta = clamp(dot(n, l), 0.0, 1.0);
    vec3 p = worldPos + n * texelWorld * (1.0 + 1.5 * (1.0 - cosTheta));
    vec4 clip = view.viewProj * vec4(p, 1.0);
    if (clip.w <= 1e-6) return 0.0;
    vec3 ndc = clip.xyz / clip.w;
    vec3 uvz = ndc * 0.5 + 0.5;
    // A cube face's neighbour starts at its edge: rounding there must not read as shadow.
    if (lightType(i) == GIS_LIGHT_POINT) uvz.xy = clamp(uvz.xy, vec2(0.0), vec2(1.0));
    if (any(lessThan(uvz.xy, vec2(0.0))) || any(greaterThan(uvz.xy, vec2(1.0)))) return 0.0;
    // Past the far plane of an orthographic view (nothing there casts a shadow): lit.
    uvz.z = min(uvz.z, 1.0);
    return pcfFiltered(uvz, float(v), int(gFrame.rsmInfo.w), max(gFrame.rsmInfo.z, 1.0));
}

// Reflected radiance of every light towards `toViewer` (unit) at a surface point: diffuse rho_d / pi
// plus the specular lobe when `withSpecular` (and the program has one, GIS_SPECULAR), shadowed. A
// light at p itself adds 0 (S.4 case 1).
vec3 lightsReflected(vec3 p, vec3 n, vec3 albedo, vec4 spec, vec3 toViewer, bool withSpecular) {
    if (!(gFrame.toneInfo.z > 0.5)) return vec3(0.0);
    vec3 sum = vec3(0.0);
    for (int i = 0; i < lightCount(); ++i) {
        vec3 l, irradiance;
        float dist;
        if (!lightIncidence(i, p, l, dist, irradiance)) continue;
        float cosTheta = max(dot(n, l), 0.0);
        vec3 e = irradiance * cosTheta;
        if (!(max(e.r, max(e.g, e.b)) > 0.0)) continue;
        vec3 f = albedo * kInvPi;
#if GIS_SPECULAR == GIS_SPECULAR_PER_FRAME
        if (withSpecular) f += brdfSpecular(spec.rgb, spec.a, int(gFrame.shadingInfo.x), n, l, toViewer);
#elif GIS_SPECULAR != GIS_SPECULAR_OFF
        if (withSpecular) f += brdfSpecular(spec.rgb, spec.a, GIS_SPECULAR, n, l, toViewer);
#endif
        sum += f * e * shadowVisibility(i, p, n, l);
    }
    return sum;
}

#endif
