// The scene's geometry, materials and textures on the GPU, and the draw loop every raster pass
// (shadow map, RSM, G-buffer) shares.
#pragma once

#include <vector>

#include "gl/Objects.h"
#include "gl/Shader.h"
#include "scene/Scene.h"

namespace gis {

class SceneGpu {
public:
    /// Uploads everything; throws gis::Error on GL failure (a load boundary).
    explicit SceneGpu(const Scene& scene);
    /// Draws every mesh with `program` bound (`instances` times each); sets the material uniforms
    /// when `withMaterials`.
    void draw(const gl::Program& program, bool withMaterials, int instances = 1) const;
    std::size_t triangleCount() const { return mTriangles; }
    /// Marks meshes as planar mirrors: `mirrorOfMesh[i]` is mesh i's mirror index, -1 for none. The
    /// G-buffer writes index + 1 into the normal's w (shaders/render/gbuffer.frag).
    void setMirrorIndices(const std::vector<int>& mirrorOfMesh);

private:
    struct Draw {
        GLint firstIndex = 0;
        GLsizei indexCount = 0;
        GLint baseVertex = 0;
        int material = 0;
        int mesh = 0;    ///< index into Scene::meshes
        int mirror = -1; ///< planar-mirror index, -1 for none
    };
    gl::Buffer mVertices;
    gl::Buffer mIndices;
    gl::VertexArray mVao;
    std::vector<Draw> mDraws;
    std::vector<Material> mMaterials;
    std::vector<gl::Texture> mTextures;
    std::size_t mTriangles = 0;
};

} // namespace gis
