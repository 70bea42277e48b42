// Level 0 of the eye hierarchy is the G-buffer itself (not copied into the atlas): the per-pixel
// statistics the coarser levels reduce, computed on demand.
layout(binding = 8) uniform sampler2D gPosition; // RGBA32F world position, w = 1 covered
layout(binding = 9) uniform sampler2D gNormal;   // RGBA16F unit normal
layout(binding = 10) uniform sampler2D gAlbedo;  // RGBA8 linear albedo

// A pixel with a non-finite position or normal counts as background: the G-buffer pass never writes
// one, but a single NaN entering the mean and min-max mips would poison every coarser level and,
// through coarse receivers, whole screen regions (digest S.4 case 5).
// Outside the image: not covered (the fetch is clamped rather than skipped: no branch).
bool eyePixelCovered(ivec2 p) {
    bool inside = all(greaterThanEqual(p, ivec2(0))) && all(lessThan(p, gEye.info.yz));
    ivec2 q = clamp(p, ivec2(0), gEye.info.yz - 1);
    vec4 pos = texelFetch(gPosition, q, 0);
    vec3 n = texelFetch(gNormal, q, 0).xyz;
    return inside && pos.w > 0.5 && !any(isnan(pos.xyz)) && !any(isinf(pos.xyz)) && !any(isnan(n)) &&
           !any(isinf(n));
}
float eyePixelDistance(ivec2 p) { return length(texelFetch(gPosition, p, 0).xyz - gFrame.cameraPos.xyz); }

// Relative depth derivative and curvature of covered pixel p. Only the program variant of a metric
// that needs them calls this (GIS_EYE_PIXEL_METRICS): llvmpipe runs a branch on a uniform it cannot
// prove uniform for every fragment, and these 16 extra fetches per pixel were most of the level-1
// reduction's time. Derivative: the larger one-sided difference to a covered neighbour along each
// axis, so a step between two surfaces registers in full (a central difference would halve it);
// relative to d so thresholds do not depend on the scene's scale. Curvature: 2 sin(angle / 2)
// between unit normals equals the chord |n1 - n2| (000 Eq. 1 without the acos); max over the 4
// neighbours.
vec2 eyePixelDerivativeCurvature(ivec2 p, float d, vec3 n) {
    vec2 grad = vec2(0.0);
    float curvature = 0.0;
    const ivec2 kOffsets[4] = ivec2[4](ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1));
    for (int i = 0; i < 4; ++i) {
        ivec2 q = p + kOffsets[i];
        bool covered = eyePixelCovered(q);
        float dq = covered ? abs(eyePixelDistance(q) - d) : 0.0;
        if (i < 2) grad.x = max(grad.x, dq); else grad.y = max(grad.y, dq);
        float chord = covered ? length(texelFetch(gNormal, q, 0).xyz - n) : 0.0;
        curvature = max(curvature, chord);
    }
    return vec2(length(grad) / max(d, 1e-6), curvature);
}
