// VPL visibility from per-VPL cube shadow maps (an option of the VPL transport, so bias compensation
// can be compared with indirect visibility on and off; 002 uses imperfect shadow maps). Layer
// 6 * vpl + face of a depth array holds distance / uVplShadowFar as seen from the VPL.
// Face of direction p: the major axis and its sign (0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z); uv = the
// two other coordinates in fixed order over the major one. vpl_shadow.vert renders with the same map.
int vplCubeFace(vec3 p, out vec2 uv) {
    vec3 a = abs(p);
    if (a.x >= a.y && a.x >= a.z) {
        uv = p.yz / max(a.x, 1e-30);
        return p.x > 0.0 ? 0 : 1;
    }
    if (a.y >= a.z) {
        uv = p.xz / max(a.y, 1e-30);
        return p.y > 0.0 ? 2 : 3;
    }
    uv = p.xy / max(a.z, 1e-30);
    return p.z > 0.0 ? 4 : 5;
}

#ifdef GIS_VPL_SHADOW_LOOKUP
layout(binding = 7) uniform sampler2DArray uVplShadowMaps;
uniform int uVplShadows;        // 1: test visibility
uniform int uVplShadowed;       // VPLs with a shadow map (the first ones; the rest are unshadowed)
uniform float uVplShadowFar;    // m: the scene's diagonal
uniform float uVplShadowBias;   // fraction of the distance

// 1 when the receiver is visible from VPL `index` (or shadows are off), else 0. The receiver is
// moved off its surface by a bias proportional to its distance, against self-shadowing.
float vplVisibility(int index, vec3 vplPos, vec3 receiverPos, vec3 receiverNormal) {
    if (uVplShadows == 0 || index >= uVplShadowed) return 1.0;
    vec3 p = receiverPos - vplPos;
    float dist = length(p);
    if (!(dist > 1e-6)) return 1.0;
    p += receiverNormal * (uVplShadowBias * dist);
    vec2 uv;
    int face = vplCubeFace(p, uv);
    float stored = texture(uVplShadowMaps, vec3(uv * 0.5 + 0.5, float(index * 6 + face))).r * uVplShadowFar;
    return length(p) * (1.0 - uVplShadowBias) <= stored ? 1.0 : 0.0;
}
#endif
