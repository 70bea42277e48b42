// Scenes shared read-only by every session: loaded once per name, kept while anyone holds them; and
// what sessions derive from each at some cost, kept while a session holds it, so a second session on
// the same scene does not build it again: the effect planner's ray structure and the levels of detail.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "render/SceneGpu.h"
#include "scene/Scene.h"
#include "scene/SceneLoader.h"

namespace gis {
namespace reference {
class RayScene;
}

class SceneCache {
public:
    /// Loads (or returns the cached) scene; throws gis::InputError from the loader. Scenes are cached
    /// by `name` (a builtin: name or an absolute path); `options` apply when it is loaded.
    std::shared_ptr<const Scene> get(const std::string& name, const SceneLoadOptions& options = {});

    /// The planner's ray structure of `scene` that a session built and still holds, or null.
    std::shared_ptr<const reference::RayScene> planRays(const std::shared_ptr<const Scene>& scene);
    /// Offers `rays` (built from `scene`) to the sessions that plan on the same scene later.
    void keepPlanRays(const std::shared_ptr<const Scene>& scene,
                      const std::shared_ptr<const reference::RayScene>& rays);
    /// The same for the levels of detail (SceneGpu::prepareLevels of `scene`).
    std::shared_ptr<const SceneGpu::LodSet> levels(const std::shared_ptr<const Scene>& scene);
    void keepLevels(const std::shared_ptr<const Scene>& scene,
                    const std::shared_ptr<const SceneGpu::LodSet>& levels);

private:
    std::mutex mMutex;
    std::map<std::string, std::weak_ptr<const Scene>> mScenes;
    /// By the scene's address, with the scene itself to tell a new scene at a reused address.
    template <typename T> struct Kept {
        std::weak_ptr<const Scene> scene;
        std::weak_ptr<const T> value;
    };
    template <typename T> using KeptMap = std::map<const Scene*, Kept<T>>;
    /// What `map` keeps for `scene` and someone still holds; drops what nobody holds. Under mMutex.
    template <typename T>
    static std::shared_ptr<const T> findKept(KeptMap<T>& map, const std::shared_ptr<const Scene>& scene);
    KeptMap<reference::RayScene> mPlanRays;
    KeptMap<SceneGpu::LodSet> mLevels;
};

} // namespace gis
