#include "scene/Scene.h"

#include <limits>

namespace gis {

std::size_t Scene::triangleCount() const {
    std::size_t n = 0;
    for (const auto& m : meshes) n += m.indices.size() / 3;
    return n;
}

void Scene::updateBounds() {
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    bool any = false;
    for (const auto& m : meshes)
        for (const auto& p : m.positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
            any = true;
        }
    bounds = any ? Bounds{lo, hi} : Bounds{};
}

} // namespace gis
