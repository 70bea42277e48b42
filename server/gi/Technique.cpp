#include "gi/Technique.h"

#include "core/Error.h"

namespace gis {

const gl::Texture& FrameInputs::get(const std::string& name) const {
    GIS_ASSERT(resources != nullptr);
    return resources->get(name);
}

bool FrameInputs::complete() const {
    for (const char* name : {"gbuffer.position", "gbuffer.normal", "gbuffer.albedo", "direct"})
        if (!find(name)) return false;
    return find("lights.rsm.position") != nullptr;
}

} // namespace gis
