// Planar mirrors (004 §5.1, Diefenbach): the mirror's pixels are marked in the stencil buffer (from
// the G-buffer's mirror index), the scene is re-rendered with the camera reflected about the
// mirror's plane (clipped to the mirror's front side) into those pixels only, and the result, times
// the mirror's Fresnel reflectance, is added to the frame. mirror_depth > 1 repeats this inside the
// mirrored view for mirrors seen in mirrors. mirror_blur=on blurs the reflection by the material's
// roughness and the reflected distance (004 §5.1.1).
// Parameters (frame table): mirror_depth (0-3), mirror_roughness (classification), mirror_blur.
//
// Views: a view at level k is a chain eye -> m1 -> ... -> mk of mirrors, rendered with the eye's
// projection and the view matrix V R_m1 ... R_mk, so its image lies in the eye's image space. Views are
// processed breadth first, one set of targets per level (radiance, world position, mirror id, depth
// + stencil, eye size); a view's pixels are those whose ids along the chain match (the eye G-buffer's
// normal.w, then each level's mirror id), marked in that level's stencil with the view's number. An
// occlusion query drops views without pixels. A view gets no child in the mirror it was made by, nor
// in a mirror whose plane its eye is behind. After the deepest level, each view (optionally blurred)
// times Fresnel is added into its parent, deepest first, the level-1 views into `target`.
// Bound: at most mirrorViewBound(mirrors, depth) = sum_k M (M-1)^(k-1) views (M <= kMaxMirrors,
// depth <= kMaxMirrorDepth: 4 + 12 + 36), capped at kMaxMirrorViews in breadth-first order.
// Timer passes: mirror_stencil, mirror_render (level 1; mirror_stencil_k, mirror_render_k deeper),
// mirror_apply (blur and apply, all levels). Counter: mirror_views.
// Limits: reflected views show direct light and emission, plus the technique's indirect light where
// the reflected point is also seen by the eye (reprojected into the eye view within a tolerance);
// Fresnel uses the mirror material's F0 (no textures); at most kMaxMirrors mirrors.
#pragma once

#include <memory>

#include "core/Param.h"
#include "gi/Technique.h"
#include "gl/Objects.h"
#include "gl/PassTimer.h"
#include "render/Reflections.h"

namespace gis {

inline constexpr int kMaxMirrorDepth = 3;  ///< the mirror_depth parameter's maximum
inline constexpr int kMaxMirrorViews = 16; ///< mirrored views per frame, all levels together

/// The reflection about the plane through `point` with normal `normal` (normalised here; a zero
/// normal becomes +y): x -> x - 2 (n . (x - point)) n. Its own inverse; determinant -1.
glm::mat4 mirrorReflection(glm::vec3 point, glm::vec3 normal);
/// The most views `mirrors` planar mirrors can need at `depth` levels, before the kMaxMirrorViews cap
/// is applied (returned capped).
int mirrorViewBound(int mirrors, int depth);

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
