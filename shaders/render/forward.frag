#version 450 core
// Forward shading for views other than the eye camera: emission plus the shadowed lights (diffuse
// and specular lobes of render/brdf.glsl) as seen from uEye. No indirect light: a reflection shows
// the directly lit scene (docs/nondiffuse.md, limits). Output is linear radiance, sanitised.
#include "common.glsl"
#include "render/material.glsl"
#include "render/lighting.glsl"

in vec3 vWorldPos;
in vec3 vNormal;
in vec2 vTexcoord;
in vec4 vTangent;

uniform vec3 uEye; // the viewpoint (m): probe centre or mirrored camera

layout(location = 0) out vec4 outRadiance; // rgb linear radiance, a = 1 covered
layout(location = 1) out vec4 outPosition; // xyz world position (m), w = 1 covered
layout(location = 2) out vec4 outMirror;   // x planar-mirror index + 1 (0 none); only mirrored views attach it

void main() {
    CUT_OUT(vTexcoord);
    vec3 toEye = uEye - vWorldPos;
    float e2 = dot(toEye, toEye);
    vec3 v = e2 > 1e-20 ? toEye * inversesqrt(e2) : vec3(0.0, 1.0, 0.0);
    vec3 n = safeNormal(vNormal, vWorldPos, v);
    n = materialNormal(n, vNormal, vTangent, vTexcoord);
    vec4 spec = materialSpecular(vTexcoord);
    vec3 radiance = max(sanitize(materialEmissive(vTexcoord)), vec3(0.0)) +
                    lightsReflected(vWorldPos, n, materialAlbedo(vTexcoord), spec, v, gFrame.shadingInfo.z > 0.5);
    outRadiance = vec4(max(sanitize(radiance), vec3(0.0)), 1.0);
    outPosition = vec4(vWorldPos, 1.0);
    outMirror = vec4(float(uMirrorId), 0.0, 0.0, 1.0);
}
