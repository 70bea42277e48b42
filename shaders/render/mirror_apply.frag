#version 450 core
// Planar mirrors, step 3: adds Fresnel(F0, cos) x the reflected radiance of one mirrored view into its
// parent (the reflections target for level 1, the parent view's radiance deeper), additively blended,
// at the view's pixels only. cos is taken between the mirror's normal and the direction from the
// mirror point to the parent's eye; at grazing angles Fresnel tends to F90 and nothing divides.
#include "common.glsl"
#include "render/brdf.glsl"
#include "render/mirror_region.glsl"

layout(binding = 5) uniform sampler2D gReflected; // this view's radiance (RGBA32F)
layout(binding = 6) uniform sampler2D gMirrorPos; // the mirror points (parent view): xyz world (m), w = 1

uniform vec3 uParentEye;    // the parent view's eye (m): camera, or a mirrored camera
uniform vec3 uMirrorNormal; // unit, towards the mirror's front (the parent eye's side)
uniform vec3 uF0;           // the mirror's reflectance at normal incidence

layout(location = 0) out vec4 outRadiance;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    if (!inRegion(px)) discard;
    vec4 m = texelFetch(gMirrorPos, px, 0);
    if (m.w < 0.5) discard;
    vec3 toEye = uParentEye - m.xyz;
    float e2 = dot(toEye, toEye);
    float cosTheta = e2 > 1e-20 ? dot(uMirrorNormal, toEye) * inversesqrt(e2) : 1.0;
    vec3 f = brdfFresnel(clamp(uF0, 0.0, 1.0), clamp(cosTheta, 0.0, 1.0));
    vec3 l = max(sanitize(texelFetch(gReflected, px, 0).rgb), vec3(0.0));
    outRadiance = vec4(max(sanitize(f * l), vec3(0.0)), 0.0);
}
