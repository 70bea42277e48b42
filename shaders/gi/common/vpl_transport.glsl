// VPL transport kernels shared by every VPL technique (digest S.3 P6). Both return the irradiance
// (W/m^2 in the renderer's units) a diffuse VPL of reflected flux Phi gives a receiver; the caller
// multiplies by the receiver's BRDF. Guards (digest S.4): a VPL coincident with the receiver
// (d^2 below 1e-20 m^2) has no defined direction and contributes 0 (case 1), except under K2, whose
// limit is bounded (case 8); back-facing pairs contribute exactly 0 (case 2, the max(.,0) 001 Eq. 1
// leaves implicit).
//
// K1, point kernel with a distance clamp (000 Eq. 2):  E = Phi/pi * cos_l cos_r / max(d^2, dmin^2).
// The clamp bounds the r -> 0 singularity (000 Fig. 13 names it, gives no value): dmin in metres.
//
// K2, disk-to-point form factor (001 Eq. 1, Wallace et al.): the VPL is a disk of area A (001 Eq. 3)
// with radiosity Phi/A, so  E = Phi cos_l cos_r / (pi d^2 + A). Bounded by Phi/A as d -> 0, so it
// needs no clamp; A = 0 degrades to the unclamped point kernel, still finite by the d^2 guard. A
// coincident pair gets that bound, Phi/A <n_r, -n_l>+ (the limit along the disk's axis), not 0.
//
// K3, bounded geometry term (002 G_b; digest S.1): with clamp_b = b > 0 both kernels above become
// E = Phi/pi * min(G, b), G = cos_l cos_r / d^2 unclamped (no dmin, no disk area), so the energy the
// clamp removes is exactly Phi/pi * max(G - b, 0), the residual that bias compensation restores.
// uVplInvClampB carries 1/b (m^2); an unset uniform reads 0, which leaves K1/K2 bit-identical (the
// clamp's term in the denominator is exactly 0), so programs that never set it keep their default
// images. min(G, b) is written c / max(d^2, c / b), c = cos_l cos_r: one division, no branch, finite
// because d^2 > 1e-20 wherever it is used.
#define GIS_KERNEL_POINT 0
#define GIS_KERNEL_DISK 1

uniform float uVplInvClampB; // 1/b (m^2); 0: no clamp

// Distance and clamped cosines of a receiver-VPL pair; false when they coincide (no direction).
bool vplPair(vec3 receiverPos, vec3 receiverNormal, vec3 vplPos, vec3 vplNormal, out float d2, out float cosR,
             out float cosL) {
    vec3 toVpl = vplPos - receiverPos;
    d2 = dot(toVpl, toVpl);
    bool apart = d2 > 1e-20;
    vec3 w = toVpl * inversesqrt(apart ? d2 : 1.0);
    cosR = apart ? max(dot(receiverNormal, w), 0.0) : 0.0;
    cosL = apart ? max(dot(vplNormal, -w), 0.0) : 0.0;
    return apart;
}

// Both kernels divide once per pair, with the clamps folded into the denominator: K3's
// min(G, b) = c / max(d^2, c / b) for c = cos_r cos_l (as d^2 max(1, G / b) = max(d^2, c / b)), and
// with the clamp off (1/b = 0) the denominators are K1's max(d^2, dmin^2) and K2's pi d^2 + A
// exactly. Written without branches: llvmpipe runs both sides of one for every pair, and the old
// form's second and third divisions (the clamp factor, the coincident disk's limit) cost 11-15% of
// the gathers (docs/multires.md).
vec3 vplIrradiance(vec3 receiverPos, vec3 receiverNormal, vec3 vplPos, vec3 vplNormal, vec3 vplFlux,
                   float minDistance) {
    float d2, cosR, cosL;
    bool apart = vplPair(receiverPos, receiverNormal, vplPos, vplNormal, d2, cosR, cosL);
    float dmin2 = uVplInvClampB > 0.0 ? 0.0 : minDistance * minDistance;
    float c = cosR * cosL;
    float denominator = max(max(d2, dmin2), c * uVplInvClampB);
    // A coincident pair (d^2 below 1e-20 m^2) has no direction and contributes 0 (S.4 case 1).
    return apart ? vplFlux * (kInvPi * cosR * cosL / denominator) : vec3(0.0);
}

vec3 vplIrradianceDisk(vec3 receiverPos, vec3 receiverNormal, vec3 vplPos, vec3 vplNormal, vec3 vplFlux,
                       float area) {
    float d2, cosR, cosL;
    float a = uVplInvClampB > 0.0 ? 0.0 : max(area, 0.0);
    bool apart = vplPair(receiverPos, receiverNormal, vplPos, vplNormal, d2, cosR, cosL);
    // Coincident pair: K2's bounded limit along the disk's axis, Phi/A cos_r with cos_l = 1 and
    // cos_r = <n_r, -n_l> (the on-axis value B of digest S.4 case 8 for facing normals, 0 for a
    // receiver on the disk's own side), the same formula at d^2 = 0. No disk (A = 0, or K3) keeps
    // the fallback 0.
    float c = apart ? cosR * cosL : max(-dot(receiverNormal, vplNormal), 0.0);
    float d2Used = apart ? d2 : 0.0;
    float denominator = kPi * max(d2Used, c * uVplInvClampB) + a;
    bool coincident = d2 <= 1e-20; // neither for a NaN distance
    return (apart || (coincident && a > 0.0)) ? vplFlux * (c / denominator) : vec3(0.0);
}

// The kernel the program was built for: GIS_VPL_KERNEL is defined per program variant (a uniform
// branch inside the per-VPL loop measured 25% slower on llvmpipe).
#ifndef GIS_VPL_KERNEL
#define GIS_VPL_KERNEL GIS_KERNEL_POINT
#endif
vec3 vplIrradianceSelected(vec3 receiverPos, vec3 receiverNormal, Vpl v, float minDistance) {
#if GIS_VPL_KERNEL == GIS_KERNEL_DISK
    return vplIrradianceDisk(receiverPos, receiverNormal, v.position.xyz, v.normal.xyz, v.flux.rgb, v.normal.w) *
           v.position.w;
#else
    return vplIrradiance(receiverPos, receiverNormal, v.position.xyz, v.normal.xyz, v.flux.rgb, minDistance) *
           v.position.w;
#endif
}
