#version 450 core
// One SSBC step (002 §4.2): C(y) = albedo_y / pi * sum_i G_r(y, z_i) L(z_i) A_i over the mip chain of
// the step's input L, hierarchically refined (BiasCompensation.h lists the choices). The coarse
// texels under the screen disc of radius r_s are iterated outside the stack (digest 002.6 item 8),
// so the stack only holds one depth-first descent: 1 + 3 (levels - 1) entries.
// Writes C to the next step's level 0 and adds it to the target (the technique's indirect radiance,
// or the compensation accumulator when ssbc_blur is on).
// Half resolution (ssbc_half_resolution, 002 §5): uReceiverLevel 1 makes each level-1 texel (a 2x2
// block's area-weighted mean position and normal) one receiver; it writes (1/pi) sum without the
// albedo to uHalfOut, and ssbc_upsample.comp brings it to full resolution with each pixel's albedo.
#include "common.glsl"
#include "gi/common/ssbc_common.glsl"

layout(local_size_x = GIS_SSBC_GROUP, local_size_y = GIS_SSBC_GROUP) in;

layout(binding = 0) uniform sampler2D uGeo;    // mips: xyz mean position, w summed area
layout(binding = 1) uniform sampler2D uNormal; // mips: xyz mean normal, w discontinuity
layout(binding = 2) uniform sampler2D uIllum;  // mips: rgb mean radiance of the step's input
layout(binding = 3) uniform sampler2D gAlbedo;

layout(rgba32f, binding = 0) uniform image2D uIndirect;          // += C
layout(rgba32f, binding = 1) uniform writeonly image2D uNextIllum; // level 0 of the next step's input
layout(rgba32f, binding = 2) uniform writeonly image2D uHalfOut;   // half resolution: (1/pi) sum, a = covered

uniform float uB;             // clamp bound b (1/m^2), > 0
uniform float uR;             // 1/sqrt(b) (m)
uniform float uTanHalfFov;
uniform int uLevels;          // mip levels (>= 1)
uniform float uSolidAngle;    // refine above this (sr); <= 0 refines everything
uniform float uDiscAngle;     // refine discontinuous samples above this (sr)
uniform int uMaxVisited;      // per-pixel cap on samples visited (bounded frame time)
uniform int uSlot;            // counter slot of this step
uniform int uReceiverLevel;   // 0: every pixel is a receiver; 1: every 2x2 block (half resolution)

const int kStack = 64; // >= 1 + 3 * 11 (12 levels at most)

uint packNode(int level, ivec2 t) { return uint(level) | (uint(t.x) << 4) | (uint(t.y) << 18); }

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    int rl = uReceiverLevel;
    // Image extent at the receiver level: ceil(W / 2^rl) x ceil(H / 2^rl).
    ivec2 size = (ivec2(gFrame.viewport.xy) + (1 << rl) - 1) >> rl;
    vec4 stats = vec4(0.0);
    vec3 comp = vec3(0.0);
    vec4 self = all(lessThan(p, size)) ? texelFetch(uGeo, p, rl) : vec4(0.0);
    if (self.w > 0.0) {
        vec3 y = self.xyz;
        vec3 ny = texelFetch(uNormal, p, rl).xyz;
        float dist = length(gFrame.cameraPos.xyz - y);
        // r_s in pixels, clamped to the image (camera-near surfaces, digest 002.6 item 7).
        float rs = uR / max(uTanHalfFov * dist, 1e-6) * 0.5 * gFrame.viewport.y;
        rs = min(rs, gFrame.viewport.x + gFrame.viewport.y);
        int coarse = uLevels - 1;
        float scale = float(1 << coarse);
        ivec2 cs = textureSize(uGeo, coarse);
        vec2 pc = (vec2(p) + 0.5) * float(1 << rl); // receiver centre in full-resolution pixels
        ivec2 lo = max(ivec2(floor((pc - rs) / scale)), ivec2(0));
        ivec2 hi = min(ivec2(floor((pc + rs) / scale)), cs - 1);
        uint stack[kStack];
        int visited = 0;
        vec3 sum = vec3(0.0);
        for (int ty = lo.y; ty <= hi.y && visited < uMaxVisited; ++ty)
            for (int tx = lo.x; tx <= hi.x && visited < uMaxVisited; ++tx) {
                // Skip coarse texels whose pixel rectangle misses the disc.
                vec2 rmin = vec2(tx, ty) * scale, rmax = rmin + scale;
                vec2 q = clamp(pc, rmin, rmax) - pc;
                if (dot(q, q) > rs * rs) continue;
                stack[0] = packNode(coarse, ivec2(tx, ty));
                int sp = 1;
                while (sp > 0 && visited < uMaxVisited) {
                    uint s = stack[--sp];
                    int level = int(s & 15u);
                    ivec2 t = ivec2(int((s >> 4) & 0x3FFFu), int(s >> 18));
                    ++visited;
                    vec4 g = texelFetch(uGeo, t, level);
                    float area = g.w;
                    if (!(area > 0.0)) continue;
                    // Nodes at or above the receiver's level that contain it. A half-resolution
                    // receiver's own four pixels (level 0) are ordinary samples: they are distinct
                    // surfaces points at d > 0 from the block mean (d = 0 is skipped below).
                    bool containsSelf = level >= rl && all(equal((p << rl) >> level, t));
                    if (level == 0 && containsSelf) continue; // the pixel itself (d = 0)
                    vec3 v = g.xyz - y;
                    float d2 = dot(v, v);
                    // Every point of the sample is farther than r: G <= 1/d^2 < b, nothing to add.
                    // sqrt(area) bounds no coarse sample's extent (grazing, or across a depth edge),
                    // so with thresholds 0 (refine everything) only level 0, where it is exact, prunes.
                    bool prune = level == 0 || uSolidAngle > 0.0;
                    if (!containsSelf && prune && sqrt(d2) - sqrt(area) >= uR) continue;
                    vec4 nz = texelFetch(uNormal, t, level);
                    vec3 w = d2 > 1e-20 ? v * inversesqrt(d2) : vec3(0.0);
                    float cosZ = max(-dot(nz.xyz, w), 0.0);
                    float omega = area * cosZ / max(d2, 1e-20);
                    // G_r = max(G - b, 0) is not linear: a coarse sample evaluated at its mean drops
                    // the part of it that lies inside r while the mean lies outside (and vice versa).
                    // Refine a sample wider than r/4 whose nearest point may reach G > b, so the
                    // result does not depend on the start level (only on the two thresholds).
                    float ext = sqrt(area);
                    float dNear = max(sqrt(d2) - ext, 0.0);
                    float cosYc = max(dot(ny, w), 0.0);
                    bool straddles = ext > 0.25 * uR && cosYc * max(cosZ, 0.1) > uB * dNear * dNear;
                    // A threshold of 0 refines every sample (the flat sum, digest S.4 case 12): a coarse
                    // sample whose mean normal faces away (omega = 0) may hold children that face y.
                    bool refine = level > 0 && (containsSelf || uSolidAngle <= 0.0 || omega > uSolidAngle ||
                                                (nz.w > 0.5 && omega > uDiscAngle) || straddles);
                    if (refine && sp + 4 <= kStack) {
                        for (int k = 3; k >= 0; --k) stack[sp++] = packNode(level - 1, 2 * t + ivec2(k & 1, k >> 1));
                        continue;
                    }
                    if (!(d2 > 1e-20)) continue;
                    float cosY = max(dot(ny, w), 0.0);
                    // Disk form: bounded by pi / A for a sample next to y (digest 002.6 item 5).
                    float gs = cosY * cosZ / (d2 + area * kInvPi);
                    float gr = max(gs - uB, 0.0);
                    if (gr > 0.0) sum += gr * area * texelFetch(uIllum, t, level).rgb;
                }
            }
        if (rl == 0) {
            vec3 albedo = texelFetch(gAlbedo, p, 0).rgb;
            comp = max(sanitize(albedo * kInvPi * sum), vec3(0.0));
            vec4 current = imageLoad(uIndirect, p);
            imageStore(uIndirect, p, vec4(max(sanitize(current.rgb), vec3(0.0)) + comp, current.a));
        } else {
            // The albedo varies inside a block: the upsampling applies each pixel's own.
            comp = max(sanitize(kInvPi * sum), vec3(0.0));
        }
        stats = vec4((comp.r + comp.g + comp.b) / 3.0, float(visited), float(visited), 1.0);
    }
    if (rl == 0) {
        if (all(lessThan(p, imageSize(uNextIllum)))) imageStore(uNextIllum, p, vec4(comp, self.w > 0.0 ? 1.0 : 0.0));
    } else if (all(lessThan(p, imageSize(uHalfOut)))) {
        imageStore(uHalfOut, p, vec4(comp, self.w > 0.0 ? 1.0 : 0.0));
    }
    ssbcGroupSum(stats, uSlot);
}
