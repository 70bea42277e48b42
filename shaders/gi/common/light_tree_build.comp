#version 450 core
// One level of the light-space VPL tree per dispatch (001 §3.5 "VPL tree"; layout in
// shared/LightTree.h). Level 0 copies the RSM texel by texel; level l >= 1 reduces the (up to) four
// children on level l - 1, so every statistic is exact over the node's texels at every level:
//   flux, area, texel count:  sums (flux is conserved level by level; digest S.4 case 4)
//   position, normal:         means weighted by flux luminance, over valid children only; a plain
//                             (texel-count weighted) mean where the node reflects no light
//   light distance, normal:   min and max (Eq. 8's max depth; isr's discontinuity test)
// Empty texels (position.w < 0.5) contribute nothing and never define a position.
// Several light views: level 0 is a mosaic of the views' RSM layers, uTiles per row, each uViewSide
// texels square (view v at tile (v % uTiles, v / uTiles)); tiles past the last view are empty. One
// tree thus spans every light's texels, and its upper levels cluster texels across views.
// The level-1 dispatch also writes level 0 (its children, from the RSM): one pass fewer over the
// largest level (llvmpipe, R = 256: 3.3 ms against 4.7 ms for separate passes; 16 x 16 tiles
// reducing four levels in shared memory took 17 ms, their barriers being costly there).
#include "common.glsl"
#define GIS_LIGHT_NODES_QUALIFIER
#include "gi/common/light_tree.glsl"

layout(local_size_x = 64) in;

layout(binding = 0) uniform sampler2DArray uRsmPosition;
layout(binding = 1) uniform sampler2DArray uRsmNormal;
layout(binding = 2) uniform sampler2DArray uRsmFlux;

uniform int uLevel;    // >= 1; level 1 also writes level 0, straight from the RSM
uniform int uTiles;    // views per mosaic row
uniform int uViewSide; // RSM texels per view side
uniform int uFirstNode; // this dispatch's first node of the level (a level may go in chunks)

LightNode emptyNode() {
    LightNode n;
    n.position = vec4(0.0);
    n.normal = vec4(0.0);
    n.flux = vec4(0.0);
    n.lo = vec4(0.0);
    n.hi = vec4(0.0);
    return n;
}

bool finite3(vec3 v) { return !(isBad(v.x) || isBad(v.y) || isBad(v.z)); }

LightNode fromTexel(ivec2 q) {
    ivec2 tile = q / max(uViewSide, 1);
    int view = tile.y * uTiles + tile.x;
    if (view >= lightViewCount()) return emptyNode();
    ivec3 t = ivec3(q - tile * uViewSide, view);
    vec4 p = texelFetch(uRsmPosition, t, 0);
    if (!(p.w >= 0.5) || !finite3(p.xyz)) return emptyNode();
    float d = lightViewDistance(view, p.xyz);
    // The RSM writes unit normals (fp16-quantised); level 0 keeps them as stored so a full
    // traversal reproduces the per-texel gather exactly. A broken one falls back to facing the light.
    vec3 n = texelFetch(uRsmNormal, t, 0).xyz;
    if (!finite3(n) || !(dot(n, n) > 1e-12)) n = directionToLight(lightOfView(view), p.xyz);
    LightNode node;
    node.position = vec4(p.xyz, 1.0);
    vec4 f = texelFetch(uRsmFlux, t, 0);
    node.normal = vec4(n, isBad(f.a) ? 0.0 : max(f.a, 0.0));
    node.flux = vec4(max(sanitize(f.rgb), vec3(0.0)), 1.0);
    node.lo = vec4(n, d);
    node.hi = vec4(n, d);
    return node;
}

// Reduces up to four children (empty ones included: they are skipped).
LightNode combine(LightNode c[4]) {
    vec3 flux = vec3(0.0), posW = vec3(0.0), normalW = vec3(0.0), posC = vec3(0.0), normalC = vec3(0.0);
    float weight = 0.0, texels = 0.0, area = 0.0, bestWeight = -1.0;
    vec3 fallbackNormal = vec3(0.0, 1.0, 0.0);
    vec4 lo = vec4(1e30), hi = vec4(-1e30);
    for (int i = 0; i < 4; ++i) {
        LightNode k = c[i];
        if (k.position.w < 0.5) continue;
        float w = lightLuminance(k.flux.rgb);
        flux += k.flux.rgb;
        texels += k.flux.w;
        area += k.normal.w;
        weight += w;
        posW += w * k.position.xyz;
        normalW += w * k.normal.xyz;
        posC += k.flux.w * k.position.xyz;
        normalC += k.flux.w * k.normal.xyz;
        lo = min(lo, k.lo);
        hi = max(hi, k.hi);
        if (w > bestWeight) { // the brightest child's normal stands in when the mean cancels out
            bestWeight = w;
            fallbackNormal = k.normal.xyz;
        }
    }
    if (!(texels > 0.0)) return emptyNode();
    bool weighted = weight > 0.0;
    // texels >= 1 here, so the plain mean's divisor is never zero.
    vec3 pos = weighted ? posW / weight : posC / texels;
    vec3 nSum = weighted ? normalW : normalC;
    float len = length(nSum);
    // Relative to the weights' sum (the mean normal's length): flux scales with the scene (I x s^2 in
    // digest S.4 case 14), and an absolute floor sent dim millimetre-scale nodes to the fallback.
    vec3 n = len > 1e-6 * (weighted ? weight : texels) ? nSum / len : fallbackNormal;
    if (!finite3(pos)) pos = posC / texels;
    if (!finite3(n)) n = fallbackNormal;
    LightNode node;
    node.position = vec4(pos, 1.0);
    node.normal = vec4(n, area);
    node.flux = vec4(sanitize(flux), texels);
    node.lo = lo;
    node.hi = hi;
    return node;
}

void main() {
    int side = lightLevelSide(uLevel);
    int index = uFirstNode + int(gl_GlobalInvocationID.x);
    if (index >= side * side) return;
    ivec2 t = ivec2(index % side, index / side);
    int childSide = lightLevelSide(uLevel - 1);
    LightNode c[4];
    for (int k = 0; k < 4; ++k) {
        ivec2 q = t * 2 + ivec2(k & 1, k >> 1);
        // Children past the last row or column (odd sizes) do not exist: empty.
        if (q.x >= childSide || q.y >= childSide) {
            c[k] = emptyNode();
        } else if (uLevel == 1) {
            c[k] = fromTexel(q);
            gLightNodes[lightNodeIndex(0, q)] = c[k];
        } else {
            c[k] = gLightNodes[lightNodeIndex(uLevel - 1, q)];
        }
    }
    gLightNodes[lightNodeIndex(uLevel, t)] = combine(c);
}
