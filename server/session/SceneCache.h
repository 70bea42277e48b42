// Scenes shared read-only by every session: loaded once per name, kept while anyone holds them.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "scene/Scene.h"
#include "scene/SceneLoader.h"

namespace gis {

class SceneCache {
public:
    /// Loads (or returns the cached) scene; throws gis::InputError from the loader. Scenes are cached
    /// by `name` (a builtin: name or an absolute path); `options` apply when it is loaded.
    std::shared_ptr<const Scene> get(const std::string& name, const SceneLoadOptions& options = {});

private:
    std::mutex mMutex;
    std::map<std::string, std::weak_ptr<const Scene>> mScenes;
};

} // namespace gis
