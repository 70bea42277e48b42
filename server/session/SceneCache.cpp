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

template <typename T>
std::shared_ptr<const T> SceneCache::findKept(KeptMap<T>& map, const std::shared_ptr<const Scene>& scene) {
    std::erase_if(map, [](const auto& entry) { return entry.second.value.expired(); });
    const auto found = map.find(scene.get());
    if (found == map.end() || found->second.scene.lock() != scene) return nullptr;
    return found->second.value.lock();
}

std::shared_ptr<const reference::RayScene> SceneCache::planRays(const std::shared_ptr<const Scene>& scene) {
    std::lock_guard lock(mMutex);
    return findKept(mPlanRays, scene);
}

void SceneCache::keepPlanRays(const std::shared_ptr<const Scene>& scene,
                              const std::shared_ptr<const reference::RayScene>& rays) {
    std::lock_guard lock(mMutex);
    mPlanRays[scene.get()] = {scene, rays};
}

std::shared_ptr<const SceneGpu::LodSet> SceneCache::levels(const std::shared_ptr<const Scene>& scene) {
    std::lock_guard lock(mMutex);
    return findKept(mLevels, scene);
}

void SceneCache::keepLevels(const std::shared_ptr<const Scene>& scene,
                            const std::shared_ptr<const SceneGpu::LodSet>& levels) {
    std::lock_guard lock(mMutex);
    mLevels[scene.get()] = {scene, levels};
}

} // namespace gis
