// K4 (003 §3.3, digest S.3): the irradiance on the BACK side of a receiver at x with normal n from a
// diffuse point light v, with K1's distance clamp minDistance (m): K1 with cos taken against -n. It
// is what place_negative.comp measures to place negative lights, and what the stability suite's
// kernel probe evaluates directly (tests/stability/KernelProbeTest.cpp). toLight returns the unit
// direction to the light (0 for a coincident pair).
#ifndef GIS_SECOND_ORDER_K4_GLSL
#define GIS_SECOND_ORDER_K4_GLSL

vec3 backIrradiance(vec3 x, vec3 n, Vpl v, float minDistance, out vec3 toLight) {
    toLight = vec3(0.0);
    vec3 d = v.position.xyz - x;
    float d2 = dot(d, d);
    if (!(d2 > 1e-20)) return vec3(0.0); // coincident: no defined direction (digest S.4 case 1)
    toLight = d * inversesqrt(d2);
    // Light in (or numerically at) p's tangent plane does not cross the surface: a light on the
    // same plane reads cos ~ 1e-7 from rounded positions, and would take a slot for nothing. The
    // positions are fp32 world coordinates: far from the origin (digest S.4 case 17, 1e4 m: a 1 mm
    // ulp) a light on p's own wall sits a few ulps off its plane, so the light must also be farther
    // from the plane than 8 ulps of the larger coordinate (a micrometre near the origin).
    vec3 m = max(abs(x), abs(v.position.xyz));
    float planeTolerance = 8.0 * 1.1920929e-7 * max(m.x, max(m.y, m.z));
    float cosBack = -dot(n, toLight);
    if (!(cosBack > max(1e-3, planeTolerance * inversesqrt(d2)))) return vec3(0.0);
    float cosLight = max(dot(v.normal.xyz, -toLight), 0.0);
    return v.flux.rgb * (kInvPi * cosBack * cosLight / max(d2, minDistance * minDistance));
}

#endif
