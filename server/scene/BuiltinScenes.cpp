// Scenes generated in code, so tests, benchmarks and the default session need no asset files.
// Every surface is a grid of quads (vertex-based effects need more than 2 triangles per wall; the
// bumpy sphere is a latitude/longitude grid) wound CCW as seen from the side its normal points to.
#include "scene/SceneLoader.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "core/Error.h"

namespace gis {
namespace {

constexpr int kWallGrid = 8;
constexpr glm::vec3 kWhite{0.725f, 0.71f, 0.68f};
constexpr glm::vec3 kRed{0.63f, 0.065f, 0.05f};
constexpr glm::vec3 kGreen{0.14f, 0.45f, 0.091f};
constexpr glm::vec3 kGrey{0.8f};
/// Albedo of the black walls: black velvet (about 0.5%), not exactly 0, so the bounce is negligible
/// rather than absent.
constexpr glm::vec3 kBlack{0.005f};

int addMaterial(Scene& scene, const std::string& name, const glm::vec3& albedo) {
    scene.materials.push_back(Material{.name = name, .baseColor = glm::vec4(albedo, 1.0f)});
    return static_cast<int>(scene.materials.size()) - 1;
}

/// Appends an n x n grid spanning origin + [0,1]u + [0,1]v, facing cross(u, v).
void addGrid(Mesh& mesh, const glm::vec3& origin, const glm::vec3& u, const glm::vec3& v, int n) {
    const glm::vec3 normal = glm::normalize(glm::cross(u, v));
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const float s = static_cast<float>(i) / static_cast<float>(n);
            const float t = static_cast<float>(j) / static_cast<float>(n);
            mesh.positions.push_back(origin + s * u + t * v);
            mesh.normals.push_back(normal);
            mesh.texcoords.emplace_back(s, t);
        }
    const auto row = static_cast<std::uint32_t>(n + 1);
    for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(n); ++j)
        for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(n); ++i) {
            const std::uint32_t p00 = base + j * row + i, p10 = p00 + 1, p01 = p00 + row, p11 = p01 + 1;
            mesh.indices.insert(mesh.indices.end(), {p00, p10, p11, p00, p11, p01});
        }
}

Mesh makeGrid(const std::string& name, int material, const glm::vec3& origin, const glm::vec3& u,
              const glm::vec3& v) {
    Mesh mesh{.name = name, .material = material};
    addGrid(mesh, origin, u, v, kWallGrid);
    return mesh;
}

/// Box of the given full size centred at center, turned by yaw about +Y, outward-facing, all 6 faces.
Mesh makeBox(const std::string& name, int material, const glm::vec3& center, const glm::vec3& size,
             float yaw) {
    const glm::mat3 r(glm::rotate(glm::mat4(1.0f), yaw, glm::vec3(0.0f, 1.0f, 0.0f)));
    const glm::vec3 h = 0.5f * size;
    const glm::vec3 x(size.x, 0, 0), y(0, size.y, 0), z(0, 0, size.z);
    struct Face {
        glm::vec3 origin, u, v;
    };
    const Face faces[] = {
        {{h.x, -h.y, -h.z}, y, z}, {{-h.x, -h.y, -h.z}, z, y}, // +x, -x
        {{-h.x, h.y, -h.z}, z, x}, {{-h.x, -h.y, -h.z}, x, z}, // +y, -y
        {{-h.x, -h.y, h.z}, x, y}, {{-h.x, -h.y, -h.z}, y, x}, // +z, -z
    };
    Mesh mesh{.name = name, .material = material};
    for (const Face& f : faces) addGrid(mesh, center + r * f.origin, r * f.u, r * f.v, 2);
    return mesh;
}

Light makeSpot(const std::string& name, const glm::vec3& position, const glm::vec3& direction, float innerDeg,
               float outerDeg) {
    return Light{.name = name,
                 .type = LightType::Spot,
                 .position = position,
                 .direction = glm::normalize(direction),
                 .color = glm::vec3(1.0f),
                 .intensity = 6.0f,
                 .innerConeAngle = glm::radians(innerDeg),
                 .outerConeAngle = glm::radians(outerDeg)};
}

Camera makeCamera(const glm::vec3& position, const glm::vec3& target) {
    return Camera{.name = "default",
                  .position = position,
                  .target = target,
                  .up = glm::vec3(0.0f, 1.0f, 0.0f),
                  .yfovRadians = glm::radians(40.0f),
                  .znear = 0.05f,
                  .zfar = 20.0f};
}

/// Radius factor of the bumpy sphere at polar angle theta (from +Y) and azimuth phi: a sum of
/// sines whose azimuthal terms are weighted by sin(theta), so they fade out smoothly at the poles
/// and the surface has a single well-defined point there. Integer frequencies keep it periodic in
/// phi. Stays within [0.8, 1.2].
double bumpyRadiusFactor(double theta, double phi) {
    const double w = std::sin(theta);
    return 1.0 + 0.12 * w * std::sin(12.0 * theta) * std::sin(12.0 * phi) +
           0.05 * w * std::sin(31.0 * theta) * std::cos(29.0 * phi + 0.7) + 0.03 * std::cos(23.0 * theta);
}

/// Closed sphere of base radius radius with its radius displaced by bumpyRadiusFactor, tessellated
/// as rings x segments latitude/longitude quads (one vertex per pole, the phi seam shared), so it
/// has 2 * segments * (rings - 1) triangles. Shifted so its lowest point sits at y = 0 above the
/// (x, z) position base. Normals are left empty: finalizeScene generates area-weighted vertex
/// normals from the displaced surface, smooth everywhere because every vertex is shared.
Mesh makeBumpySphere(const std::string& name, int material, const glm::vec3& base, float radius, int rings,
                     int segments, bool bumpy = true) {
    Mesh mesh{.name = name, .material = material};
    const double pi = glm::pi<double>();
    auto addVertex = [&](double theta, double phi) {
        const double r = radius * (bumpy ? bumpyRadiusFactor(theta, phi) : 1.0);
        mesh.positions.emplace_back(static_cast<float>(r * std::sin(theta) * std::cos(phi)),
                                    static_cast<float>(r * std::cos(theta)),
                                    static_cast<float>(r * std::sin(theta) * std::sin(phi)));
        mesh.texcoords.emplace_back(static_cast<float>(phi / (2.0 * pi)), static_cast<float>(theta / pi));
    };
    addVertex(0.0, 0.0); // north pole
    for (int j = 1; j < rings; ++j)
        for (int i = 0; i < segments; ++i) addVertex(pi * j / rings, 2.0 * pi * i / segments);
    addVertex(pi, 0.0); // south pole

    const auto seg = static_cast<std::uint32_t>(segments);
    const auto north = 0u, south = static_cast<std::uint32_t>(mesh.positions.size()) - 1;
    auto at = [&](int ring, std::uint32_t i) {
        return 1 + static_cast<std::uint32_t>(ring - 1) * seg + i % seg;
    };
    // Seen from outside, +phi then +theta turns counter-clockwise.
    for (std::uint32_t i = 0; i < seg; ++i)
        mesh.indices.insert(mesh.indices.end(), {north, at(1, i + 1), at(1, i)});
    for (int j = 1; j + 1 < rings; ++j)
        for (std::uint32_t i = 0; i < seg; ++i) {
            const std::uint32_t p00 = at(j, i), p10 = at(j, i + 1), p01 = at(j + 1, i),
                                p11 = at(j + 1, i + 1);
            mesh.indices.insert(mesh.indices.end(), {p00, p10, p11, p00, p11, p01});
        }
    for (std::uint32_t i = 0; i < seg; ++i)
        mesh.indices.insert(mesh.indices.end(), {at(rings - 1, i), at(rings - 1, i + 1), south});

    float minY = 0.0f;
    for (const glm::vec3& p : mesh.positions) minY = std::min(minY, p.y);
    for (glm::vec3& p : mesh.positions) p += glm::vec3(base.x, base.y - minY, base.z);
    return mesh;
}

enum class CornellContents { Boxes, Empty, Dense, Black };

Scene makeCornell(CornellContents contents) {
    Scene scene;
    // The black variant is the empty box with every wall black: the light still lights the view, but
    // nothing bounces it back (the diffuse-bounce decision's negative case).
    const bool black = contents == CornellContents::Black;
    const int white = addMaterial(scene, "white", black ? kBlack : kWhite);
    const int red = addMaterial(scene, "red", black ? kBlack : kRed);
    const int green = addMaterial(scene, "green", black ? kBlack : kGreen);
    const glm::vec3 x(2, 0, 0), y(0, 2, 0), z(0, 0, 2);
    scene.meshes.push_back(makeGrid("floor", white, {-1, 0, -1}, z, x));
    scene.meshes.push_back(makeGrid("ceiling", white, {-1, 2, -1}, x, z));
    scene.meshes.push_back(makeGrid("back_wall", white, {-1, 0, -1}, x, y));
    scene.meshes.push_back(makeGrid("left_wall", red, {-1, 0, -1}, y, z));
    scene.meshes.push_back(makeGrid("right_wall", green, {1, 0, -1}, z, y));
    if (contents == CornellContents::Boxes) {
        scene.meshes.push_back(
            makeBox("short_box", white, {0.35f, 0.3f, 0.3f}, glm::vec3(0.6f), glm::radians(-17.0f)));
        scene.meshes.push_back(
            makeBox("tall_box", white, {-0.35f, 0.6f, -0.35f}, {0.6f, 1.2f, 0.6f}, glm::radians(17.0f)));
    } else if (contents == CornellContents::Dense) {
        // 2 * 256 * 127 = 65024 triangles, about 8 vertices per period of the finest ripple.
        scene.meshes.push_back(makeBumpySphere("bumpy_sphere", white, {0.0f, 0.0f, 0.0f}, 0.5f, 128, 256));
    }
    scene.lights.push_back(makeSpot("ceiling_spot", {0.0f, 1.95f, 0.0f}, {0.0f, -1.0f, 0.0f}, 50.0f, 60.0f));
    scene.cameras.push_back(makeCamera({0.0f, 1.0f, 3.9f}, {0.0f, 1.0f, 0.0f}));
    return scene;
}

/// The non-diffuse gallery (docs/nondiffuse.md): the Cornell room with a glossy floor (metal 0.5,
/// roughness 0.2: environment probe), a planar mirror on the back wall, a smooth gold sphere
/// (roughness 0.15: environment probe), a rough copper block (roughness 0.55: glossy VPL transport)
/// and a cyan marker cube whose reflection the mirror shows at a pixel predictable from geometry.
Scene makeGallery() {
    Scene scene;
    const int white = addMaterial(scene, "white", kWhite);
    const int red = addMaterial(scene, "red", kRed);
    const int green = addMaterial(scene, "green", kGreen);
    auto addPbr = [&](const std::string& name, const glm::vec3& base, float metallic, float roughness) {
        scene.materials.push_back(Material{.name = name,
                                           .baseColor = glm::vec4(base, 1.0f),
                                           .metallic = metallic,
                                           .roughness = roughness,
                                           .specular = 1.0f});
        return static_cast<int>(scene.materials.size()) - 1;
    };
    const int floorMat = addPbr("glossy_floor", {0.5f, 0.45f, 0.4f}, 0.5f, 0.2f);
    const int mirror = addPbr("mirror", {0.95f, 0.95f, 0.95f}, 1.0f, 0.0f);
    const int gold = addPbr("gold", {1.0f, 0.78f, 0.34f}, 1.0f, 0.15f);
    const int copper = addPbr("rough_copper", {0.95f, 0.64f, 0.54f}, 1.0f, 0.55f);
    const int cyan = addMaterial(scene, "marker_cyan", {0.05f, 0.8f, 0.8f});
    const glm::vec3 x(2, 0, 0), y(0, 2, 0), z(0, 0, 2);
    scene.meshes.push_back(makeGrid("floor", floorMat, {-1, 0, -1}, z, x));
    scene.meshes.push_back(makeGrid("ceiling", white, {-1, 2, -1}, x, z));
    scene.meshes.push_back(makeGrid("back_wall", white, {-1, 0, -1}, x, y));
    scene.meshes.push_back(makeGrid("left_wall", red, {-1, 0, -1}, y, z));
    scene.meshes.push_back(makeGrid("right_wall", green, {1, 0, -1}, z, y));
    // 2 cm in front of the back wall, facing +z (towards the camera).
    scene.meshes.push_back(makeGrid("mirror", mirror, {-0.6f, 0.35f, -0.98f}, {1.2f, 0, 0}, {0, 1.2f, 0}));
    scene.meshes.push_back(makeBumpySphere("gold_sphere", gold, {-0.3f, 0.0f, 0.2f}, 0.3f, 32, 64, false));
    scene.meshes.push_back(makeBox("copper_block", copper, {-0.55f, 0.35f, -0.5f}, {0.4f, 0.7f, 0.4f}, 0.3f));
    scene.meshes.push_back(makeBox("marker", cyan, {0.5f, 0.1f, 0.55f}, glm::vec3(0.2f), 0.0f));
    scene.lights.push_back(makeSpot("ceiling_spot", {0.0f, 1.95f, 0.0f}, {0.0f, -1.0f, 0.0f}, 50.0f, 60.0f));
    scene.cameras.push_back(makeCamera({0.0f, 1.0f, 3.9f}, {0.0f, 1.0f, 0.0f}));
    return scene;
}

/// The Cornell room with its boxes lit by one point light under the ceiling instead of the spot: the
/// light reaches the ceiling and all walls directly (every cube face of its shadow map and RSM
/// matters). 2 cd at 0.45 m below the ceiling gives the floor's centre about 0.8 lux, half the
/// spot's, so the default exposure suits it.
Scene makeCornellPoint() {
    Scene scene = makeCornell(CornellContents::Boxes);
    scene.lights.clear();
    scene.lights.push_back(Light{.name = "ceiling_bulb",
                                 .type = LightType::Point,
                                 .position = {0.1f, 1.55f, 0.35f},
                                 .color = glm::vec3(1.0f),
                                 .intensity = 2.0f});
    return scene;
}

/// A closed grey room (2 x 2 x 2 m) with a 0.6 x 0.6 m skylight, lit by a directional sun through
/// it: the sun lights a patch of the floor and the lower back wall, and most of what the camera sees
/// is lit only indirectly (the "room lit mostly indirectly"). A red and a blue box stand in it.
/// 20 lux of sun: about 7 W enter, so the indirectly lit walls get some 0.5 lux.
Scene makeSunRoom() {
    Scene scene;
    const int white = addMaterial(scene, "white", kWhite);
    const int red = addMaterial(scene, "red", kRed);
    const int blue = addMaterial(scene, "blue", {0.08f, 0.15f, 0.55f});
    const glm::vec3 x(2, 0, 0), y(0, 2, 0), z(0, 0, 2);
    scene.meshes.push_back(makeGrid("floor", white, {-1, 0, -1}, z, x));
    scene.meshes.push_back(makeGrid("back_wall", white, {-1, 0, -1}, x, y));
    scene.meshes.push_back(makeGrid("front_wall", white, {1, 0, 1}, -x, y));
    scene.meshes.push_back(makeGrid("left_wall", white, {-1, 0, -1}, y, z));
    scene.meshes.push_back(makeGrid("right_wall", white, {1, 0, -1}, z, y));
    // The ceiling, facing down, around a skylight spanning x, z in [-0.3, 0.3] x [-0.3, 0.3]:
    // four strips.
    const float h = 0.3f;
    auto ceiling = [&](const std::string& name, float x0, float x1, float z0, float z1) {
        scene.meshes.push_back(makeGrid(name, white, {x0, 2, z0}, {x1 - x0, 0, 0}, {0, 0, z1 - z0}));
    };
    ceiling("ceiling_back", -1, 1, -1, -h);
    ceiling("ceiling_front", -1, 1, h, 1);
    ceiling("ceiling_left", -1, -h, -h, h);
    ceiling("ceiling_right", h, 1, -h, h);
    scene.meshes.push_back(
        makeBox("red_box", red, {-0.45f, 0.3f, -0.35f}, {0.5f, 0.6f, 0.5f}, glm::radians(20.0f)));
    scene.meshes.push_back(
        makeBox("blue_box", blue, {0.5f, 0.2f, 0.2f}, {0.35f, 0.4f, 0.35f}, glm::radians(-15.0f)));
    scene.lights.push_back(Light{.name = "sun",
                                 .type = LightType::Directional,
                                 .position = {0.5f, 3.0f, 0.6f},
                                 .direction = glm::normalize(glm::vec3(-0.25f, -1.0f, -0.3f)),
                                 .color = {1.0f, 0.95f, 0.85f},
                                 .intensity = 20.0f});
    // Inside the room, by the front wall, looking at the sunlit patch.
    scene.cameras.push_back(Camera{.name = "default",
                                   .position = {0.55f, 1.3f, 0.92f},
                                   .target = {-0.2f, 0.5f, -0.5f},
                                   .up = glm::vec3(0.0f, 1.0f, 0.0f),
                                   .yfovRadians = glm::radians(70.0f),
                                   .znear = 0.02f,
                                   .zfar = 10.0f});
    return scene;
}

/// The empty Cornell room lit by three coloured lights: a warm spot from a corner, a blue point light
/// near the floor and a faint green directional light through the open front. Each light alone
/// lights a different part, so superposition and the VPL budget's split are visible.
Scene makeCornellColored() {
    Scene scene = makeCornell(CornellContents::Boxes);
    scene.lights.clear();
    Light warm = makeSpot("warm_spot", {0.8f, 1.85f, 0.8f}, {-0.6f, -1.0f, -0.7f}, 25.0f, 40.0f);
    warm.color = {1.0f, 0.6f, 0.3f};
    warm.intensity = 4.0f;
    scene.lights.push_back(warm);
    scene.lights.push_back(Light{.name = "blue_bulb",
                                 .type = LightType::Point,
                                 .position = {-0.6f, 0.35f, 0.6f},
                                 .color = {0.3f, 0.5f, 1.0f},
                                 .intensity = 0.6f,
                                 .range = 3.0f});
    scene.lights.push_back(Light{.name = "green_fill",
                                 .type = LightType::Directional,
                                 .position = {0.0f, 1.0f, 3.0f},
                                 .direction = glm::normalize(glm::vec3(0.2f, -0.3f, -1.0f)),
                                 .color = {0.4f, 1.0f, 0.5f},
                                 .intensity = 0.25f});
    return scene;
}

Scene makeCrease() {
    Scene scene;
    const int grey = addMaterial(scene, "grey", kGrey);
    scene.meshes.push_back(makeGrid("floor", grey, {-1, 0, -1}, {0, 0, 2}, {2, 0, 0}));
    scene.meshes.push_back(makeGrid("wall", grey, {-1, 0, -1}, {0, 2, 0}, {0, 0, 2}));
    scene.lights.push_back(makeSpot("crease_spot", {0.2f, 1.5f, 0.0f}, {-1.0f, -1.0f, 0.0f}, 40.0f, 50.0f));
    scene.cameras.push_back(makeCamera({1.6f, 1.2f, 2.8f}, {-0.6f, 0.4f, 0.0f}));
    return scene;
}

// ---- The atrium: a large scene for the triangle-count benchmarks ---------------------------------

/// Appends a procedural RGBA8 texture (`texel(x, y)` gives each texel) and returns its index.
template <typename Texel>
int addTexture(Scene& scene, const std::string& name, int size, bool srgb, Texel texel) {
    TextureImage image{.width = size, .height = size, .name = name, .srgb = srgb};
    image.rgba.reserve(static_cast<std::size_t>(size) * size * 4);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const glm::u8vec4 c = texel(x, y);
            image.rgba.insert(image.rgba.end(), {c.r, c.g, c.b, c.a});
        }
    scene.textures.push_back(std::move(image));
    return static_cast<int>(scene.textures.size()) - 1;
}

/// A small integer hash in [0, 1): texture variation without a random number generator's state.
float hash01(int x, int y, int salt) {
    std::uint32_t h = static_cast<std::uint32_t>(x) * 374761393u +
                      static_cast<std::uint32_t>(y) * 668265263u +
                      static_cast<std::uint32_t>(salt) * 2246822519u;
    h = (h ^ (h >> 13)) * 1274126177u;
    return static_cast<float>((h ^ (h >> 16)) & 0xffffffu) / 16777216.0f;
}

/// A surface of revolution about +Y through `base`: radius(phi, t) at height t * height, `segments`
/// around (the seam shared) and `rings` up, open at both ends, outward-facing. Normals are left to
/// finalizeScene (smooth, area-weighted).
template <typename Radius>
Mesh makeColumn(const std::string& name, int material, const glm::vec3& base, float height, int segments,
                int rings, Radius radius) {
    Mesh mesh{.name = name, .material = material};
    const float twoPi = glm::two_pi<float>();
    for (int j = 0; j <= rings; ++j)
        for (int i = 0; i < segments; ++i) {
            const float phi = twoPi * static_cast<float>(i) / static_cast<float>(segments);
            const float t = static_cast<float>(j) / static_cast<float>(rings);
            const float r = radius(phi, t);
            mesh.positions.push_back(base + glm::vec3(r * std::cos(phi), t * height, r * std::sin(phi)));
            mesh.texcoords.emplace_back(static_cast<float>(i) / static_cast<float>(segments), t * 4.0f);
        }
    const auto seg = static_cast<std::uint32_t>(segments);
    for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(rings); ++j)
        for (std::uint32_t i = 0; i < seg; ++i) {
            const std::uint32_t p00 = j * seg + i, p10 = j * seg + (i + 1) % seg, p01 = p00 + seg,
                                p11 = p10 + seg;
            // Seen from outside, +phi then +y turns clockwise: wind the other way.
            mesh.indices.insert(mesh.indices.end(), {p00, p11, p10, p00, p01, p11});
        }
    return mesh;
}

/// Part of a torus: the tube of radius `minor` swept `sweep` radians along a circle of radius `major`
/// about `centre`, in the plane spanned by `u` (angle 0) and `v` (angle pi/2), `sweepSegments` x
/// `tubeSegments` quads, outward-facing. A half sweep in a vertical plane is an arch.
Mesh makeTorusPart(const std::string& name, int material, const glm::vec3& centre, const glm::vec3& u,
                   const glm::vec3& v, float major, float minor, float sweep, int sweepSegments,
                   int tubeSegments) {
    Mesh mesh{.name = name, .material = material};
    const glm::vec3 axis = glm::normalize(glm::cross(u, v));
    const bool closed = sweep >= glm::two_pi<float>() - 1e-4f;
    const int along = closed ? sweepSegments : sweepSegments + 1;
    for (int j = 0; j < along; ++j) {
        const float a = sweep * static_cast<float>(j) / static_cast<float>(sweepSegments);
        const glm::vec3 out = std::cos(a) * u + std::sin(a) * v; // from the centre to the tube's axis
        for (int i = 0; i < tubeSegments; ++i) {
            const float b = glm::two_pi<float>() * static_cast<float>(i) / static_cast<float>(tubeSegments);
            const glm::vec3 n = std::cos(b) * out + std::sin(b) * axis;
            mesh.positions.push_back(centre + major * out + minor * n);
            mesh.texcoords.emplace_back(static_cast<float>(j) / static_cast<float>(sweepSegments) * 4.0f,
                                        static_cast<float>(i) / static_cast<float>(tubeSegments));
        }
    }
    const auto tube = static_cast<std::uint32_t>(tubeSegments);
    const auto rows = static_cast<std::uint32_t>(along);
    for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(sweepSegments); ++j)
        for (std::uint32_t i = 0; i < tube; ++i) {
            const std::uint32_t j1 = (j + 1) % rows;
            const std::uint32_t p00 = j * tube + i, p10 = j * tube + (i + 1) % tube, p01 = j1 * tube + i,
                                p11 = j1 * tube + (i + 1) % tube;
            // Seen from outside, +tube angle then +sweep turns clockwise: wind the other way.
            mesh.indices.insert(mesh.indices.end(), {p00, p11, p10, p00, p01, p11});
        }
    return mesh;
}

/// A 16 x 12 x 9 m courtyard open to the sky: two colonnades of fluted columns joined by arches, a
/// fountain ring, a stone floor (texture), ivy on the west wall and a pergola under the open roof
/// (alpha-masked textures), lit by the sun through the pergola. `detail` scales every curved
/// surface's tessellation in both directions (1: about 560k triangles, the triangle count grows
/// with its square).
Scene makeAtrium(double detail) {
    Scene scene;
    auto steps = [&](int full, int least) {
        return std::max(least, static_cast<int>(std::lround(full * detail)));
    };
    const int floorTexture = addTexture(scene, "stone_tiles", 128, true, [](int x, int y) {
        const bool dark = ((x / 64) + (y / 64)) % 2 == 1;
        const float grain = 0.85f + 0.15f * hash01(x / 2, y / 2, 1);
        const bool grout = x % 64 < 2 || y % 64 < 2;
        const glm::vec3 c = grout ? glm::vec3(0.35f)
                                  : (dark ? glm::vec3(0.42f, 0.38f, 0.33f) : glm::vec3(0.8f, 0.76f, 0.68f));
        const glm::vec3 srgb = glm::pow(glm::clamp(c * grain, 0.0f, 1.0f), glm::vec3(1.0f / 2.2f)) * 255.0f;
        return glm::u8vec4(glm::u8vec3(srgb), 255);
    });
    // Leaves: discs at hashed positions in 16 x 16 cells, each opaque inside, cut out between.
    const int ivyTexture = addTexture(scene, "ivy_leaves", 128, true, [](int x, int y) {
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int cx = x / 16 + dx, cy = y / 16 + dy;
                const float px = (static_cast<float>(cx) + hash01(cx, cy, 2)) * 16.0f;
                const float py = (static_cast<float>(cy) + hash01(cx, cy, 3)) * 16.0f;
                const float r = 6.0f + 5.0f * hash01(cx, cy, 4);
                const float d =
                    glm::length(glm::vec2(static_cast<float>(x) - px, static_cast<float>(y) - py));
                if (d < r) {
                    const float g = 0.5f + 0.5f * hash01(cx, cy, 5);
                    return glm::u8vec4(static_cast<std::uint8_t>(40 * g), static_cast<std::uint8_t>(150 * g),
                                       30, 255);
                }
            }
        return glm::u8vec4(30, 90, 20, 0);
    });
    // Slats: a bar along each edge of the tile (a quarter of it), open in between.
    const int latticeTexture = addTexture(scene, "pergola_lattice", 64, true, [](int x, int y) {
        const bool bar = x % 32 < 8 || y % 32 < 6;
        return glm::u8vec4(120, 80, 45, bar ? 255 : 0);
    });

    auto add = [&](Material m) {
        scene.materials.push_back(std::move(m));
        return static_cast<int>(scene.materials.size()) - 1;
    };
    const int stone = add({.name = "stone_floor", .baseColorTexture = floorTexture, .roughness = 0.8f});
    const int plaster = add({.name = "plaster", .baseColor = {0.75f, 0.72f, 0.66f, 1.0f}, .roughness = 0.9f});
    const int marble = add({.name = "marble", .baseColor = {0.85f, 0.83f, 0.8f, 1.0f}, .roughness = 0.5f});
    const int basin = add({.name = "basin", .baseColor = {0.35f, 0.37f, 0.4f, 1.0f}, .roughness = 0.7f});
    const int ivy = add({.name = "ivy",
                         .baseColorTexture = ivyTexture,
                         .roughness = 0.7f,
                         .alphaMode = Material::Alpha::Mask,
                         .alphaCutoff = 0.5f});
    const int pergola = add({.name = "pergola",
                             .baseColorTexture = latticeTexture,
                             .roughness = 0.8f,
                             .alphaMode = Material::Alpha::Mask,
                             .alphaCutoff = 0.5f});

    const float hx = 8.0f, hz = 6.0f, wallHeight = 9.0f;
    auto grid = [&](const std::string& name, int material, glm::vec3 origin, glm::vec3 u, glm::vec3 v, int n,
                    float uvScale) {
        Mesh mesh{.name = name, .material = material};
        addGrid(mesh, origin, u, v, n);
        for (glm::vec2& t : mesh.texcoords) t *= uvScale;
        scene.meshes.push_back(std::move(mesh));
    };
    grid("floor", stone, {-hx, 0, -hz}, {0, 0, 2 * hz}, {2 * hx, 0, 0}, 24, 8.0f);
    grid("back_wall", plaster, {-hx, 0, -hz}, {2 * hx, 0, 0}, {0, wallHeight, 0}, 8, 1.0f);
    grid("front_wall", plaster, {hx, 0, hz}, {-2 * hx, 0, 0}, {0, wallHeight, 0}, 8, 1.0f);
    grid("left_wall", plaster, {-hx, 0, -hz}, {0, wallHeight, 0}, {0, 0, 2 * hz}, 8, 1.0f);
    grid("right_wall", plaster, {hx, 0, -hz}, {0, 0, 2 * hz}, {0, wallHeight, 0}, 8, 1.0f);
    // Ivy on the west wall, facing the default view down the court.
    for (int k = 0; k < 3; ++k) {
        const float z0 = -4.5f + 3.25f * static_cast<float>(k);
        grid("ivy_" + std::to_string(k), ivy, {-hx + 0.08f, 0.5f, z0}, {0, 4.0f, 0}, {0, 0, 2.5f}, 1, 3.0f);
    }
    // Facing down, under the open top: the sun reaches the floor through its gaps.
    grid("pergola", pergola, {-hx, 8.0f, -hz}, {2 * hx, 0, 0}, {0, 0, 2 * hz}, 4, 12.0f);

    // Colonnades: seven fluted columns a row at z = +-3.5, arches between them, a beam along the top.
    const int segments = steps(128, 8), rings = steps(128, 2);
    const float columnBase = 0.25f, columnTop = 4.0f, capital = 0.3f;
    for (float z : {-3.5f, 3.5f}) {
        const std::string side = z < 0.0f ? "north" : "south";
        for (int i = 0; i < 7; ++i) {
            const float x = -6.0f + 2.0f * static_cast<float>(i);
            const std::string id = side + "_" + std::to_string(i);
            scene.meshes.push_back(
                makeColumn("column_" + id, marble, {x, columnBase, z}, columnTop - columnBase, segments,
                           rings, [](float phi, float t) {
                               // Slight entasis and 24 flutes.
                               return 0.26f - 0.03f * t * t + 0.012f * std::cos(24.0f * phi);
                           }));
            scene.meshes.push_back(
                makeBox("base_" + id, marble, {x, columnBase / 2, z}, {0.7f, columnBase, 0.7f}, 0.0f));
            scene.meshes.push_back(makeBox("capital_" + id, marble, {x, columnTop + capital / 2, z},
                                           {0.75f, capital, 0.75f}, 0.0f));
            if (i + 1 < 7)
                scene.meshes.push_back(makeTorusPart("arch_" + id, marble, {x + 1.0f, columnTop + capital, z},
                                                     {1, 0, 0}, {0, 1, 0}, 1.0f, 0.18f, glm::pi<float>(),
                                                     steps(96, 4), steps(32, 4)));
        }
        scene.meshes.push_back(makeBox("beam_" + side, marble, {0.0f, 5.75f, z}, {12.8f, 0.5f, 0.5f}, 0.0f));
    }
    scene.meshes.push_back(makeTorusPart("fountain", basin, {0.0f, 0.25f, 0.0f}, {1, 0, 0}, {0, 0, -1}, 1.2f,
                                         0.25f, glm::two_pi<float>(), steps(256, 8), steps(48, 4)));

    scene.lights.push_back(Light{.name = "sun",
                                 .type = LightType::Directional,
                                 .position = {0.0f, 12.0f, 0.0f},
                                 .direction = glm::normalize(glm::vec3(-0.35f, -1.0f, -0.25f)),
                                 .color = {1.0f, 0.95f, 0.85f},
                                 .intensity = 3.0f});
    scene.cameras.push_back(Camera{.name = "default",
                                   .position = {7.4f, 2.6f, 1.2f},
                                   .target = {-6.0f, 2.2f, -0.8f},
                                   .up = glm::vec3(0.0f, 1.0f, 0.0f),
                                   .yfovRadians = glm::radians(60.0f),
                                   .znear = 0.05f,
                                   .zfar = 60.0f});
    return scene;
}

/// The atrium's detail for about `triangles` triangles (its count grows with detail^2).
double atriumDetail(double triangles) {
    constexpr double kTrianglesAtDetail1 = 560000.0;
    return std::sqrt(std::max(triangles, 1.0) / kTrianglesAtDetail1);
}

} // namespace

std::vector<std::string> builtinSceneNames() {
    return {"cornell", "cornell-empty", "cornell-dense", "crease",          "cornell-black",
            "gallery", "cornell-point", "sun-room",      "cornell-colored", "atrium"};
}

Scene makeBuiltinScene(const std::string& name) {
    Scene scene;
    if (name == "cornell")
        scene = makeCornell(CornellContents::Boxes);
    else if (name == "cornell-empty")
        scene = makeCornell(CornellContents::Empty);
    else if (name == "cornell-dense")
        scene = makeCornell(CornellContents::Dense);
    else if (name == "cornell-black")
        scene = makeCornell(CornellContents::Black);
    else if (name == "crease")
        scene = makeCrease();
    else if (name == "gallery")
        scene = makeGallery();
    else if (name == "cornell-point")
        scene = makeCornellPoint();
    else if (name == "sun-room")
        scene = makeSunRoom();
    else if (name == "cornell-colored")
        scene = makeCornellColored();
    else if (name == "atrium")
        scene = makeAtrium(1.0);
    else if (int k = 0; name.starts_with("atrium-") && name.ends_with("k") &&
                        std::sscanf(name.c_str(), "atrium-%dk", &k) == 1 && k >= 1 && k <= 20000 &&
                        name == "atrium-" + std::to_string(k) + "k")
        // The benchmarks' sizes (docs/scenes.md): atrium-10k .. atrium-2000k, about k thousand triangles.
        scene = makeAtrium(atriumDetail(1000.0 * k));
    else {
        std::string known;
        for (const auto& n : builtinSceneNames()) known += (known.empty() ? "" : ", ") + n;
        throw InputError("builtin:" + name, "unknown built-in scene; known: " + known);
    }
    scene.name = "builtin:" + name;
    scene.authoredExposureEv = 0.0f; // every built-in scene's lights are chosen for the default exposure
    finalizeScene(scene, scene.name);
    return scene;
}

} // namespace gis
