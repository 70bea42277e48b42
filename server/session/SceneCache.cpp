#include "session/SceneCache.h"

#include "scene/SceneLoader.h"

namespace gis {

std::shared_ptr<const Scene> SceneCache::get(const std::string& name, const SceneLoadOptions& options) {
    {
        std::lock_guard lock(mMutex);
        if (auto s = mScenes[name].lock()) return s;
    }
    auto scene = std::make_shared<const Scene>(loadScene(name, options)); // outside the lock: may be slow
    std::lock_guard lock(mMutex);
    if (auto s = mScenes[name].lock()) return s;
    mScenes[name] = scene;
    return scene;
}

std::shared_ptr<const reference::RayScene> SceneCache::planRays(const std::shared_ptr<const Scene>& scene) {
    std::lock_guard lock(mMutex);
    std::erase_if(mPlanRays, [](const auto& entry) { return entry.second.rays.expired(); });
    const auto found = mPlanRays.find(scene.get());
    if (found == mPlanRays.end() || found->second.scene.lock() != scene) return nullptr;
    return found->second.rays.lock();
}

void SceneCache::keepPlanRays(const std::shared_ptr<const Scene>& scene,
                              const std::shared_ptr<const reference::RayScene>& rays) {
    std::lock_guard lock(mMutex);
    mPlanRays[scene.get()] = {scene, rays};
}

} // namespace gis
