// The scene's geometry, materials and textures on the GPU, and the draw loop every raster pass
// (shadow map, RSM, G-buffer) shares.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "gl/Objects.h"
#include "gl/Shader.h"
#include "scene/Scene.h"
#include "scene/TextureMips.h"

namespace gis {

/// The material uniforms of a scene-drawing program (shaders/render/material.glsl), resolved once
/// where the program is built, so the draw loop looks nothing up.
struct MaterialSlots {
    gl::UniformLocation baseColor, emissive, hasTexture, metalRoughSpec, mirrorId;
    gl::UniformLocation alphaCutoff; ///< only in programs built with GIS_ALPHA_CUTOUT
    gl::UniformLocation hasMetalRoughTexture, hasEmissiveTexture, hasNormalTexture, normalScale,
        hasVertexColor, hasOcclusionTexture, occlusionStrength;
    gl::TextureUnit baseColorTexture{gl::kNoUnit}, metalRoughTexture{gl::kNoUnit},
        emissiveTexture{gl::kNoUnit}, normalTexture{gl::kNoUnit}, occlusionTexture{gl::kNoUnit};
    /// `program`'s slots. With `complete`, every one must be active (the G-buffer's program, which
    /// reads them all: a misspelt name in material.glsl fails there); otherwise the ones a program
    /// leaves unused are skipped.
    static MaterialSlots of(const gl::Program& program, bool complete = false);
};

/// Triangles one draw loop sent and left out (frustum culling's measure, per pass in the stats), and
/// the GL draw calls it took for its runs.
struct DrawCount {
    std::size_t drawn = 0, culled = 0;
    std::size_t runs = 0, calls = 0; ///< runs drawn; glMultiDrawElementsIndirect calls they took
    std::size_t simplified = 0;      ///< of `drawn`, triangles of coarser levels of detail (LodView)
    DrawCount& operator+=(const DrawCount& o) {
        drawn += o.drawn;
        culled += o.culled;
        simplified += o.simplified;
        runs += o.runs;
        calls += o.calls;
        return *this;
    }
};

/// What a view tolerates of the meshes' levels of detail (scene/MeshLod.h): each placement of a mesh is
/// drawn at its coarsest level whose error, seen from `eye` at the placement's nearest point, stays
/// within `errorAtEye` plus `errorPerMetre` per metre of that distance. For a camera (or a perspective
/// light view), a tolerance of p pixels is p * 2 tan(fov / 2) / image height per metre
/// (lodErrorPerMetre()); an orthographic view's pixel has one size at any distance, p * its width /
/// its pixels, which is `errorAtEye`.
struct LodView {
    glm::vec3 eye{0.0f};
    float errorPerMetre = 0.0f; ///< world units per unit of distance
    float errorAtEye = 0.0f;    ///< world units, whatever the distance
    /// Both 0: every mesh at full detail.
    bool tolerates() const { return errorPerMetre > 0.0f || errorAtEye > 0.0f; }
};
/// The world distance per metre from the eye that `pixels` of an image `imageHeight` px tall under a
/// vertical field of view `yfovRadians` span; 0 for no tolerance or a degenerate view.
float lodErrorPerMetre(float pixels, float yfovRadians, int imageHeight);

class SceneGpu {
public:
    /// Triangles per draw: a bigger mesh is drawn in runs of consecutive triangles, each with its own
    /// bounds, so culling can leave out part of it.
    static constexpr std::size_t kChunkTriangles = 16384;

    /// What the upload sends, built without GL on any thread: the interleaved vertices, the indices,
    /// the placements, the runs with their bounds and every texture's mipmap chain. A scene load
    /// builds it beside the scene, so the render thread only uploads, in slices (docs/scenes.md,
    /// "Loading": eight 2048^2 textures 108-122 ms in 8 slices of at most 14-19 ms, against one hold
    /// of 291-306 ms; `node bench/scenes/load_progress.mjs --textures 8`). `cancelled` (may be
    /// empty) is asked between meshes and between textures; when it answers true, prepare returns null.
    struct Prepared;
    static std::shared_ptr<const Prepared> prepare(const Scene& scene,
                                                   const std::function<bool()>& cancelled = {});

    /// The coarser levels of detail of the scene's meshes of at least LodOptions::minTriangles
    /// (scene/MeshLod.h), their runs and bounds, built without GL on any thread. Kept apart from the
    /// scene's upload because they cost several times its load (0.25-0.35 s for the atrium's 560k
    /// triangles): a session shows the scene first and adds them when they are ready. `cancelled`
    /// is asked between meshes (null when it answers true).
    struct LodSet;
    static std::shared_ptr<const LodSet> prepareLevels(const Scene& scene,
                                                       const std::function<bool()>& cancelled = {});
    /// Uploads `levels` (from prepareLevels of this scene) into an index buffer of their own; draw()
    /// uses them from then on. Throws gis::Error on GL failure.
    void setLevels(std::shared_ptr<const LodSet> levels);
    bool hasLevels() const { return mLod != nullptr; }

    /// Uploads everything; throws gis::Error on GL failure (a load boundary). `prepared` must come
    /// from prepare(scene) of this scene; null: prepared here.
    explicit SceneGpu(const Scene& scene, std::shared_ptr<const Prepared> prepared = nullptr);
    /// Staged: plans the upload as pieces (each buffer's or texture's storage, then ranges and row
    /// bands of at most kUploadChunkBytes, the vertex array last) and sends them through
    /// uploadSome(), so that a big scene's upload can be spread between frames instead of holding
    /// the render thread. Draw only once complete(). `scene` must outlive
    /// the upload; `prepared` as above.
    struct Staged {};
    SceneGpu(const Scene& scene, std::shared_ptr<const Prepared> prepared, Staged);
    // The staged pieces refer to this object: it stays where it was made.
    SceneGpu(const SceneGpu&) = delete;
    SceneGpu& operator=(const SceneGpu&) = delete;
    /// Sends pieces while they are predicted to fit `budgetMs` (at least one piece; each kind's
    /// cost per byte measured as it goes); true when everything is sent.
    /// Throws gis::Error on GL failure once the last piece is sent.
    bool uploadSome(double budgetMs);
    bool complete() const { return mNextPiece >= mPieces.size(); }
    static constexpr std::size_t kUploadChunkBytes = std::size_t{4} << 20;
    /// Draws every mesh with `program` bound (`instances` times each); sets the material uniforms
    /// through `materials` (null: none, as for depth-only passes). `skipMesh` (an index into
    /// Scene::meshes) is left out: a local environment probe does not see the object it belongs to.
    /// With `cullViewProj` (world -> clip, the matrix the program's vertex stage applies), runs whose
    /// bounds lie wholly outside one of its clip planes are skipped: GL would clip every triangle of
    /// them, so the image is the same.
    /// With `cullBackFaces` (the views that show surfaces: the G-buffer, environment-probe faces and
    /// mirrored views), single-sided materials (Material::doubleSided false) are drawn with back faces
    /// culled (front faces as the pass's glFrontFace says: CCW, as glTF, unless mirrored).
    /// Consecutive runs that need the same state (material uniforms and textures, face culling) go
    /// out as one glMultiDrawElementsIndirect, in scene order, so images do not change.
    /// With `lod` and levels (setLevels), a mesh with coarser levels draws each placement at the
    /// coarsest level the view tolerates; without them, or with a zero tolerance, every mesh is
    /// drawn whole.
    DrawCount draw(const gl::Program& program, const MaterialSlots* materials, int instances = 1,
                   int skipMesh = -1, const glm::mat4* cullViewProj = nullptr, bool cullBackFaces = false,
                   const LodView* lod = nullptr) const;
    /// Triangles drawn (an instanced mesh's once per placement) and stored.
    std::size_t triangleCount() const { return mTriangles; }
    std::size_t storedTriangleCount() const { return mStoredTriangles; }
    /// Triangles stored in the coarser levels of detail besides the meshes' own (0 without levels).
    std::size_t lodTriangleCount() const;
    /// Placements of instanced meshes (Mesh::instances).
    std::size_t instanceCount() const { return mInstances; }
    std::size_t drawCount() const { return mDraws.size(); }

    /// Vertex attributes of the placement matrices (shaders/render/instance.glsl): the object ->
    /// world matrix's four columns and the normal matrix's three.
    static constexpr GLuint kToWorldAttribute = 5, kNormalToWorldAttribute = 9;
    /// The reflector id of each mesh, written by the G-buffer into the normal's w
    /// (shaders/render/gbuffer.frag): k + 1 for planar mirror k, -(k + 1) for the object of local
    /// environment probe k, 0 for none (render/Reflections).
    void setSurfaceIds(const std::vector<int>& idOfMesh);

private:
    struct Vertex {
        float position[3];
        float normal[3];
        float texcoord[2];
        float tangent[4]; ///< Mesh::tangents; zero where the mesh has none (no normal map)
        float color[4];   ///< Mesh::colors; white where the mesh has none
    };
    static_assert(sizeof(Vertex) == 64);
    struct Draw {
        GLint firstIndex = 0;
        GLsizei indexCount = 0;
        GLint baseVertex = 0;
        int material = 0;
        int mesh = 0;         ///< index into Scene::meshes
        int surfaceId = 0;    ///< reflector id (setSurfaceIds)
        bool colored = false; ///< the mesh has COLOR_0 (uHasVertexColor)
        /// Placements [instance, instance + placements) of mPlacements (placement 0: the identity),
        /// each with its world box at mRunBounds[firstBounds + k].
        GLuint instance = 0, placements = 1;
        std::size_t firstBounds = 0;
    };
    struct RunBounds {
        glm::vec3 lo, hi; ///< world space, of one placement of a run's triangles
    };
    /// Scene::meshes[i]'s own runs: mDraws[firstDraw, firstDraw + drawCount).
    struct MeshRuns {
        std::size_t firstDraw = 0, drawCount = 0;
    };
    /// One coarser level of detail of a mesh: its runs LodSet::draws[firstDraw, + drawCount).
    struct Level {
        std::size_t firstDraw = 0, drawCount = 0;
        float error = 0.0f; ///< in the mesh's own units (LodLevel::error)
    };
    /// A placement of a mesh as the level choice sees it: its world box and how much its matrix
    /// enlarges (the largest column length: an error in the mesh's units times this is metres).
    struct PlacementExtent {
        glm::vec3 lo, hi;
        float scale = 1.0f;
    };
    /// Scene::meshes[i]'s coarser levels, LodSet::levels[firstLevel, + levelCount) finest first, and
    /// its placements' extents LodSet::extents[firstExtent, + placements).
    struct MeshLevels {
        std::size_t firstLevel = 0, levelCount = 0;
        std::size_t firstExtent = 0, placements = 1;
    };
    /// The draw every run of `mesh` copies: its vertices from `baseVertex`, its placements (when
    /// instanced) from `nextPlacement`.
    static Draw meshDraw(const Scene& scene, const Mesh& mesh, GLint baseVertex, GLuint nextPlacement);
    /// Appends the runs of `levelIndices` (a triangle list of `mesh`, stored from `firstIndex` on)
    /// to `draws` and their per-placement bounds to `bounds`, each run a copy of `proto`. Returns
    /// how many runs.
    static std::size_t appendRuns(const Mesh& mesh, const Draw& proto,
                                  const std::vector<std::uint32_t>& levelIndices, std::size_t firstIndex,
                                  std::vector<Draw>& draws, std::vector<RunBounds>& bounds);
    /// Draw commands, kCommandSlots regions of one command per run, used in turn by successive
    /// draw() calls (a region is rewritten only after the calls of the other regions were issued).
    static constexpr std::size_t kCommandSlots = 16;
    static constexpr std::size_t kCommandBytes = std::size_t{32} << 20; ///< the ring's cap, bytes
    struct IndirectCommand {
        GLuint count, instanceCount, firstIndex;
        GLint baseVertex;
        GLuint baseInstance;
    };
    static_assert(sizeof(IndirectCommand) == 20, "glMultiDrawElementsIndirect's command layout");
    /// One placement's matrices as the vertex stage reads them (columns; normalToWorld's w unused).
    struct InstanceTransform {
        glm::mat4 toWorld{1.0f};
        glm::vec4 normalToWorld[3]{};
        static InstanceTransform of(const glm::mat4& toWorld);
    };
    static_assert(sizeof(InstanceTransform) == 112, "instance.glsl's attribute layout");

public:
    struct Prepared {
        std::vector<Vertex> vertices;
        std::vector<std::uint32_t> indices;
        std::vector<InstanceTransform> placements; ///< [0]: the identity of world-space meshes
        std::vector<Draw> draws;
        std::vector<RunBounds> runBounds;
        std::vector<MeshRuns> meshes; ///< one per Scene::meshes entry
        std::size_t maxCommands = 0, triangles = 0, storedTriangles = 0;
        std::vector<std::vector<MipLevel>> textureMips; ///< levels 1.. of each Scene::textures entry
    };
    struct LodSet {
        std::vector<std::uint32_t> indices; ///< every level's, in an index buffer of their own
        std::vector<Draw> draws;            ///< firstIndex into `indices`
        std::vector<RunBounds> runBounds;
        std::vector<Level> levels;
        std::vector<PlacementExtent> extents;
        std::vector<MeshLevels> meshes; ///< one per Scene::meshes entry
        std::size_t triangles = 0;      ///< stored in all levels
    };

private:
    /// Larger than any instance count a pass draws, so a command's instances all read its placement.
    static constexpr GLuint kPlacementDivisor = 1u << 30;
    mutable GLuint mDivisor = 1; ///< the placement binding's divisor as last set (draw())
    gl::Buffer mVertices;
    gl::Buffer mIndices;
    gl::Buffer mPlacements;
    mutable gl::Buffer mCommands;
    mutable std::size_t mCommandSlot = 0;
    mutable std::size_t mCommandCapacity = 0; ///< commands per region
    mutable std::size_t mCommandSlots = kCommandSlots;
    std::size_t mMaxCommands = 0; ///< the most one draw() can send: every placement of every run
    /// Regions of `commands` each (the buffer is replaced; GL keeps the old one while in use).
    void reserveCommands(std::size_t commands) const;
    /// Consecutive commands of one state (draw()'s batches): one multi-draw each.
    struct Batch {
        std::size_t first = 0, count = 0;
        const Draw* head = nullptr; ///< the first run: its material, ids and face culling
        bool oneSided = false;
        bool coarse = false; ///< its runs index mLodIndices, not mIndices
    };
    mutable std::vector<IndirectCommand> mCommandScratch; ///< reused by draw(): no per-call allocation
    mutable std::vector<Batch> mBatchScratch;
    gl::VertexArray mVao;
    std::vector<Draw> mDraws;
    std::vector<RunBounds> mRunBounds;
    std::vector<MeshRuns> mMeshes;
    std::shared_ptr<const LodSet> mLod; ///< null until setLevels
    std::vector<Draw> mLodDraws;        ///< mLod's runs, with the surface ids (setSurfaceIds)
    std::vector<int> mSurfaceIdOfMesh;  ///< as last set, for levels set later
    gl::Buffer mLodIndices;
    mutable std::vector<std::uint8_t> mLevelScratch; ///< draw(): each placement's chosen level
    std::vector<Material> mMaterials;
    std::vector<gl::Texture> mTextures;
    /// The staged upload: each piece sends one buffer range or one band of rows of one texture level,
    /// from the prepared data and the scene's images (kept until the last piece).
    struct Piece {
        std::function<void()> send;
        std::size_t bytes = 0;
        bool creates = false; ///< makes a storage (llvmpipe clears it) rather than filling one
    };
    std::vector<Piece> mPieces;
    /// Cost of a piece, ms per MiB, of creating and of filling storage: uploadSome stops before a
    /// piece predicted to overrun its budget. The first values are guesses; each piece of 1 MiB or
    /// more replaces half of its kind's value by what it measured.
    double mCreateMsPerMiB = 0.6, mFillMsPerMiB = 0.3;
    void setUpVertexArray(); ///< the last piece: attributes over the filled buffers
    std::size_t mNextPiece = 0;
    std::shared_ptr<const Prepared> mUploading;
    std::string mSceneName;
    gl::Texture mFallbackTexture; ///< one white texel, nearest: on the units of maps a material lacks
    std::size_t mTriangles = 0, mStoredTriangles = 0, mInstances = 0;
};

} // namespace gis
