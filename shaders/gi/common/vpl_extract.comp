#version 450 core
// VPLs on a regular grid over one light view's RSM layer (000 §3 step 3): one VPL per grid cell,
// placed at the cell's centre texel (or the valid texel nearest to it) and carrying the summed flux
// of every valid texel in the cell, so the VPL set conserves the RSM's total flux exactly (digest S.4
// case 7). The VPL's disk area (001 Eq. 3, the texels' A_perp summed, m^2; rsm.frag) feeds the disk
// kernel. One dispatch per view writes that view's cells from uOffset on.
#include "common.glsl"

layout(local_size_x = 64) in;

layout(binding = 0) uniform sampler2DArray gRsmPosition;
layout(binding = 1) uniform sampler2DArray gRsmNormal;
layout(binding = 2) uniform sampler2DArray gRsmFlux;
layout(binding = 3) uniform sampler2DArray gRsmSpecular; // rgb F0, a roughness (0 when unbound)

layout(std430, binding = 0) writeonly buffer VplOut {
    Vpl gVplsOut[];
};
layout(std430, binding = 1) writeonly buffer VplGlossyOut {
    VplGlossy gVplGlossyOut[];
};

uniform int uGrid;     // VPLs per side
uniform int uRsmSize;  // texels per side
uniform int uView;     // the light view (RSM layer)
uniform int uOffset;   // index of this view's first VPL

void main() {
    int index = int(gl_GlobalInvocationID.x);
    if (index >= uGrid * uGrid) return;
    int light = lightOfView(uView);
    ivec2 cell = ivec2(index % uGrid, index / uGrid);
    ivec2 lo = (cell * uRsmSize) / uGrid;
    ivec2 hi = ((cell + 1) * uRsmSize) / uGrid; // exclusive; cells tile the RSM exactly
    ivec2 centre = (lo + hi) / 2;

    vec3 flux = vec3(0.0);
    vec3 incident = vec3(0.0); // rsm.frag's flux before the albedo (colour x I x spot x solid angle), specular texels
    vec4 specSum = vec4(0.0);
    float specWeight = 0.0;
    float texels = 0.0;
    float area = 0.0;
    ivec2 best = ivec2(-1);
    int bestDist = 1 << 30;
    for (int y = lo.y; y < hi.y; ++y)
        for (int x = lo.x; x < hi.x; ++x) {
            ivec3 t = ivec3(x, y, uView);
            vec4 p = texelFetch(gRsmPosition, t, 0);
            // Empty texel (no surface), or one that is not finite: a NaN in the summed flux or the
            // VPL position would turn every receiver's whole sum into NaN (digest S.4 case 5).
            if (p.w < 0.5 || any(isnan(p.xyz)) || any(isinf(p.xyz))) continue;
            vec4 f = texelFetch(gRsmFlux, t, 0);
            flux += max(sanitize(f.rgb), vec3(0.0));
            texels += 1.0;
            float areaPerp = isBad(f.a) ? 0.0 : max(f.a, 0.0);
            area += areaPerp;
            // The glossy lobe sums only texels that have one (a cell mixing copper and a diffuse floor
            // must not send the floor's light through the copper's lobe): F0 and roughness are the
            // means over those texels weighted by their incident flux.
            vec4 spec = texelFetch(gRsmSpecular, t, 0);
            if (clamp(50.0 * 0.33 * (spec.r + spec.g + spec.b), 0.0, 1.0) > 0.0) {
                vec3 l, irradiance;
                float dist;
                vec3 phi = lightIncidence(light, p.xyz, l, dist, irradiance)
                               ? max(sanitize(irradiance * areaPerp), vec3(0.0))
                               : vec3(0.0);
                float w = phi.r + phi.g + phi.b;
                incident += phi;
                specSum += vec4(spec.rgb, spec.a) * w;
                specWeight += w;
            }
            ivec2 d = t.xy - centre;
            int dist = d.x * d.x + d.y * d.y;
            if (dist < bestDist) {
                bestDist = dist;
                best = t.xy;
            }
        }

    VplGlossy g;
    g.specular = vec4(0.0);
    g.incident = vec4(0.0);
    Vpl v;
    if (best.x < 0) {
        v.position = vec4(0.0);
        v.normal = vec4(0.0, 1.0, 0.0, 0.0);
        v.flux = vec4(0.0);
    } else {
        v.position = vec4(texelFetch(gRsmPosition, ivec3(best, uView), 0).xyz, 1.0);
        vec3 n = texelFetch(gRsmNormal, ivec3(best, uView), 0).xyz;
        if (any(isnan(n)) || any(isinf(n))) n = directionToLight(light, v.position.xyz); // faces the light
        v.normal = vec4(n, area);
        v.flux = vec4(flux, texels);
        bool specular = specWeight > 0.0;
        g.specular = specular ? specSum / specWeight : vec4(0.0);
        g.incident = vec4(incident, specular ? 1.0 + float(light) : 0.0);
    }
    gVplsOut[uOffset + index] = v;
    gVplGlossyOut[uOffset + index] = g;
}
