// C++ view of shaders/shared/*.h: the same struct text, with GLSL's vector types mapped to GLM.
#pragma once

#include <cstddef>

#include <glm/glm.hpp>

namespace gis::shader {
using vec4 = glm::vec4;
using mat4 = glm::mat4;
using ivec4 = glm::ivec4;
using uvec4 = glm::uvec4;
#include "shaders/shared/FrameData.h"
#include "shaders/shared/EyeHierarchy.h"
#include "shaders/shared/LightTree.h"
#include "shaders/shared/Subsplat.h"

static_assert(sizeof(FrameUniforms) % 16 == 0, "std140 blocks must be whole vec4s");
static_assert(sizeof(FrameUniforms) == 64 + 5 * 16, "FrameUniforms layout drifted from the GLSL side");
static_assert(offsetof(FrameUniforms, toneInfo) == 64 + 3 * 16);
static_assert(sizeof(GpuLight) == 4 * 16, "GpuLight must be four vec4s in std140");
static_assert(sizeof(LightView) == 64 + 3 * 16, "LightView must be a mat4 and three vec4s in std140");
static_assert(sizeof(LightUniforms) ==
                  GIS_MAX_LIGHTS * sizeof(GpuLight) + GIS_MAX_LIGHT_VIEWS * sizeof(LightView) + 16,
              "LightUniforms drifted from the GLSL side");
static_assert(sizeof(LightUniforms) <= 65536, "the light block must fit the 64 KiB UBO limit");
static_assert(offsetof(LightUniforms, counts) == GIS_MAX_LIGHTS * 64 + GIS_MAX_LIGHT_VIEWS * 112);
static_assert(sizeof(Vpl) == 48, "Vpl must be three vec4s in std140 and std430");
static_assert(sizeof(VplGlossy) == 32, "VplGlossy must be two vec4s in std430");
// A VPL batch is a buffer-texture view (gi/common/vpl_batch.glsl): its texels within the 65,536 every
// implementation allows, and every batch's first byte on the strictest offset alignment (256).
static_assert(GIS_MAX_VPLS_PER_BATCH * sizeof(Vpl) / 16 <= 65536,
              "a VPL batch must fit the smallest texel buffer");
static_assert((GIS_MAX_VPLS_PER_BATCH * sizeof(Vpl)) % 256 == 0,
              "VPL batches must start on 256-byte offsets");
static_assert(sizeof(EyeHierarchyUniforms) == GIS_MAX_EYE_LEVELS * 16 + 2 * 16,
              "EyeHierarchyUniforms drifted");
static_assert(offsetof(EyeHierarchyUniforms, info) == GIS_MAX_EYE_LEVELS * 16);
static_assert(sizeof(EyeReceiverListHeader) == 32, "EyeReceiverListHeader must be two uvec4s in std430");
static_assert(offsetof(EyeReceiverListHeader, counts) == 16);
static_assert(sizeof(LightNode) == 80, "LightNode must be five vec4s in std430");
static_assert(offsetof(LightNode, flux) == offsetof(Vpl, flux), "a LightNode starts with a Vpl's layout");
static_assert(sizeof(LightTreeUniforms) == GIS_MAX_LIGHT_LEVELS * 16 + 16, "LightTreeUniforms drifted");
static_assert(offsetof(LightTreeUniforms, info) == GIS_MAX_LIGHT_LEVELS * 16);
static_assert(sizeof(SubsplatCounters) == 7 * 16, "SubsplatCounters drifted from the GLSL side");
static_assert(4 * 4 >= GIS_MAX_EYE_LEVELS, "perLevel holds one count per eye level");
} // namespace gis::shader
