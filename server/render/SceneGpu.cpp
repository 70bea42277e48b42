#include "render/SceneGpu.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include <glm/gtc/matrix_inverse.hpp>

#include "core/Error.h"
#include "scene/Frustum.h"
#include "scene/MeshLod.h"

namespace gis {

SceneGpu::InstanceTransform SceneGpu::InstanceTransform::of(const glm::mat4& toWorld) {
    InstanceTransform t;
    t.toWorld = toWorld;
    const glm::mat3 normalToWorld = glm::inverseTranspose(glm::mat3(toWorld));
    for (int c = 0; c < 3; ++c) t.normalToWorld[c] = glm::vec4(normalToWorld[c], 0.0f);
    return t;
}

std::shared_ptr<const SceneGpu::Prepared> SceneGpu::prepare(const Scene& scene,
                                                            const std::function<bool()>& cancelled) {
    auto prepared = std::make_shared<Prepared>();
    std::vector<Vertex>& vertices = prepared->vertices;
    std::vector<std::uint32_t>& indices = prepared->indices;
    // Placement 0 is the identity that every world-space mesh is drawn with.
    std::vector<InstanceTransform>& placements = prepared->placements;
    placements.push_back(InstanceTransform::of(glm::mat4(1.0f)));
    std::size_t vertexCount = 0, indexCount = 0;
    for (const Mesh& mesh : scene.meshes) {
        vertexCount += mesh.positions.size();
        indexCount += mesh.indices.size();
    }
    vertices.reserve(vertexCount);
    indices.reserve(indexCount);
    for (const Mesh& mesh : scene.meshes) {
        if (cancelled && cancelled()) return nullptr;
        const Draw d = meshDraw(scene, mesh, static_cast<GLint>(vertices.size()),
                                static_cast<GLuint>(placements.size()));
        for (const glm::mat4& toWorld : mesh.instances) placements.push_back(InstanceTransform::of(toWorld));
        const std::size_t firstDraw = prepared->draws.size();
        const std::size_t runs =
            appendRuns(mesh, d, mesh.indices, indices.size(), prepared->draws, prepared->runBounds);
        indices.insert(indices.end(), mesh.indices.begin(), mesh.indices.end());
        prepared->meshes.push_back({firstDraw, runs});
        prepared->maxCommands += runs * mesh.placements();
        for (size_t i = 0; i < mesh.positions.size(); ++i) {
            Vertex v{};
            v.position[0] = mesh.positions[i].x;
            v.position[1] = mesh.positions[i].y;
            v.position[2] = mesh.positions[i].z;
            if (i < mesh.normals.size()) {
                v.normal[0] = mesh.normals[i].x;
                v.normal[1] = mesh.normals[i].y;
                v.normal[2] = mesh.normals[i].z;
            }
            if (i < mesh.texcoords.size()) {
                v.texcoord[0] = mesh.texcoords[i].x;
                v.texcoord[1] = mesh.texcoords[i].y;
            }
            if (i < mesh.tangents.size())
                for (int c = 0; c < 4; ++c) v.tangent[c] = mesh.tangents[i][c];
            for (int c = 0; c < 4; ++c) v.color[c] = i < mesh.colors.size() ? mesh.colors[i][c] : 1.0f;
            vertices.push_back(v);
        }
        prepared->triangles += mesh.indices.size() / 3 * mesh.placements();
        prepared->storedTriangles += mesh.indices.size() / 3;
    }
    prepared->textureMips.reserve(scene.textures.size());
    for (const TextureImage& image : scene.textures) {
        if (cancelled && cancelled()) return nullptr;
        prepared->textureMips.push_back(mipChain(image));
    }
    return prepared;
}

SceneGpu::Draw SceneGpu::meshDraw(const Scene& scene, const Mesh& mesh, GLint baseVertex,
                                  GLuint nextPlacement) {
    Draw d;
    d.baseVertex = baseVertex;
    d.material = mesh.material;
    d.mesh = static_cast<int>(&mesh - scene.meshes.data());
    d.colored = !mesh.colors.empty();
    d.instance = mesh.instanced() ? nextPlacement : 0; // world-space meshes: the identity
    d.placements = static_cast<GLuint>(mesh.placements());
    return d;
}

std::size_t SceneGpu::appendRuns(const Mesh& mesh, const Draw& proto,
                                 const std::vector<std::uint32_t>& levelIndices, std::size_t firstIndex,
                                 std::vector<Draw>& draws, std::vector<RunBounds>& bounds) {
    // Runs of consecutive triangles with their bounds in the mesh's space. Indices were validated at
    // load; a bad one is skipped here rather than read out of range.
    std::size_t runs = 0;
    for (std::size_t t0 = 0; t0 + 3 <= levelIndices.size(); t0 += 3 * kChunkTriangles) {
        const std::size_t t1 = std::min(levelIndices.size() / 3 * 3, t0 + 3 * kChunkTriangles);
        glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
        for (std::size_t i = t0; i < t1; ++i) {
            const std::uint32_t v = levelIndices[i];
            if (v >= mesh.positions.size()) continue;
            lo = glm::min(lo, mesh.positions[v]);
            hi = glm::max(hi, mesh.positions[v]);
        }
        if (t1 <= t0) continue;
        // One run per chunk, covering all the mesh's placements, each with its world box: draw()
        // sends a run's visible placements as instanced commands.
        Draw run = proto;
        run.firstIndex = static_cast<GLint>(firstIndex + t0);
        run.indexCount = static_cast<GLsizei>(t1 - t0);
        run.firstBounds = bounds.size();
        if (!mesh.instanced()) {
            bounds.push_back({lo, hi});
        } else {
            // The world box around the placed corners: culling stays conservative.
            for (const glm::mat4& toWorld : mesh.instances) {
                const Bounds placed = placedBounds({lo, hi}, toWorld);
                bounds.push_back({placed.min, placed.max});
            }
        }
        draws.push_back(run);
        ++runs;
    }
    return runs;
}

std::shared_ptr<const SceneGpu::LodSet> SceneGpu::prepareLevels(const Scene& scene,
                                                                const std::function<bool()>& cancelled) {
    auto set = std::make_shared<LodSet>();
    // The vertices and placements as prepare() lays them out: each mesh's after the ones before it,
    // placement 0 the identity.
    GLint baseVertex = 0;
    GLuint nextPlacement = 1;
    for (const Mesh& mesh : scene.meshes) {
        if (cancelled && cancelled()) return nullptr;
        const Draw d = meshDraw(scene, mesh, baseVertex, nextPlacement);
        baseVertex += static_cast<GLint>(mesh.positions.size());
        if (mesh.instanced()) nextPlacement += static_cast<GLuint>(mesh.instances.size());

        MeshLevels levels;
        levels.firstLevel = set->levels.size();
        levels.firstExtent = set->extents.size();
        levels.placements = mesh.placements();
        for (const LodLevel& level : buildLodLevels(mesh)) {
            const std::size_t firstDraw = set->draws.size();
            const std::size_t runs =
                appendRuns(mesh, d, level.indices, set->indices.size(), set->draws, set->runBounds);
            set->indices.insert(set->indices.end(), level.indices.begin(), level.indices.end());
            set->levels.push_back({firstDraw, runs, level.error});
            set->triangles += level.indices.size() / 3;
            ++levels.levelCount;
        }
        // The mesh's own box (a level's vertices are some of the mesh's): where the eye's distance is
        // measured from.
        const Bounds own = ownBounds(mesh);
        if (!mesh.instanced()) {
            set->extents.push_back({own.min, own.max, 1.0f});
        } else {
            for (const glm::mat4& toWorld : mesh.instances) {
                const Bounds placed = placedBounds(own, toWorld);
                const float scale =
                    std::max({glm::length(glm::vec3(toWorld[0])), glm::length(glm::vec3(toWorld[1])),
                              glm::length(glm::vec3(toWorld[2]))});
                set->extents.push_back({placed.min, placed.max, std::isfinite(scale) ? scale : 1.0f});
            }
        }
        set->meshes.push_back(levels);
    }
    return set;
}

void SceneGpu::setLevels(std::shared_ptr<const LodSet> levels) {
    GIS_ASSERT(complete());
    if (!levels || levels->meshes.size() != mMeshes.size()) return;
    gl::Buffer buffer;
    if (!levels->indices.empty())
        buffer = gl::Buffer::create(static_cast<GLsizeiptr>(levels->indices.size() * sizeof(std::uint32_t)),
                                    levels->indices.data());
    gl::checkErrors(("levels of detail of '" + mSceneName + "'").c_str());
    mLodIndices = std::move(buffer);
    mLodDraws = levels->draws;
    mLod = std::move(levels);
    setSurfaceIds(mSurfaceIdOfMesh);
}

std::size_t SceneGpu::lodTriangleCount() const {
    return mLod ? mLod->triangles : 0;
}

SceneGpu::SceneGpu(const Scene& scene, std::shared_ptr<const Prepared> prepared)
    : SceneGpu(scene, std::move(prepared), Staged{}) {
    uploadSome(std::numeric_limits<double>::infinity());
}

SceneGpu::SceneGpu(const Scene& scene, std::shared_ptr<const Prepared> prepared, Staged)
    : mMaterials(scene.materials), mSceneName(scene.name) {
    if (!prepared) prepared = prepare(scene);
    GIS_ASSERT(prepared->vertices.size() == [&] {
        std::size_t n = 0;
        for (const Mesh& mesh : scene.meshes) n += mesh.positions.size();
        return n;
    }());
    const std::vector<Vertex>& vertices = prepared->vertices;
    const std::vector<std::uint32_t>& indices = prepared->indices;
    const std::vector<InstanceTransform>& placements = prepared->placements;
    mDraws = prepared->draws;
    mRunBounds = prepared->runBounds;
    mMeshes = prepared->meshes;
    mMaxCommands = prepared->maxCommands;
    mTriangles = prepared->triangles;
    mStoredTriangles = prepared->storedTriangles;
    mInstances = placements.size() - 1;
    if (vertices.empty() || indices.empty())
        throw Error("render: scene '" + scene.name + "' has no triangles");

    // Everything in pieces (uploadSome), each buffer's storage a piece of its own (llvmpipe clears
    // it): the pieces read `prepared` and the scene's images.
    const auto bufferInPieces = [&](gl::Buffer& buffer, const void* data, std::size_t bytes) {
        mPieces.push_back({[&buffer, bytes] {
                               buffer = gl::Buffer::create(static_cast<GLsizeiptr>(bytes), nullptr,
                                                           GL_DYNAMIC_STORAGE_BIT);
                           },
                           bytes, true});
        const auto* bytesIn = static_cast<const std::uint8_t*>(data);
        for (std::size_t offset = 0; offset < bytes; offset += kUploadChunkBytes) {
            const std::size_t size = std::min(kUploadChunkBytes, bytes - offset);
            mPieces.push_back({[&buffer, offset, size, bytesIn] {
                                   glNamedBufferSubData(buffer.id(), static_cast<GLintptr>(offset),
                                                        static_cast<GLsizeiptr>(size), bytesIn + offset);
                               },
                               size, false});
        }
    };
    bufferInPieces(mVertices, vertices.data(), vertices.size() * sizeof(Vertex));
    bufferInPieces(mIndices, indices.data(), indices.size() * sizeof(std::uint32_t));
    bufferInPieces(mPlacements, placements.data(), placements.size() * sizeof(InstanceTransform));
    mPieces.push_back({[this] { setUpVertexArray(); }, 0, false});

    GIS_ASSERT(prepared->textureMips.size() == scene.textures.size());
    // Creating a texture's storage is a piece of its own: llvmpipe clears it, which is most of a
    // big texture's upload.
    mTextures.resize(scene.textures.size());
    for (std::size_t i = 0; i < scene.textures.size(); ++i) {
        const TextureImage& image = scene.textures[i];
        const std::vector<MipLevel>& mips = prepared->textureMips[i];
        // Colour is sRGB-encoded (the sampler decodes it); metallic-roughness data is linear. The
        // mipmaps come from prepare(), built on the CPU off the render thread.
        const GLenum format = image.srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8;
        const int width = image.width, height = image.height, levels = static_cast<int>(mips.size()) + 1;
        std::size_t textureBytes = image.rgba.size();
        for (const MipLevel& m : mips) textureBytes += m.rgba.size();
        mPieces.push_back({[this, i, format, width, height, levels] {
                               gl::Texture t = gl::Texture::create2D(format, width, height, levels);
                               t.setFilter(GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR);
                               t.setWrap(GL_REPEAT);
                               mTextures[i] = std::move(t);
                           },
                           textureBytes, true});
        const auto levelInBands = [&](GLint level, int levelWidth, int levelHeight,
                                      const std::uint8_t* rgba) {
            const std::size_t rowBytes = static_cast<std::size_t>(levelWidth) * 4;
            const int rowsPerBand = static_cast<int>(std::max<std::size_t>(1, kUploadChunkBytes / rowBytes));
            for (int y = 0; y < levelHeight; y += rowsPerBand) {
                const int rows = std::min(rowsPerBand, levelHeight - y);
                const std::uint8_t* first = rgba + static_cast<std::size_t>(y) * rowBytes;
                mPieces.push_back({[this, i, level, y, levelWidth, rows, first] {
                                       glTextureSubImage2D(mTextures[i].id(), level, 0, y, levelWidth, rows,
                                                           GL_RGBA, GL_UNSIGNED_BYTE, first);
                                   },
                                   static_cast<std::size_t>(rows) * rowBytes, false});
            }
        };
        levelInBands(0, image.width, image.height, image.rgba.data());
        for (std::size_t l = 0; l < mips.size(); ++l)
            levelInBands(static_cast<GLint>(l + 1), mips[l].width, mips[l].height, mips[l].rgba.data());
    }
    mUploading = std::move(prepared);
    // Bound wherever a material lacks a map: the shader ignores it (uHas*Tex 0) but still samples
    // what the unit holds (llvmpipe runs both sides of the branch), and a one-texel nearest texture
    // is the cheapest thing to sample. Left to whatever a previous pass bound there, the
    // G-buffer pass of the untextured Cornell box took about twice as long (docs/multires.md).
    mFallbackTexture = gl::Texture::create2D(GL_RGBA8, 1, 1);
    const unsigned char white[4] = {255, 255, 255, 255};
    glTextureSubImage2D(mFallbackTexture.id(), 0, 0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, white);
    mFallbackTexture.setFilter(GL_NEAREST, GL_NEAREST);
    reserveCommands(std::max<std::size_t>(mDraws.size(), 1));
    mCommandScratch.reserve(mDraws.size());
    gl::checkErrors("scene upload");
}

void SceneGpu::setUpVertexArray() {
    mVao = gl::VertexArray::create();
    const GLuint vao = mVao.id();
    glVertexArrayVertexBuffer(vao, 0, mVertices.id(), 0, sizeof(Vertex));
    glVertexArrayElementBuffer(vao, mIndices.id());
    const GLuint offsets[5] = {offsetof(Vertex, position), offsetof(Vertex, normal),
                               offsetof(Vertex, texcoord), offsetof(Vertex, tangent),
                               offsetof(Vertex, color)};
    const GLint sizes[5] = {3, 3, 2, 4, 4};
    for (GLuint a = 0; a < 5; ++a) {
        glEnableVertexArrayAttrib(vao, a);
        glVertexArrayAttribFormat(vao, a, sizes[a], GL_FLOAT, GL_FALSE, offsets[a]);
        glVertexArrayAttribBinding(vao, a, 0);
    }
    // The placements' matrices (shaders/render/instance.glsl), per instance; draw() sets the
    // divisor each pass needs. Seven vec4 columns from attribute 5: the object -> world matrix's four,
    // then the normal matrix's three (read as vec3).
    static_assert(kNormalToWorldAttribute == kToWorldAttribute + 4 &&
                  offsetof(InstanceTransform, toWorld) == 0 &&
                  offsetof(InstanceTransform, normalToWorld) == 4 * sizeof(glm::vec4));
    glVertexArrayVertexBuffer(vao, 1, mPlacements.id(), 0, sizeof(InstanceTransform));
    glVertexArrayBindingDivisor(vao, 1, mDivisor);
    for (GLuint column = 0; column < 7; ++column) {
        const GLuint attribute = kToWorldAttribute + column;
        glEnableVertexArrayAttrib(vao, attribute);
        glVertexArrayAttribFormat(vao, attribute, column < 4 ? 4 : 3, GL_FLOAT, GL_FALSE,
                                  static_cast<GLuint>(column * sizeof(glm::vec4)));
        glVertexArrayAttribBinding(vao, attribute, 1);
    }
}

bool SceneGpu::uploadSome(double budgetMs) {
    using Clock = std::chrono::steady_clock;
    const auto msSince = [](Clock::time_point t) {
        return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
    };
    const auto start = Clock::now();
    for (bool first = true; mNextPiece < mPieces.size(); first = false) {
        const Piece& piece = mPieces[mNextPiece];
        const double mib = static_cast<double>(piece.bytes) / (1024.0 * 1024.0);
        double& msPerMiB = piece.creates ? mCreateMsPerMiB : mFillMsPerMiB;
        if (!first && msSince(start) + mib * msPerMiB > budgetMs) break;
        const auto pieceStart = Clock::now();
        piece.send();
        ++mNextPiece;
        // Pieces under 1 MiB say little about the rate (their fixed cost dominates).
        if (mib >= 1.0) msPerMiB = 0.5 * msPerMiB + 0.5 * msSince(pieceStart) / mib;
    }
    if (mNextPiece < mPieces.size()) return false;
    if (mUploading) {
        mPieces.clear();
        mPieces.shrink_to_fit();
        mNextPiece = 0;
        mUploading.reset(); // the prepared copy is no longer needed
        gl::checkErrors(("scene upload of '" + mSceneName + "'").c_str());
    }
    return true;
}

void SceneGpu::reserveCommands(std::size_t commands) const {
    // Up to kCommandSlots regions, fewer where a region is large (a scene of many placements): the
    // ring only spares the driver waits, the regions' total stays within kCommandBytes.
    mCommandCapacity = commands;
    const std::size_t regionBytes = commands * sizeof(IndirectCommand);
    mCommandSlots =
        std::clamp<std::size_t>(kCommandBytes / std::max<std::size_t>(regionBytes, 1), 1, kCommandSlots);
    mCommands = gl::Buffer::create(static_cast<GLsizeiptr>(regionBytes * mCommandSlots));
    mCommandSlot = 0;
}

void SceneGpu::setSurfaceIds(const std::vector<int>& idOfMesh) {
    mSurfaceIdOfMesh = idOfMesh;
    for (std::vector<Draw>* draws : {&mDraws, &mLodDraws})
        for (Draw& d : *draws) {
            const auto m = static_cast<size_t>(d.mesh);
            d.surfaceId = m < idOfMesh.size() ? idOfMesh[m] : 0;
        }
}

MaterialSlots MaterialSlots::of(const gl::Program& program, bool complete) {
    auto slot = [&](const char* name) {
        return complete ? program.location(name) : program.optionalLocation(name);
    };
    MaterialSlots m;
    m.baseColor = slot("uBaseColor");
    m.emissive = slot("uEmissive");
    m.hasTexture = slot("uHasTexture");
    m.metalRoughSpec = slot("uMetalRoughSpec");
    m.mirrorId = slot("uMirrorId");
    if (program.declares("uAlphaCutoff")) m.alphaCutoff = program.optionalLocation("uAlphaCutoff");
    m.hasMetalRoughTexture = slot("uHasMetalRoughTex");
    m.hasEmissiveTexture = slot("uHasEmissiveTex");
    // A sampler the program leaves unused gets no unit (kNoUnit): binding to unit 0 would replace the
    // base colour texture.
    auto unit = [&](const char* name) {
        if (complete) return program.textureUnit(name);
        return program.declares(name) ? program.optionalTextureUnit(name) : gl::TextureUnit{gl::kNoUnit};
    };
    m.baseColorTexture = unit("uBaseColorTex");
    m.metalRoughTexture = unit("uMetalRoughTex");
    m.emissiveTexture = unit("uEmissiveTex");
    m.normalTexture = unit("uNormalTex");
    m.occlusionTexture = unit("uOcclusionTex");
    m.hasOcclusionTexture = slot("uHasOcclusionTex");
    m.occlusionStrength = slot("uOcclusionStrength");
    m.hasNormalTexture = slot("uHasNormalTex");
    m.normalScale = slot("uNormalScale");
    m.hasVertexColor = slot("uHasVertexColor");
    return m;
}

float lodErrorPerMetre(float pixels, float yfovRadians, int imageHeight) {
    if (!(pixels > 0.0f) || imageHeight <= 0 || !(yfovRadians > 0.0f) || !(yfovRadians < 3.1f)) return 0.0f;
    const float perMetre = pixels * 2.0f * std::tan(0.5f * yfovRadians) / static_cast<float>(imageHeight);
    return std::isfinite(perMetre) ? perMetre : 0.0f;
}

DrawCount SceneGpu::draw(const gl::Program&, const MaterialSlots* materials, int instances, int skipMesh,
                         const glm::mat4* cullViewProj, bool cullBackFaces, const LodView* lod) const {
    // The caller has bound the program; `materials` were resolved from it.
    GIS_ASSERT(complete());
    glBindVertexArray(mVao.id());
    const std::optional<Frustum> frustum =
        cullViewProj ? std::optional<Frustum>(Frustum(*cullViewProj)) : std::nullopt;
    DrawCount count;

    // 1. The visible runs as draw commands, cut into batches wherever the state changes. Runs of one
    // mesh share its uniforms; different meshes share them when their material, surface id and
    // vertex colours agree.
    std::vector<Batch>& batches = mBatchScratch;
    std::vector<IndirectCommand>& commands = mCommandScratch;
    batches.clear();
    commands.clear();
    // A pass that draws instanced for its own reasons (cube faces per VPL) gets one command per
    // placement, all of whose instances read it; any other pass draws each run of visible
    // consecutive placements as one instanced command, a placement per instance.
    const bool commandPerPlacement = instances > 1;
    if (const GLuint divisor = commandPerPlacement ? kPlacementDivisor : 1u; divisor != mDivisor) {
        glVertexArrayBindingDivisor(mVao.id(), 1, divisor);
        mDivisor = divisor;
    }
    for (std::size_t meshIndex = 0; meshIndex < mMeshes.size(); ++meshIndex) {
        if (static_cast<int>(meshIndex) == skipMesh) continue;
        const MeshRuns& own = mMeshes[meshIndex];
        const MeshLevels* levels = mLod ? &mLod->meshes[meshIndex] : nullptr;
        // Each placement's level (0: the mesh itself): the coarsest whose error, at the placement's
        // nearest point, the view tolerates (inside the box, distance 0: only an orthographic view's
        // errorAtEye).
        std::vector<std::uint8_t>& chosen = mLevelScratch;
        std::size_t lastLevel = 0;
        const bool choose = lod && lod->tolerates() && levels && levels->levelCount > 0;
        if (choose) {
            chosen.assign(levels->placements, 0);
            for (std::size_t k = 0; k < levels->placements; ++k) {
                const PlacementExtent& e = mLod->extents[levels->firstExtent + k];
                const float distance =
                    glm::length(glm::max(glm::max(e.lo - lod->eye, lod->eye - e.hi), glm::vec3(0.0f)));
                const float tolerated = lod->errorAtEye + lod->errorPerMetre * distance;
                for (std::size_t l = levels->levelCount; l > 0; --l)
                    if (mLod->levels[levels->firstLevel + l - 1].error * e.scale <= tolerated) {
                        chosen[k] = static_cast<std::uint8_t>(l);
                        lastLevel = std::max(lastLevel, l);
                        break;
                    }
            }
        }
        for (std::size_t l = 0; l <= lastLevel; ++l) {
            const bool coarse = l > 0;
            const Draw* runs = coarse ? mLodDraws.data() : mDraws.data();
            const std::vector<RunBounds>& runBounds = coarse ? mLod->runBounds : mRunBounds;
            std::size_t firstRun = own.firstDraw, runCount = own.drawCount;
            if (coarse) {
                const Level& level = mLod->levels[levels->firstLevel + l - 1];
                firstRun = level.firstDraw;
                runCount = level.drawCount;
            }
            for (std::size_t r = firstRun; r < firstRun + runCount; ++r) {
                const Draw& d = runs[r];
                const auto triangles = static_cast<std::size_t>(d.indexCount / 3);
                bool open = false; // the last command takes the next placement as one more instance
                bool first = true; // no command of this run yet
                for (GLuint k = 0; k < d.placements; ++k) {
                    if (choose && chosen[k] != l) {
                        open = false;
                        continue;
                    }
                    const RunBounds& b = runBounds[d.firstBounds + k];
                    if (frustum && frustum->outside(b.lo, b.hi)) {
                        count.culled += triangles;
                        open = false;
                        continue;
                    }
                    count.drawn += triangles;
                    if (coarse) count.simplified += triangles;
                    if (open) {
                        ++commands.back().instanceCount;
                        continue;
                    }
                    if (first || batches.empty() || batches.back().head != &d) {
                        const bool oneSided = cullBackFaces && d.material >= 0 &&
                                              static_cast<std::size_t>(d.material) < mMaterials.size() &&
                                              !mMaterials[static_cast<std::size_t>(d.material)].doubleSided;
                        const Draw* head = batches.empty() ? nullptr : batches.back().head;
                        const bool sameState =
                            head && batches.back().oneSided == oneSided && batches.back().coarse == coarse &&
                            (!materials || head->mesh == d.mesh ||
                             (head->material == d.material && head->surfaceId == d.surfaceId &&
                              head->colored == d.colored));
                        if (!sameState) batches.push_back({commands.size(), 0, &d, oneSided, coarse});
                    }
                    first = false;
                    commands.push_back({static_cast<GLuint>(d.indexCount),
                                        static_cast<GLuint>(commandPerPlacement ? instances : 1),
                                        static_cast<GLuint>(d.firstIndex), d.baseVertex, d.instance + k});
                    ++batches.back().count;
                    open = !commandPerPlacement;
                }
            }
        }
    }
    count.runs = commands.size();
    count.calls = batches.size();
    if (commands.empty()) return count;

    // 2. This call's region of the command buffer, then one multi-draw per batch.
    if (commands.size() > mCommandCapacity) reserveCommands(std::min(mMaxCommands, 2 * commands.size()));
    const std::size_t slotBytes = mCommandCapacity * sizeof(IndirectCommand);
    const std::size_t base = (mCommandSlot++ % mCommandSlots) * slotBytes;
    mCommands.upload(static_cast<GLintptr>(base),
                     static_cast<GLsizeiptr>(commands.size() * sizeof(IndirectCommand)), commands.data());
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, mCommands.id());
    bool culling = false; // GL_CULL_FACE is off in every pass (FrameRenderer::render) until set here
    std::array<GLuint, 5> unitHolds{}; // what this call bound on each material unit (0: not yet)
    bool coarseBound = false;          // the vertex array's element buffer is mIndices until a coarse batch
    for (const Batch& b : batches) {
        if (b.coarse != coarseBound) {
            glVertexArrayElementBuffer(mVao.id(), b.coarse ? mLodIndices.id() : mIndices.id());
            coarseBound = b.coarse;
        }
        if (cullBackFaces && b.oneSided != culling) {
            if (b.oneSided) {
                glCullFace(GL_BACK);
                glEnable(GL_CULL_FACE);
            } else {
                glDisable(GL_CULL_FACE);
            }
            culling = b.oneSided;
        }
        if (materials) {
            const Draw& d = *b.head;
            const MaterialSlots& s = *materials;
            const Material& m = mMaterials[static_cast<size_t>(d.material)];
            glUniform4f(s.baseColor.location, m.baseColor.r, m.baseColor.g, m.baseColor.b, m.baseColor.a);
            glUniform3f(s.metalRoughSpec.location, m.metallic, m.roughness, m.specular);
            glUniform1i(s.mirrorId.location, d.surfaceId);
            glUniform1i(s.hasVertexColor.location, d.colored ? 1 : 0);
            glUniform1f(s.alphaCutoff.location, m.cutsOut() ? m.cutoff() : -1.0f);
            glUniform3f(s.emissive.location, m.emissive.r, m.emissive.g, m.emissive.b);
            // Each texture the material has, on its unit, the fallback texel on the others; a unit the
            // program does not sample is skipped, and one that already holds the texture (an earlier
            // batch of this call bound it) is left as it is.
            auto bind = [&](std::size_t slot, int texture, gl::UniformLocation has,
                            const gl::TextureUnit& unit) {
                const bool present = texture >= 0 && texture < static_cast<int>(mTextures.size());
                glUniform1i(has.location, present ? 1 : 0);
                const GLuint id =
                    present ? mTextures[static_cast<size_t>(texture)].id() : mFallbackTexture.id();
                if (unit.unit == gl::kNoUnit || unitHolds[slot] == id) return;
                glBindTextureUnit(unit.unit, id);
                unitHolds[slot] = id;
            };
            bind(0, m.baseColorTexture, s.hasTexture, s.baseColorTexture);
            bind(1, m.metallicRoughnessTexture, s.hasMetalRoughTexture, s.metalRoughTexture);
            bind(2, m.emissiveTexture, s.hasEmissiveTexture, s.emissiveTexture);
            bind(3, m.normalTexture, s.hasNormalTexture, s.normalTexture);
            bind(4, m.occlusionTexture, s.hasOcclusionTexture, s.occlusionTexture);
            glUniform1f(s.occlusionStrength.location,
                        std::isfinite(m.occlusionStrength) ? m.occlusionStrength : 1.0f);
            glUniform1f(s.normalScale.location, std::isfinite(m.normalScale) ? m.normalScale : 1.0f);
        }
        glMultiDrawElementsIndirect(
            GL_TRIANGLES, GL_UNSIGNED_INT,
            reinterpret_cast<const void*>(static_cast<uintptr_t>(base + b.first * sizeof(IndirectCommand))),
            static_cast<GLsizei>(b.count), 0);
    }
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
    if (culling) glDisable(GL_CULL_FACE);
    if (coarseBound) glVertexArrayElementBuffer(mVao.id(), mIndices.id());
    return count;
}

} // namespace gis
