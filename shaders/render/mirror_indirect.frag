#version 450 core
// Planar mirrors: the reflected views are forward shaded (direct light + emission only). Where a
// reflected point is also visible in the eye view, the technique's indirect radiance at that eye pixel
// is added (blended into the level's radiance). Diffuse indirect light is view independent, so this is
// exact for it up to the reprojection; a glossy part of the technique's indirect output would be
// evaluated for the eye's direction instead of the reflected one (docs/nondiffuse.md, limits).
#include "common.glsl"

layout(binding = 5) uniform sampler2D gIndirect; // the technique's indirect radiance (eye view)
layout(binding = 6) uniform sampler2D gPosition; // eye G-buffer: xyz world (m), w = 1 covered
layout(binding = 7) uniform sampler2D gViewPos;  // this level's reflected points: xyz world (m), w = 1

// Reprojection tolerance: the eye G-buffer point must lie within this fraction of its eye distance
// (dimensionless) plus kReprojectPixels pixel footprints (px) of the reflected point.
const float kReprojectRelative = 0.01;
const float kReprojectPixels = 2.0;

layout(location = 0) out vec4 outRadiance;

void main() {
    vec4 p = texelFetch(gViewPos, ivec2(gl_FragCoord.xy), 0);
    if (p.w < 0.5) discard;
    vec4 clip = gFrame.viewProj * vec4(p.xyz, 1.0);
    if (!(clip.w > 1e-6)) discard; // behind the eye
    vec2 ndc = clip.xy / clip.w;
    if (any(greaterThan(abs(ndc), vec2(1.0)))) discard;
    ivec2 size = ivec2(gFrame.viewport.xy);
    ivec2 q = clamp(ivec2((ndc * 0.5 + 0.5) * vec2(size)), ivec2(0), size - 1);
    vec4 g = texelFetch(gPosition, q, 0);
    if (g.w < 0.5) discard;
    // One pixel's footprint (m) at the point's depth: 2 w tan(fov/2) / height, tan(fov/2) = 1/P11 =
    // 1/|row 1 of viewProj| (the view rotation's rows are unit).
    vec3 row1 = vec3(gFrame.viewProj[0][1], gFrame.viewProj[1][1], gFrame.viewProj[2][1]);
    float p11 = max(length(row1), 1e-6);
    float footprint = 2.0 * clip.w / (p11 * max(gFrame.viewport.y, 1.0));
    float eyeDist = length(p.xyz - gFrame.cameraPos.xyz);
    float tol = kReprojectRelative * eyeDist + kReprojectPixels * footprint;
    if (!(length(g.xyz - p.xyz) <= tol)) discard;
    outRadiance = vec4(max(sanitize(texelFetch(gIndirect, q, 0).rgb), vec3(0.0)), 0.0);
}
