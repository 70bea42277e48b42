#version 450 core
// Eye G-buffer (000 §3 step 2): world position, normal, diffuse albedo, emission, specular.
#include "common.glsl"
#include "render/material.glsl"

in vec3 vWorldPos;
in vec3 vNormal;
in vec2 vTexcoord;
in vec4 vTangent;

layout(location = 0) out vec4 outPosition; // xyz world (m), w = 1 covered
layout(location = 1) out vec4 outNormal;   // xyz unit normal facing the camera
layout(location = 2) out vec4 outAlbedo;   // rgb linear albedo, a occlusion (1: none)
layout(location = 3) out vec4 outEmissive; // rgb emitted radiance
layout(location = 4) out vec4 outSpecular; // rgb F0, a perceptual roughness (render/brdf.glsl)

void main() {
    CUT_OUT(vTexcoord);
    vec3 toEye = gFrame.cameraPos.xyz - vWorldPos;
    vec3 n = safeNormal(vNormal, vWorldPos, toEye);
    n = materialNormal(n, vNormal, vTangent, vTexcoord);
    outPosition = vec4(vWorldPos, 1.0);
    outNormal = vec4(n, float(uMirrorId)); // w: reflector id (mirror k + 1, local probe -(k + 1), 0)
    outAlbedo = vec4(materialAlbedo(vTexcoord), materialOcclusion(vTexcoord));
    outSpecular = materialSpecular(vTexcoord);
    outEmissive = vec4(max(sanitize(materialEmissive(vTexcoord)), vec3(0.0)), 1.0);
}
