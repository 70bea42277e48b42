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

private:
    struct Draw {
        GLint firstIndex = 0;
        GLsizei indexCount = 0;
        GLint baseVertex = 0;
        int material = 0;
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
