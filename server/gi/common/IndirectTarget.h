// The full-resolution RGBA32F indirect-radiance texture every technique returns from indirect(),
// with the framebuffer its last pass renders into.
#pragma once

#include "gl/Objects.h"

namespace gis {

struct IndirectTarget {
    gl::Texture texture;
    gl::Framebuffer framebuffer;

    void resize(int width, int height, const char* label) {
        texture = gl::Texture::create2D(GL_RGBA32F, width, height);
        framebuffer = gl::Framebuffer::of(label, {&texture});
    }
};

} // namespace gis
