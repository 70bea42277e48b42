// VPL transport kernels shared by every VPL technique (digest S.3 P6).
//
// Point kernel with a distance clamp (K1): the irradiance a diffuse VPL of reflected flux Phi
// gives a receiver at distance d is  E = Phi/pi * cos(theta_l) * cos(theta_r) / max(d^2, dmin^2).
// The clamp bounds the r -> 0 singularity (000 Fig. 13 names it, gives no value): dmin in metres.
// A VPL coincident with the receiver (d^2 below 1e-20 m^2) has no defined direction and
// contributes 0 (digest S.4 case 1). Back-facing pairs contribute exactly 0 (case 2).
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
