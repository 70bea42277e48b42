// Eye-space hierarchy access shared by every multiresolution pass (layout: shared/EyeHierarchy.h).
// common.glsl (included once per program) provides gFrame for pixel footprints and isBad.
#include "common.glsl"
#include "shared/EyeHierarchy.h"

layout(std140, binding = GIS_UBO_EYE) uniform EyeBlock {
    EyeHierarchyUniforms gEye;
};

int eyeLevelCount() { return gEye.info.x; }
ivec2 eyeLevelSize(int level) { return gEye.level[level].zw; }
ivec2 eyeAtlas(int level, ivec2 t) { return gEye.level[level].xy + t; }
bool eyeInLevel(int level, ivec2 t) { return all(greaterThanEqual(t, ivec2(0))) && all(lessThan(t, gEye.level[level].zw)); }

// The level holding atlas texel `a` (and the texel within it), or -1 for padding.
int eyeLevelOf(ivec2 a, out ivec2 t) {
    for (int l = 0; l < gEye.info.x; ++l) {
        t = a - gEye.level[l].xy;
        if (eyeInLevel(l, t)) return l;
    }
    t = ivec2(-1);
    return -1;
}

// Full-resolution pixels under texel t of `level` (fewer on the last row/column of odd sizes).
float eyeFootprintPixels(int level, ivec2 t) {
    int s = 1 << level;
    ivec2 lo = t * s;
    ivec2 hi = min(lo + s, gEye.info.yz);
    ivec2 n = max(hi - lo, ivec2(0));
    return float(n.x * n.y);
}

// 000 §3 step 5's ContainsDepth/NormalDiscontinuity for a patch of `level` >= 1 from its statistics:
// partly background (an object edge), or depth or normal statistics beyond the thresholds.
bool eyePatchDiscontinuous(int level, ivec2 t, float covered, vec4 depthInfo, vec3 normalMin, vec3 normalMax) {
    if (level == 0 || covered <= 0.0) return false;           // one pixel, or empty: nothing to refine
    if (covered < eyeFootprintPixels(level, t)) return true;  // object / background edge
    int options = gEye.info.w;
    bool depthDisc = (options & GIS_EYE_DEPTH_DERIVATIVE) != 0
                         ? depthInfo.z > gEye.thresholds.y
                         : (depthInfo.y - depthInfo.x) > gEye.thresholds.x * max(depthInfo.x, 1e-6);
    bool normalDisc = (options & GIS_EYE_CURVATURE) != 0
                          ? depthInfo.w > gEye.thresholds.w
                          : any(greaterThan(normalMax - normalMin, vec3(gEye.thresholds.z)));
    return depthDisc || normalDisc;
}

// The receiver predicate (digest S.3 R2 == R3). A patch receives light when it has geometry, needs
// no subdivision, and every ancestor was subdivided. 001's pseudo-code tests only the parent's
// refine flag, which equals the iterative refinement only when the refine test is monotone (a
// child never refines without its parent); the diagonal rule breaks that, so the whole ancestor
// chain counts: the flags pass marks a patch GIS_EYE_FLAG_SUBDIVIDED when it and every ancestor
// refine, and the test reads that mark on the parent. Boundary cases (001 leaves them open): the
// coarsest level has no ancestor, and the finest level never refines, so its covered pixels
// receive whenever all ancestors refined. Level 0 lives in the G-buffer: `pixelCovered` is its
// coverage at t when level == 0. Written without early returns (llvmpipe runs both sides of a
// divergent branch anyway): the fetches a level does not need are clamped to valid texels.
bool eyeIsReceiver(usampler2D flags, int level, ivec2 t, bool pixelCovered) {
    uint own = texelFetch(flags, eyeAtlas(max(level, 1), level == 0 ? ivec2(0) : t), 0).r;
    bool receives = level == 0 ? pixelCovered
                               : (own & GIS_EYE_FLAG_COVERED) != 0u && (own & GIS_EYE_FLAG_REFINE) == 0u;
    bool coarsest = level + 1 >= gEye.info.x;
    uint parent = texelFetch(flags, eyeAtlas(min(level + 1, gEye.info.x - 1), coarsest ? ivec2(0) : t >> 1), 0).r;
    return receives && (coarsest || (parent & GIS_EYE_FLAG_SUBDIVIDED) != 0u);
}

// Receiver geometry the reconstruction compares (digest S.4 case 10): the texel's mean position
// (w > 0: it has geometry) and unit normal. The coarse levels' come from the atlas geometry
// (EyeHierarchy binds it at units 11 and 12 for the reconstruction), level 0's from the G-buffer.
struct EyeGeometry {
    vec4 position;
    vec3 normal;
};

// World size (m) of one pixel at p, perpendicular to the view: 2 w / (H f), with the clip w and the
// focal length f = 1 / tan(fov_y / 2) = |row 1 of viewProj| (the view's rotation rows are unit).
float eyePixelFootprint(vec3 p) {
    mat4 m = gFrame.viewProj;
    float focal = length(vec3(m[0][1], m[1][1], m[2][1]));
    float w = m[0][3] * p.x + m[1][3] * p.y + m[2][3] * p.z + m[3][3];
    return 2.0 * abs(w) / max(focal * gFrame.viewport.y, 1e-30);
}

// How far a coarse neighbour's surface agrees with the fine texel's (1 same surface, 0 another):
// its plane distance (either tangent plane) against the coarse texel's footprint F (m, from
// eyePixelFootprint scaled to the coarse level), 1 up to F/4 and 0 from F/2 (a continuous surface's
// neighbours lie in its tangent plane up to its curvature), times the normals' agreement, 1 up to
// 26 degrees and 0 from 60 degrees apart. `fourOverFootprint` is 4 / F (1/m), computed once per texel
// for its four neighbours. A NaN weight (from a NaN position) fails the comparison and reads 0.
float eyeGeometricWeight(EyeGeometry fine, vec3 coarsePos, vec3 coarseNormal, float fourOverFootprint) {
    vec3 v = coarsePos - fine.position.xyz;
    float plane = max(abs(dot(fine.normal, v)), abs(dot(coarseNormal, v)));
    float wd = clamp(2.0 - plane * fourOverFootprint, 0.0, 1.0);
    float wn = clamp((dot(fine.normal, coarseNormal) - 0.5) * 2.5, 0.0, 1.0);
    float w = wd * wn;
    return w > 0.0 ? w : 0.0;
}

// Coarse-to-fine reconstruction step (000 §3.5, digest S.3 U1) for texel t of level `coarse - 1`:
// when the texel lies under a coarser receiver (its parent holds data), interpolate the finished
// coarse level bilinearly using only the coarse texels that hold data (alpha > 0), weights
// renormalised, so energy is never pulled from empty or refined areas nor spread into them.
// Otherwise the texel stays empty (alpha 0). 000 leaves the weights open: bilinear (tent) weights
// of the 2x upsample, times a geometric similarity weight (eyeGeometricWeight) when the texel has
// geometry: a coarse receiver on another surface (across a depth or normal edge that no patch
// straddles, so nothing was refined) lends it no light. When every weight vanishes the parent, the
// nearest sample, is replicated. On a continuous surface every geometric weight is exactly 1 and the
// result is the plain bilinear one.
// `interpolate` false replicates the parent instead (per-VPL lists, see eyeCombine).
// Written without branches (each neighbour fetched, clamped into the level, and weighted in or
// out): llvmpipe shades 4x4 fragment blocks together and would run every branch anyway.
vec4 eyeInterpolateCoarse(sampler2D reconstructed, sampler2D atlasPosition, sampler2D atlasNormal, int coarse,
                          ivec2 t, bool interpolate, EyeGeometry fine) {
    if (coarse >= gEye.info.x) return vec4(0.0); // the same for every fragment of a draw
    ivec2 size = eyeLevelSize(coarse);
    vec2 c = (vec2(t) + 0.5) * 0.5 - 0.5; // centre of t in the coarse level's texel coordinates
    ivec2 base = ivec2(floor(c));
    vec2 f = c - vec2(base);
    // The parent t >> 1 is one of the four: base + 1 on an axis where t is even, base where odd.
    ivec2 parentCorner = ivec2(1) - (t & 1);
    // 4 / the coarse texel's footprint (1/m); a zero footprint (a point at the eye) leaves 4e30.
    float fourOverFootprint = 4.0 / max(float(1 << coarse) * eyePixelFootprint(fine.position.xyz), 1e-30);
    bool hasGeometry = fine.position.w > 0.0;
    vec4 parent = vec4(0.0);
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            ivec2 q = base + ivec2(i, j);
            ivec2 a = eyeAtlas(coarse, clamp(q, ivec2(0), size - 1));
            vec4 v = texelFetch(reconstructed, a, 0);
            parent = ivec2(i, j) == parentCorner ? v : parent;
            float g = eyeGeometricWeight(fine, texelFetch(atlasPosition, a, 0).xyz, texelFetch(atlasNormal, a, 0).xyz,
                                         fourOverFootprint);
            float w = (i == 0 ? 1.0 - f.x : f.x) * (j == 0 ? 1.0 - f.y : f.y) * (hasGeometry ? g : 1.0);
            bool used = eyeInLevel(coarse, q) && v.a > 0.0 && w > 0.0;
            sum += used ? w * v.rgb : vec3(0.0);
            weight += used ? w : 0.0;
        }
    // Every neighbour on another surface: the parent (it holds data, and covers the texel).
    vec4 interpolated = weight > 1e-6 ? vec4(sum / weight, 1.0) : vec4(parent.rgb, 1.0);
    return parent.a > 0.0 ? (interpolate ? interpolated : parent) : vec4(0.0);
}

// One texel of the reconstruction: what was splatted or gathered on its own level plus the
// interpolated coarser levels (000 §3.5 sums rendered + input). With one receiver list per frame
// the two never overlap (a receiver's ancestors hold no data), so a receiver keeps its value
// exactly and thresholds of 0 reproduce the full-resolution result; per-VPL lists put partial sums
// on several levels, and the sum adds them all. Neighbouring texels of a per-VPL buffer hold sums
// over different VPL subsets, so interpolating between them would move one subset's light into
// another's patch (measured: 3.9% relative RMSE where refining everything should be exact); those
// buffers replicate the parent instead (`interpolate` false), leaving the patch constant as 000
// describes subsplats.
vec4 eyeCombine(vec4 rendered, sampler2D reconstructed, sampler2D atlasPosition, sampler2D atlasNormal, int level,
                ivec2 t, bool interpolate, EyeGeometry fine) {
    vec4 coarse = eyeInterpolateCoarse(reconstructed, atlasPosition, atlasNormal, level + 1, t, interpolate, fine);
    vec3 own = rendered.a > 0.0 ? rendered.rgb : vec3(0.0);
    return (rendered.a > 0.0 || coarse.a > 0.0) ? vec4(own + coarse.rgb, 1.0) : vec4(0.0);
}
