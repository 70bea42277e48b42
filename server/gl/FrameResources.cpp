#include "gl/FrameResources.h"

#include <algorithm>

#include "core/Error.h"

namespace gis {

std::string formatName(GLenum f) {
    switch (f) {
    case GL_RGBA32F:
        return "RGBA32F";
    case GL_RGBA16F:
        return "RGBA16F";
    case GL_RGBA8:
        return "RGBA8";
    case GL_RG32F:
        return "RG32F";
    case GL_R32F:
        return "R32F";
    case GL_DEPTH_COMPONENT32F:
        return "DEPTH32F";
    case GL_DEPTH24_STENCIL8:
        return "DEPTH24_STENCIL8";
    default:
        return "0x" + std::to_string(f);
    }
}

void FrameResources::publish(const std::string& name, const std::string& producer,
                             const gl::Texture& texture) {
    FrameResource r{name,
                    producer,
                    &texture,
                    formatName(texture.format()),
                    texture.width(),
                    texture.height(),
                    texture.layers()};
    auto it = std::find_if(mResources.begin(), mResources.end(),
                           [&](const FrameResource& x) { return x.name == name; });
    if (it == mResources.end())
        mResources.push_back(std::move(r));
    else
        *it = std::move(r);
}

const gl::Texture* FrameResources::find(const std::string& name) const {
    for (const auto& r : mResources)
        if (r.name == name) return r.texture;
    return nullptr;
}

const gl::Texture& FrameResources::get(const std::string& name) const {
    const gl::Texture* t = find(name);
    GIS_ASSERT_MSG(t != nullptr, "frame resource '" + name + "' was not published this frame");
    return *t;
}

void FrameResources::withdraw(const std::string& name) {
    std::erase_if(mResources, [&](const FrameResource& r) { return r.name == name; });
}

} // namespace gis
