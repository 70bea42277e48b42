// VPL transport kernels shared by every VPL technique (digest S.3 P6). Both return the irradiance
// (W/m^2 in the renderer's units) a diffuse VPL of reflected flux Phi gives a receiver; the caller
// multiplies by the receiver's BRDF. Guards (digest S.4): a VPL coincident with the receiver
// (d^2 below 1e-20 m^2) has no defined direction and contributes 0 (case 1); back-facing pairs
// contribute exactly 0 (case 2, the max(.,0) 001 Eq. 1 leaves implicit).
//
// K1, point kernel with a distance clamp (000 Eq. 2):  E = Phi/pi * cos_l cos_r / max(d^2, dmin^2).
// The clamp bounds the r -> 0 singularity (000 Fig. 13 names it, gives no value): dmin in metres.
//
// K2, disk-to-point form factor (001 Eq. 1, Wallace et al.): the VPL is a disk of area A (001 Eq. 3)
// with radiosity Phi/A, so  E = Phi cos_l cos_r / (pi d^2 + A). Bounded by Phi/A as d -> 0, so it
// needs no clamp; A = 0 degrades to the unclamped point kernel, still finite by the d^2 guard.
#define GIS_KERNEL_POINT 0
#define GIS_KERNEL_DISK 1

vec3 vplIrradiance(vec3 receiverPos, vec3 receiverNormal, vec3 vplPos, vec3 vplNormal, vec3 vplFlux,
                   float minDistance) {
    vec3 toVpl = vplPos - receiverPos;
    float d2 = dot(toVpl, toVpl);
    if (!(d2 > 1e-20)) return vec3(0.0);
    vec3 w = toVpl * inversesqrt(d2);
    float cosR = max(dot(receiverNormal, w), 0.0);
    float cosL = max(dot(vplNormal, -w), 0.0);
    return vplFlux * (kInvPi * cosR * cosL / max(d2, minDistance * minDistance));
}

vec3 vplIrradianceDisk(vec3 receiverPos, vec3 receiverNormal, vec3 vplPos, vec3 vplNormal, vec3 vplFlux,
                       float area) {
    vec3 toVpl = vplPos - receiverPos;
    float d2 = dot(toVpl, toVpl);
    if (!(d2 > 1e-20)) return vec3(0.0);
    vec3 w = toVpl * inversesqrt(d2);
    float cosR = max(dot(receiverNormal, w), 0.0);
    float cosL = max(dot(vplNormal, -w), 0.0);
    return vplFlux * (cosR * cosL / (kPi * d2 + max(area, 0.0)));
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
