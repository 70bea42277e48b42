// Planar mirrors (004 §5.1, Diefenbach): the mirror's pixels are marked in the stencil buffer (from
// the G-buffer's mirror index), the scene is re-rendered with the camera reflected about the
// mirror's plane (clipped to the mirror's front side) into those pixels only, and the result, times
// the mirror's Fresnel reflectance, is added to the frame. mirror_depth > 1 repeats this inside the
// mirrored view for mirrors seen in mirrors. mirror_blur=on blurs the reflection by the material's
// roughness and the reflected distance (004 §5.1.1).
// Parameters (frame table): mirror_depth (0-3), mirror_roughness (classification), mirror_blur.
// Limits: reflected views show direct light and emission only; at most kMaxMirrors mirrors.
#pragma once

#include "core/Param.h"
#include "gi/Technique.h"
#include "gl/Objects.h"
#include "gl/PassTimer.h"
#include "render/Reflections.h"

namespace gis {

class PlanarMirrors {
public:
    PlanarMirrors(); ///< compiles its programs: may throw gis::Error
    ~PlanarMirrors();
    /// ADDS each visible mirror's reflection into `target` (RGBA32F colour attachment 0,
    /// in.width x in.height; the caller cleared it).
    void execute(const ReflectionInputs& in, const ParamSet& frameParams, const gl::Framebuffer& target,
                 gl::PassTimer& timer, Counters& counters);

private:
    struct Impl;
    std::unique_ptr<Impl> mImpl;
};

} // namespace gis
