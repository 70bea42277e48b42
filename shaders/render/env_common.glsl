// Shared by the environment-probe passes (render/EnvProbe.cpp): cube-map texel directions, the
// Hammersley point set and lobe sampling for the prefilter and the environment-BRDF table.
#ifndef GIS_ENV_COMMON_GLSL
#define GIS_ENV_COMMON_GLSL
#include "render/brdf.glsl"

// Direction through texel (x, y) of cube face `face` (GL order +X, -X, +Y, -Y, +Z, -Z) of a face
// `size` texels wide: the inverse of the GL spec's major-axis table (OpenGL 4.5 §8.13). Unit length.
vec3 envCubeDirection(ivec2 texel, int face, int size) {
    vec2 st = (vec2(texel) + 0.5) / float(max(size, 1)) * 2.0 - 1.0; // (sc, tc) / |ma| in [-1, 1]
    float sc = st.x, tc = st.y;
    vec3 d;
    if (face == 0) d = vec3(1.0, -tc, -sc);
    else if (face == 1) d = vec3(-1.0, -tc, sc);
    else if (face == 2) d = vec3(sc, 1.0, tc);
    else if (face == 3) d = vec3(sc, -1.0, -tc);
    else if (face == 4) d = vec3(sc, -tc, 1.0);
    else d = vec3(-sc, -tc, -1.0);
    return normalize(d); // |d| >= 1: never degenerate
}

// Hammersley point i of n in [0, 1)^2 (radical inverse in base 2).
vec2 envHammersley(uint i, uint n) {
    return vec2((float(i) + 0.5) / float(max(n, 1u)), float(bitfieldReverse(i)) * 2.3283064365386963e-10);
}

// An orthonormal frame around unit n: returns t, b with (t, b, n) right-handed.
void envFrame(vec3 n, out vec3 t, out vec3 b) {
    vec3 up = abs(n.z) < 0.999 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
    t = normalize(cross(up, n)); // |up x n| >= sqrt(1 - 0.999^2) > 0.04
    b = cross(n, t);
}

// GGX half vector around +z (tangent space) for point u; its pdf over half vectors is D(h) (n.h).
vec3 envSampleGgx(vec2 u, float alpha) {
    float a2 = alpha * alpha;
    float phi = 2.0 * kPi * u.y;
    float cos2 = clamp((1.0 - u.x) / max(1.0 + (a2 - 1.0) * u.x, 1e-12), 0.0, 1.0);
    float c = sqrt(cos2), s = sqrt(max(1.0 - cos2, 0.0));
    return vec3(s * cos(phi), s * sin(phi), c);
}

// Direction around +z distributed as cos^e (the Phong lobe about the mirror direction); pdf over
// directions (e + 1) / (2 pi) cos^e.
vec3 envSamplePhong(vec2 u, float e) {
    float phi = 2.0 * kPi * u.y;
    float c = pow(max(1.0 - u.x, 0.0), 1.0 / (e + 1.0)); // u.x < 1: (1 - u.x) > 0
    float s = sqrt(max(1.0 - c * c, 0.0));
    return vec3(s * cos(phi), s * sin(phi), c);
}

#endif
