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

} // namespace gis
