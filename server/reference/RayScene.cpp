// Embree 3 scene for the reference renderer. Geometry is copied into Embree-owned buffers once; the
// scene is committed with RTC_SCENE_FLAG_ROBUST (watertight triangle test, so rays do not leak through
// shared edges of the grid walls) and RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION (the all-hits query
// installs its collector through the intersect context, plain queries pay nothing). Meshes whose
// material cuts out (alpha MASK, BLEND approximated) get a geometry filter that rejects hits where
// the base colour's alpha is below the cutoff, for intersection and occlusion rays alike.
#include "reference/RayScene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include <embree3/rtcore.h>

#include "core/Error.h"

namespace gis::reference {
namespace {

struct LinearTexture {
    int width = 0;
    int height = 0;
    std::vector<glm::vec3> texels; ///< linear RGB (sRGB decoded per texel, as GL's sRGB sampler does)
    std::vector<float> alpha;      ///< linear alpha in [0, 1] (not sRGB-encoded)
};

float srgbToLinear(std::uint8_t v) {
    const float c = static_cast<float>(v) / 255.0f;
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

glm::vec3 sanitizePositive(const glm::vec3& c) {
    glm::vec3 r;
    for (int i = 0; i < 3; ++i) r[i] = std::isfinite(c[i]) ? std::max(c[i], 0.0f) : 0.0f;
    return r;
}

int wrapIndex(int i, int n) {
    const int m = i % n;
    return m < 0 ? m + n : m;
}

/// Bilinear, wrap-repeat lookup of `values` (one per texel); texel centres at (i + 0.5) / size like GL.
template <typename T>
T bilinear(const LinearTexture& tex, const std::vector<T>& values, glm::vec2 uv, T fallback) {
    if (tex.width <= 0 || tex.height <= 0 ||
        values.size() < static_cast<size_t>(tex.width) * static_cast<size_t>(tex.height))
        return fallback;
    for (int i = 0; i < 2; ++i) {
        if (!std::isfinite(uv[i])) uv[i] = 0.0f;
        uv[i] -= std::floor(uv[i]); // keeps huge coordinates from overflowing the int conversion
    }
    const float x = uv.x * static_cast<float>(tex.width) - 0.5f;
    const float y = uv.y * static_cast<float>(tex.height) - 0.5f;
    const float x0f = std::floor(x), y0f = std::floor(y);
    const float fx = x - x0f, fy = y - y0f;
    const int x0 = static_cast<int>(x0f), y0 = static_cast<int>(y0f);
    auto at = [&](int xi, int yi) {
        const auto idx = static_cast<size_t>(wrapIndex(yi, tex.height)) * static_cast<size_t>(tex.width) +
                         static_cast<size_t>(wrapIndex(xi, tex.width));
        return values[idx];
    };
    const T top = glm::mix(at(x0, y0), at(x0 + 1, y0), fx);
    const T bottom = glm::mix(at(x0, y0 + 1), at(x0 + 1, y0 + 1), fx);
    return glm::mix(top, bottom, fy);
}

glm::vec3 sampleBilinear(const LinearTexture& tex, glm::vec2 uv) {
    return bilinear(tex, tex.texels, uv, glm::vec3(1.0f));
}

/// A mesh whose material cuts out (Material::cutsOut): what its Embree filter reads.
struct CutoutGeometry {
    const Mesh* mesh = nullptr;
    const LinearTexture* texture = nullptr; ///< the base colour texture, or none
    float alphaFactor = 1.0f;
    float cutoff = 0.5f;

    /// material.glsl's materialCutOut() at barycentrics (u, v) of triangle `prim`.
    bool cutsOut(unsigned prim, float u, float v) const {
        float alpha = alphaFactor;
        const size_t first = static_cast<size_t>(prim) * 3;
        if (mesh->colors.size() == mesh->positions.size() && first + 2 < mesh->indices.size()) {
            const auto last = static_cast<std::uint32_t>(mesh->positions.size() - 1);
            alpha *= (1.0f - u - v) * mesh->colors[std::min(mesh->indices[first], last)].w +
                     u * mesh->colors[std::min(mesh->indices[first + 1], last)].w +
                     v * mesh->colors[std::min(mesh->indices[first + 2], last)].w;
        }
        if (texture) {
            glm::vec2 uv(0.0f); // GL feeds (0, 0) to meshes without texcoords
            const size_t base = static_cast<size_t>(prim) * 3;
            if (base + 2 < mesh->indices.size() && !mesh->positions.empty() &&
                mesh->texcoords.size() == mesh->positions.size()) {
                const auto last = static_cast<std::uint32_t>(mesh->positions.size() - 1);
                const std::uint32_t i0 = std::min(mesh->indices[base], last),
                                    i1 = std::min(mesh->indices[base + 1], last),
                                    i2 = std::min(mesh->indices[base + 2], last);
                uv = (1.0f - u - v) * mesh->texcoords[i0] + u * mesh->texcoords[i1] + v * mesh->texcoords[i2];
            }
            alpha *= bilinear(*texture, texture->alpha, uv, 1.0f);
        }
        return !(alpha >= cutoff); // NaN cuts out, as in the shader
    }
};

// Embree geometry filter (intersect and occluded) of a cut-out mesh: a hit where the material's alpha is
// below its cutoff is no hit, so rays and shadow rays pass through the cut-out parts.
void cutoutFilter(const RTCFilterFunctionNArguments* args) {
    const auto* geometry = static_cast<const CutoutGeometry*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
        if (geometry->cutsOut(prim, RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i)))
            args->valid[i] = 0;
    }
}

struct CollectContext {
    RTCIntersectContext base; // must stay first: Embree hands back a pointer to it
    std::vector<RawHit>* hits;
};

struct CameraContext {
    RTCIntersectContext base;                 // must stay first: Embree hands back a pointer to it
    const std::vector<const Mesh*>* oneSided; // per Embree geometry: its mesh when single-sided
};

// A camera ray passes the back face of a single-sided mesh (glTF front faces are CCW).
void cameraFilter(const RTCFilterFunctionNArguments* args) {
    const auto* ctx = reinterpret_cast<const CameraContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        const unsigned geom = RTCHitN_geomID(args->hit, args->N, i);
        if (geom >= ctx->oneSided->size()) continue;
        const Mesh* mesh = (*ctx->oneSided)[geom];
        const std::size_t first = static_cast<std::size_t>(RTCHitN_primID(args->hit, args->N, i)) * 3;
        if (!mesh || first + 2 >= mesh->indices.size() || mesh->positions.empty()) continue;
        const auto last = static_cast<std::uint32_t>(mesh->positions.size() - 1);
        const glm::vec3 p0 = mesh->positions[std::min(mesh->indices[first], last)],
                        p1 = mesh->positions[std::min(mesh->indices[first + 1], last)],
                        p2 = mesh->positions[std::min(mesh->indices[first + 2], last)];
        const glm::vec3 dir(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                            RTCRayN_dir_z(args->ray, args->N, i));
        if (glm::dot(glm::cross(p1 - p0, p2 - p0), dir) > 0.0f) args->valid[i] = 0;
    }
}

// Records every candidate hit and rejects it, so traversal goes on to the next surface.
void collectAllHits(const RTCFilterFunctionNArguments* args) {
    auto* ctx = reinterpret_cast<CollectContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        RawHit h;
        h.t = RTCRayN_tfar(args->ray, args->N, i);
        h.geomId = RTCHitN_geomID(args->hit, args->N, i);
        h.primId = RTCHitN_primID(args->hit, args->N, i);
        h.u = RTCHitN_u(args->hit, args->N, i);
        h.v = RTCHitN_v(args->hit, args->N, i);
        // Embree may report a primitive more than once; a watertight test may also report both
        // triangles of an edge (a measure-zero event for sampled rays). Keep the first report.
        const bool seen = std::any_of(ctx->hits->begin(), ctx->hits->end(), [&](const RawHit& o) {
            return o.geomId == h.geomId && o.primId == h.primId;
        });
        if (!seen) ctx->hits->push_back(h);
        args->valid[i] = 0;
    }
}

RTCRay makeRay(const glm::vec3& o, const glm::vec3& d, float tnear, float tfar) {
    RTCRay r{};
    r.org_x = o.x;
    r.org_y = o.y;
    r.org_z = o.z;
    r.dir_x = d.x;
    r.dir_y = d.y;
    r.dir_z = d.z;
    r.tnear = tnear;
    r.tfar = tfar;
    r.mask = 0xffffffffu;
    r.flags = 0;
    r.time = 0.0f;
    return r;
}

} // namespace

struct RayScene::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    // Copied, instances flattened to world space: the renderer must not depend on the caller's
    // lifetime, and the BVH holds every placement as triangles of its own.
    Scene source;                    // its meshes have the caller's indices
    std::vector<int> meshOfGeometry; // Embree geometry id -> index into source.meshes
    std::vector<LinearTexture> textures;
    std::vector<std::unique_ptr<CutoutGeometry>> cutouts; // the filters' user data (stable addresses)
    std::vector<const Mesh*> oneSided; // Embree geometry id -> its mesh when single-sided, else null

    ~Impl() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

RayScene::RayScene(const Scene& scene, const RaySceneOptions& options) : mImpl(std::make_unique<Impl>()) {
    Impl& m = *mImpl;
    const auto throwIfCancelled = [&] {
        if (options.cancelled && options.cancelled()) throw BuildCancelled();
    };
    m.source = flattenInstances(scene);
    throwIfCancelled();
    m.device = rtcNewDevice(nullptr);
    if (!m.device) throw Error("reference: cannot create the Embree device");
    m.scene = rtcNewScene(m.device);
    rtcSetSceneFlags(m.scene, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    rtcSetSceneBuildQuality(m.scene, options.fastBuild ? RTC_BUILD_QUALITY_MEDIUM : RTC_BUILD_QUALITY_HIGH);
    if (options.cancelled) {
        // Embree asks from its build threads; answering false cancels the commit.
        rtcSetSceneProgressMonitorFunction(
            m.scene,
            [](void* cancelled, double) {
                return !(*static_cast<const std::function<bool()>*>(cancelled))();
            },
            const_cast<std::function<bool()>*>(&options.cancelled));
    }

    // One sRGB decode table: textures are decoded to linear once, then filtered in linear space.
    std::array<float, 256> decode{};
    for (int i = 0; i < 256; ++i) decode[static_cast<size_t>(i)] = srgbToLinear(static_cast<std::uint8_t>(i));
    for (const TextureImage& img : m.source.textures) {
        LinearTexture t;
        const size_t count =
            static_cast<size_t>(std::max(img.width, 0)) * static_cast<size_t>(std::max(img.height, 0));
        if (count > 0 && img.rgba.size() >= count * 4) {
            t.width = img.width;
            t.height = img.height;
            t.texels.resize(count);
            // Colour is sRGB-decoded per texel as GL's sRGB sampler does; data textures stay linear.
            const auto channel = [&](std::uint8_t v) {
                return img.srgb ? decode[v] : static_cast<float>(v) / 255.0f;
            };
            for (size_t i = 0; i < count; ++i)
                t.texels[i] = {channel(img.rgba[4 * i]), channel(img.rgba[4 * i + 1]),
                               channel(img.rgba[4 * i + 2])};
            t.alpha.resize(count);
            for (size_t i = 0; i < count; ++i) t.alpha[i] = static_cast<float>(img.rgba[4 * i + 3]) / 255.0f;
        }
        m.textures.push_back(std::move(t));
    }

    for (size_t mi = 0; mi < m.source.meshes.size(); ++mi) {
        throwIfCancelled();
        const Mesh& mesh = m.source.meshes[mi];
        const size_t triangles = mesh.indices.size() / 3;
        if (triangles == 0 || mesh.positions.empty()) continue;
        RTCGeometry geom = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
            geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.positions.size()));
        auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
            geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles));
        if (!vertices || !indices) {
            rtcReleaseGeometry(geom);
            throw Error("reference: Embree could not allocate buffers for mesh '" + mesh.name + "'");
        }
        for (size_t i = 0; i < mesh.positions.size(); ++i)
            for (int c = 0; c < 3; ++c) vertices[3 * i + static_cast<size_t>(c)] = mesh.positions[i][c];
        const auto vertexCount = static_cast<std::uint32_t>(mesh.positions.size());
        for (size_t i = 0; i < triangles * 3; ++i)
            indices[i] =
                std::min<std::uint32_t>(mesh.indices[i], vertexCount - 1); // validated; belt and braces
        if (mesh.material >= 0 && static_cast<size_t>(mesh.material) < m.source.materials.size()) {
            const Material& mat = m.source.materials[static_cast<size_t>(mesh.material)];
            if (mat.cutsOut()) {
                auto cut = std::make_unique<CutoutGeometry>();
                cut->mesh = &mesh;
                if (mat.baseColorTexture >= 0 &&
                    static_cast<size_t>(mat.baseColorTexture) < m.textures.size())
                    cut->texture = &m.textures[static_cast<size_t>(mat.baseColorTexture)];
                cut->alphaFactor = mat.baseColor.a;
                cut->cutoff = mat.cutoff();
                rtcSetGeometryUserData(geom, cut.get());
                rtcSetGeometryIntersectFilterFunction(geom, cutoutFilter);
                rtcSetGeometryOccludedFilterFunction(geom, cutoutFilter);
                m.cutouts.push_back(std::move(cut));
            }
        }
        rtcCommitGeometry(geom);
        const unsigned id = rtcAttachGeometry(m.scene, geom);
        rtcReleaseGeometry(geom);
        if (m.meshOfGeometry.size() <= id) m.meshOfGeometry.resize(id + 1, -1);
        m.meshOfGeometry[id] = static_cast<int>(mi);
        if (m.oneSided.size() <= id) m.oneSided.resize(id + 1, nullptr);
        if (mesh.material >= 0 && static_cast<size_t>(mesh.material) < m.source.materials.size() &&
            !m.source.materials[static_cast<size_t>(mesh.material)].doubleSided)
            m.oneSided[id] = &mesh;
    }
    rtcCommitScene(m.scene);
    const RTCError built = rtcGetDeviceError(m.device);
    if (built == RTC_ERROR_CANCELLED || (built != RTC_ERROR_NONE && options.cancelled && options.cancelled()))
        throw BuildCancelled();
    if (built != RTC_ERROR_NONE) throw Error("reference: Embree failed to build the scene");

    // Far enough to clear float rounding of positions anywhere in the scene (coordinates up to
    // |centre| + radius carry a relative error of ~1e-7), small enough not to skip real geometry in
    // contact (1e-4 of the scene's size: 0.3 mm in the 2 m Cornell box).
    const float extent = scene.bounds.radius() + glm::length(scene.bounds.center());
    mEpsilon = 1e-4f * (std::isfinite(extent) ? std::max(extent, 1e-2f) : 1.0f);
}

RayScene::~RayScene() = default;

bool RayScene::intersect(const glm::vec3& origin, const glm::vec3& dir, float tnear, float tfar,
                         SurfaceHit& hit) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh{};
    rh.ray = makeRay(origin, dir, tnear, tfar);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(mImpl->scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit = resolve(RawHit{rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v}, origin, dir);
    return true;
}

bool RayScene::intersectFromCamera(const glm::vec3& origin, const glm::vec3& dir, float tnear, float tfar,
                                   SurfaceHit& hit) const {
    CameraContext ctx;
    rtcInitIntersectContext(&ctx.base);
    ctx.oneSided = &mImpl->oneSided;
    const bool anyOneSided = std::any_of(mImpl->oneSided.begin(), mImpl->oneSided.end(),
                                         [](const Mesh* p) { return p != nullptr; });
    if (anyOneSided) ctx.base.filter = cameraFilter;
    RTCRayHit rh{};
    rh.ray = makeRay(origin, dir, tnear, tfar);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(mImpl->scene, &ctx.base, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit = resolve(RawHit{rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v}, origin, dir);
    return true;
}

bool RayScene::occluded(const glm::vec3& origin, const glm::vec3& dir, float tnear, float tfar) const {
    if (!(tfar > tnear)) return false;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray = makeRay(origin, dir, tnear, tfar);
    rtcOccluded1(mImpl->scene, &ctx, &ray);
    return ray.tfar < 0.0f; // Embree sets tfar to -inf on a hit
}

void RayScene::intersectAll(const glm::vec3& origin, const glm::vec3& dir, float tnear, float tfar,
                            std::vector<RawHit>& hits) const {
    hits.clear();
    CollectContext ctx;
    rtcInitIntersectContext(&ctx.base);
    ctx.base.filter = collectAllHits;
    ctx.hits = &hits;
    RTCRayHit rh{};
    rh.ray = makeRay(origin, dir, tnear, tfar);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(mImpl->scene, &ctx.base, &rh);
}

SurfaceHit RayScene::resolve(const RawHit& raw, const glm::vec3& origin, const glm::vec3& dir) const {
    const Impl& m = *mImpl;
    SurfaceHit h;
    h.t = raw.t;
    const int meshIndex = raw.geomId < m.meshOfGeometry.size() ? m.meshOfGeometry[raw.geomId] : -1;
    if (meshIndex < 0) {
        h.position = origin + raw.t * dir;
        return h;
    }
    const Mesh& mesh = m.source.meshes[static_cast<size_t>(meshIndex)];
    h.mesh = meshIndex;
    const size_t base = static_cast<size_t>(raw.primId) * 3;
    const std::uint32_t last = static_cast<std::uint32_t>(mesh.positions.size() - 1);
    const std::uint32_t i0 = std::min(mesh.indices[base], last), i1 = std::min(mesh.indices[base + 1], last),
                        i2 = std::min(mesh.indices[base + 2], last);
    const float w1 = raw.u, w2 = raw.v, w0 = 1.0f - raw.u - raw.v;

    // Barycentric interpolation puts the point on the triangle (origin + t * dir would drift off it).
    const glm::vec3 &p0 = mesh.positions[i0], &p1 = mesh.positions[i1], &p2 = mesh.positions[i2];
    h.position = w0 * p0 + w1 * p1 + w2 * p2;
    const glm::vec3 cross = glm::cross(p1 - p0, p2 - p0);
    const float c2 = glm::dot(cross, cross);
    h.geometricNormal = c2 > 1e-30f ? cross / std::sqrt(c2) : glm::vec3(0.0f, 1.0f, 0.0f);

    h.shadingNormal = h.geometricNormal;
    if (mesh.normals.size() == mesh.positions.size()) {
        const glm::vec3 n = w0 * mesh.normals[i0] + w1 * mesh.normals[i1] + w2 * mesh.normals[i2];
        const float n2 = glm::dot(n, n);
        if (n2 > 1e-12f && std::isfinite(n2)) h.shadingNormal = n / std::sqrt(n2); // as safeNormal() in GLSL
    }

    glm::vec2 uv(0.0f); // GL feeds (0, 0) to meshes without texcoords
    if (mesh.texcoords.size() == mesh.positions.size())
        uv = w0 * mesh.texcoords[i0] + w1 * mesh.texcoords[i1] + w2 * mesh.texcoords[i2];

    if (mesh.material >= 0 && static_cast<size_t>(mesh.material) < m.source.materials.size()) {
        const Material& mat = m.source.materials[static_cast<size_t>(mesh.material)];
        glm::vec3 c(mat.baseColor);
        if (mesh.colors.size() == mesh.positions.size()) // COLOR_0, as vColor in material.glsl
            c *= glm::vec3(w0 * mesh.colors[i0] + w1 * mesh.colors[i1] + w2 * mesh.colors[i2]);
        if (mat.baseColorTexture >= 0 && static_cast<size_t>(mat.baseColorTexture) < m.textures.size())
            c *= sampleBilinear(m.textures[static_cast<size_t>(mat.baseColorTexture)], uv);
        // materialBaseColor() / materialAlbedo() / materialF0() of material.glsl, via scene/Brdf.h.
        const glm::vec3 baseColour = glm::clamp(sanitizePositive(c), 0.0f, 1.0f);
        const auto finiteOr = [](float v, float fallback) { return std::isfinite(v) ? v : fallback; };
        const auto texture = [&](int index) -> const LinearTexture* {
            return index >= 0 && static_cast<size_t>(index) < m.textures.size()
                       ? &m.textures[static_cast<size_t>(index)]
                       : nullptr;
        };
        // materialMetalRoughSpec() and materialEmissive() of material.glsl.
        float metallic = finiteOr(mat.metallic, 0.0f), roughness = finiteOr(mat.roughness, 1.0f);
        if (const LinearTexture* mr = texture(mat.metallicRoughnessTexture)) {
            const glm::vec3 t = sampleBilinear(*mr, uv);
            metallic *= t.b;
            roughness *= t.g;
        }
        h.surface = brdf::surfaceFrom(baseColour, std::clamp(metallic, 0.0f, 1.0f),
                                      std::clamp(roughness, 0.0f, 1.0f), finiteOr(mat.specular, 0.0f));
        h.albedo = h.surface.diffuse; // == base when F0 = 0 (metallic 0, specular 0)
        // materialNormal() of material.glsl: the map perturbs the mesh's own (interpolated) normal in
        // the tangent frame; the integrator turns the result to the viewer's side as GL does.
        if (const LinearTexture* map = texture(mat.normalTexture);
            map && mesh.tangents.size() == mesh.positions.size()) {
            const glm::vec4 tangent =
                w0 * mesh.tangents[i0] + w1 * mesh.tangents[i1] + w2 * mesh.tangents[i2];
            const glm::vec3 n = h.shadingNormal;
            glm::vec3 t = glm::vec3(tangent) - n * glm::dot(n, glm::vec3(tangent));
            const float t2 = glm::dot(t, t);
            if (t2 > 1e-12f && std::isfinite(t2)) {
                t /= std::sqrt(t2);
                const glm::vec3 b = glm::cross(n, t) * (tangent.w < 0.0f ? -1.0f : 1.0f);
                glm::vec3 mapped = sampleBilinear(*map, uv) * 2.0f - 1.0f;
                const float scale = std::isfinite(mat.normalScale) ? mat.normalScale : 1.0f;
                mapped.x *= scale;
                mapped.y *= scale;
                const glm::vec3 r = t * mapped.x + b * mapped.y + n * mapped.z;
                const float r2 = glm::dot(r, r);
                if (r2 > 1e-12f && std::isfinite(r2)) h.shadingNormal = r / std::sqrt(r2);
            }
        }
        glm::vec3 emission = mat.emissive;
        if (const LinearTexture* e = texture(mat.emissiveTexture)) emission *= sampleBilinear(*e, uv);
        h.emission = sanitizePositive(emission);
    }
    return h;
}

} // namespace gis::reference
