// The named products of one frame (DESIGN.md §3): each stage publishes the textures it writes under
// a name (`gbuffer.normal`, `lights.rsm.flux`, `direct`, ...) with its format, size and producer,
// and later stages, tests and the stability harness read them by name. Names carry the light index
// so that every light's shadow map and RSM is one more loop iteration, not a copy. Textures stay
// owned by the stage that made them; the table only points at them for the frame.
#pragma once

#include <string>
#include <vector>

#include "gl/Objects.h"

namespace gis {

struct FrameResource {
    std::string name;     ///< "gbuffer.position", "lights.shadow", ...
    std::string producer; ///< the stage that wrote it: "gbuffer", "rsm", "technique", ...
    const gl::Texture* texture = nullptr;
    std::string format; ///< "RGBA32F", "DEPTH32F", ...
    int width = 0, height = 0;
    int layers = 1; ///< array layers (one per light view for the lights.* resources)
};

class FrameResources {
public:
    /// Publishes (or re-points) `name`; the format and size are read from the texture.
    void publish(const std::string& name, const std::string& producer, const gl::Texture& texture);
    /// The texture published as `name`, or nullptr.
    const gl::Texture* find(const std::string& name) const;
    /// The texture published as `name`; asserts that it was (a programmer mistake otherwise).
    const gl::Texture& get(const std::string& name) const;
    /// Drops `name` (a stage that did not run this frame).
    void withdraw(const std::string& name);
    const std::vector<FrameResource>& list() const { return mResources; }

private:
    std::vector<FrameResource> mResources;
};

/// The GL internal format's name ("RGBA16F", "DEPTH32F", ...).
std::string formatName(GLenum internalFormat);

} // namespace gis
