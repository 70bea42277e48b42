// Scene: the renderer-neutral description every layer above works on (GL pipeline, reference
// renderer, analysis). The node hierarchy is applied once at load time, so consumers never walk a
// graph: a mesh is either in world space (drawn once) or in its own space with one object-to-world
// matrix per placement (Mesh::instances: a glTF mesh that several nodes share is stored once).
//
// Units: lengths in metres; punctual light intensity in candela (lm/sr, glTF's
// KHR_lights_punctual convention); colours linear RGB.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace gis {

/// RGBA8 image, rows top to bottom, as stored in the source file: sRGB-encoded colour (base colour,
/// emissive) or linear data (metallic-roughness), as `srgb` says.
struct TextureImage {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgba; ///< width * height * 4 bytes
    std::string name;               ///< for messages only
    bool srgb = true;               ///< colour, decoded to linear when sampled; false: linear data
};

/// glTF metallic-roughness material, reduced to what the pipeline reads.
struct Material {
    std::string name;
    glm::vec4 baseColor{1.0f}; ///< linear RGBA factor, each in [0, 1]
    int baseColorTexture = -1; ///< index into Scene::textures, -1 for none
    float metallic = 0.0f;     ///< [0, 1]
    float roughness = 1.0f;    ///< [0, 1], perceptual
    /// [0, 1], KHR_materials_specular's specularFactor: scales the dielectric F0 (0.04). 0 here, so
    /// materials built in code are Lambertian unless they ask for a specular lobe; glTF files get the
    /// glTF default 1 from the loader. The reflection model is scene/Brdf.h.
    float specular = 0.0f;
    glm::vec3 emissive{0.0f}; ///< linear RGB radiance scale (glTF emissiveFactor)
    /// glTF metallicRoughnessTexture (linear; blue scales metallic, green roughness) and
    /// emissiveTexture (sRGB; scales emissive): indices into Scene::textures, -1 for none. Both use
    /// the base colour texture's coordinates (the loader bakes that texture's UV set and transform).
    int metallicRoughnessTexture = -1;
    int emissiveTexture = -1;
    /// glTF normalTexture (linear, tangent space: rgb * 2 - 1) and its scale (applied to x and y).
    int normalTexture = -1;
    float normalScale = 1.0f;
    /// glTF occlusionTexture (linear, red channel) and its strength: ao = 1 + strength (r - 1). It
    /// darkens the GL pipeline's indirect light where no technique pass computes indirect visibility
    /// (the small-scale occlusion VPL gathers leave out); the reference traces visibility instead.
    int occlusionTexture = -1;
    float occlusionStrength = 1.0f;
    /// glTF alphaMode. MASK cuts out where the base colour's alpha (factor times texture) is below
    /// alphaCutoff, in every pass (G-buffer, shadow maps, RSMs, reflections) and in the reference.
    /// BLEND is approximated as a cutout at 0.5: half-transparent surfaces are either opaque or gone
    /// (docs/scenes.md).
    enum class Alpha { Opaque, Mask, Blend } alphaMode = Alpha::Opaque;
    float alphaCutoff = 0.5f; ///< [0, 1], MASK only
    /// Whether some of the surface may be cut out, and below which alpha.
    bool cutsOut() const { return alphaMode != Alpha::Opaque; }
    float cutoff() const { return alphaMode == Alpha::Blend ? 0.5f : alphaCutoff; }
    /// Whether any texture map modulates the factors (the render passes' plain programs need none).
    bool hasMaps() const {
        return baseColorTexture >= 0 || metallicRoughnessTexture >= 0 || emissiveTexture >= 0 ||
               normalTexture >= 0 || occlusionTexture >= 0;
    }
    /// glTF doubleSided. False (glTF's default): the camera does not see the back faces (culled in the
    /// G-buffer, the environment-probe faces and mirrored views; passed by the reference's camera
    /// rays), so an interior of one-sided walls can be looked into from outside; light views still
    /// see both sides. True: both sides shown, each lit
    /// on the side it is seen from. Materials built in code are double-sided.
    bool doubleSided = true;
};

/// One triangle list. Every vertex attribute array has positions.size() entries.
struct Mesh {
    std::string name;
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;     ///< unit length; generated when the source has none
    std::vector<glm::vec2> texcoords;   ///< empty when the source has none
    std::vector<std::uint32_t> indices; ///< triangle list, 3 per triangle, all < positions.size()
    /// xyz: unit tangent along +u, w: the bitangent's sign (b = w cross(n, t)); generated from the
    /// texture coordinates for meshes whose material has a normal map, empty otherwise. A zero
    /// tangent (no usable texture coordinates there) leaves the normal unmapped.
    std::vector<glm::vec4> tangents;
    /// glTF COLOR_0, linear RGBA in [0, 1] (alpha 1 for RGB sources): multiplies the base colour (and
    /// its alpha, for cutouts). Empty when the source has none.
    std::vector<glm::vec4> colors;
    int material = 0; ///< index into Scene::materials
    /// Empty: the attributes above are in world space and the mesh is drawn once. Otherwise they are
    /// in the mesh's own space and it is drawn once per matrix (object -> world; each finite with a
    /// positive determinant, so winding and tangent handedness hold: the loader flattens mirrored and
    /// singular placements instead). Instanced meshes are never mirrors or local-probe objects.
    std::vector<glm::mat4> instances;
    bool instanced() const { return !instances.empty(); }
    /// How many times the mesh is drawn.
    std::size_t placements() const { return instances.empty() ? 1 : instances.size(); }
};

enum class LightType { Spot, Point, Directional };

struct Light {
    std::string name;
    LightType type = LightType::Spot;
    glm::vec3 position{0.0f};               ///< metres (unused for directional)
    glm::vec3 direction{0.0f, -1.0f, 0.0f}; ///< unit vector the light points along
    glm::vec3 color{1.0f};                  ///< linear RGB, each in [0, 1]
    float intensity = 1.0f;                 ///< candela for spot/point, lux for directional
    float innerConeAngle = 0.0f;            ///< radians, spot only, [0, outer)
    float outerConeAngle = 0.7853982f;      ///< radians, spot only, (0, pi/2]
    float range = 0.0f;                     ///< metres, 0 = infinite
};

struct Camera {
    std::string name;
    glm::vec3 position{0.0f, 0.0f, 5.0f};
    glm::vec3 target{0.0f}; ///< point looked at
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    float yfovRadians = 0.6981317f; ///< vertical field of view, (0, pi)
    float znear = 0.05f;            ///< metres, > 0
    float zfar = 100.0f;            ///< metres, > znear
};

struct Bounds {
    glm::vec3 min{0.0f};
    glm::vec3 max{0.0f};
    glm::vec3 center() const { return 0.5f * (min + max); }
    float radius() const { return 0.5f * glm::length(max - min); }
    /// The longest side (m): the unit of the scene-relative knobs (gi/common/ParamSpecs.h).
    float longestSide() const {
        const glm::vec3 d = max - min;
        return glm::max(d.x, glm::max(d.y, d.z));
    }
};

/// The world box around `own`'s eight corners placed by `toWorld` (object -> world): it holds the
/// placed geometry, a little loosely under rotation.
Bounds placedBounds(const Bounds& own, const glm::mat4& toWorld);
/// The box around `mesh`'s own positions (its space, before any placement); a zero box without any.
Bounds ownBounds(const Mesh& mesh);

/// Something the file asks for that the renderer does not show, said to the user rather than left out
/// silently (stats.not_shown): a glTF extension or a core material feature, where, and what shows instead.
struct NotShown {
    std::string feature; ///< "KHR_materials_clearcoat", "normalTexture", "alphaMode MASK", ...
    std::string detail;  ///< "3 materials ('Paint', 'Glass', 'Trim'): normal maps are not applied ..."
};

struct Scene {
    std::string name; ///< "builtin:cornell" or the file path it came from
    std::vector<Mesh> meshes;
    std::vector<Material> materials; ///< never empty after loading (a default is added)
    std::vector<TextureImage> textures;
    std::vector<Light> lights;
    std::vector<Camera> cameras; ///< never empty after loading (a framing camera is added)
    Bounds bounds;
    std::vector<NotShown> notShown; ///< what the file uses and the renderer does not show
    /// The exposure (EV) the scene's lights were made for, where someone chose it: the built-in
    /// scenes are lit for 0. Empty for files, whose lights come in any units and strengths: the frame
    /// meters them (frame/Exposure.h).
    std::optional<float> authoredExposureEv;

    /// Triangles drawn (an instanced mesh counts once per placement).
    std::size_t triangleCount() const;
    /// Triangles stored (an instanced mesh counts once): what the scene costs in memory.
    std::size_t storedTriangleCount() const;
    /// Placements of instanced meshes (0 when nothing is instanced).
    std::size_t instanceCount() const;
    /// Recomputes bounds from all mesh positions (instanced meshes: their own-space bounds' corners,
    /// placed; a little loose for rotated placements).
    void updateBounds();
};

/// `scene` in world space, for consumers that need world-space triangles (the reference's BVH): each
/// instanced mesh becomes one mesh holding a placed copy per placement, so the meshes keep their
/// indices (a hit's mesh is the same mesh in `scene`).
Scene flattenInstances(const Scene& scene);

/// Moves `mesh`'s attributes by `toWorld` (object -> world): positions by it, normals by its
/// inverse transpose (unit length; a zero or non-finite result stays zero for finalizeScene to
/// replace), tangents by its linear part. A mirroring matrix (negative determinant) also swaps each
/// triangle's winding and the tangents' handedness, so front faces stay CCW (glTF 3.7.4).
void transformMesh(Mesh& mesh, const glm::mat4& toWorld);

} // namespace gis
