// Scenes generated in code, so tests, benchmarks and the default session need no asset files.
// Every surface is a grid of quads (vertex-based effects need more than 2 triangles per wall; the
// bumpy sphere is a latitude/longitude grid) wound CCW as seen from the side its normal points to.
#include "scene/SceneLoader.h"

#include <algorithm>
#include <cmath>

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

} // namespace

std::vector<std::string> builtinSceneNames() {
    return {"cornell", "cornell-empty", "cornell-dense", "crease",         "cornell-black",
            "gallery", "cornell-point", "sun-room",      "cornell-colored"};
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
    else {
        std::string known;
        for (const auto& n : builtinSceneNames()) known += (known.empty() ? "" : ", ") + n;
        throw InputError("builtin:" + name, "unknown built-in scene; known: " + known);
    }
    scene.name = "builtin:" + name;
    finalizeScene(scene, scene.name);
    return scene;
}

} // namespace gis
