#include "gl/Objects.h"

#include "core/Error.h"
#include "core/Log.h"

namespace gis::gl {

Buffer Buffer::create(GLsizeiptr bytes, const void* data, GLbitfield flags) {
    GLuint id = 0;
    glCreateBuffers(1, &id);
    glNamedBufferStorage(id, bytes, data, flags);
    Buffer b(id);
    b.mSize = bytes;
    return b;
}

void Buffer::upload(GLintptr offset, GLsizeiptr bytes, const void* data) {
    GIS_ASSERT(offset >= 0 && offset + bytes <= mSize);
    glNamedBufferSubData(id(), offset, bytes, data);
}

BufferTexture BufferTexture::create() {
    GLuint id = 0;
    glCreateTextures(GL_TEXTURE_BUFFER, 1, &id);
    return BufferTexture(id);
}

void BufferTexture::view(const Buffer& buffer, GLenum internalFormat, GLintptr offset, GLsizeiptr bytes) {
    GIS_ASSERT(offset >= 0 && offset % 256 == 0 && bytes > 0 && offset + bytes <= buffer.size());
    glTextureBufferRange(id(), internalFormat, buffer.id(), offset, bytes);
}

Texture Texture::allocate(GLenum target, GLenum internalFormat, int width, int height, int levels,
                          int layers) {
    GLuint id = 0;
    glCreateTextures(target, 1, &id);
    if (target == GL_TEXTURE_2D_ARRAY)
        glTextureStorage3D(id, levels, internalFormat, width, height, layers);
    else
        glTextureStorage2D(id, levels, internalFormat, width, height);
    Texture t(id);
    t.mWidth = width;
    t.mHeight = height;
    t.mLevels = levels;
    t.mLayers = target == GL_TEXTURE_2D_ARRAY ? layers : target == GL_TEXTURE_CUBE_MAP ? 6 : 1;
    t.mFormat = internalFormat;
    t.setWrap(GL_CLAMP_TO_EDGE);
    return t;
}

Texture Texture::create2DArray(GLenum internalFormat, int width, int height, int layers) {
    GIS_ASSERT(width > 0 && height > 0 && layers > 0);
    Texture t = allocate(GL_TEXTURE_2D_ARRAY, internalFormat, width, height, 1, layers);
    t.setFilter(GL_NEAREST, GL_NEAREST);
    return t;
}

Texture Texture::create2D(GLenum internalFormat, int width, int height, int levels) {
    GIS_ASSERT(width > 0 && height > 0 && levels > 0);
    Texture t = allocate(GL_TEXTURE_2D, internalFormat, width, height, levels, 1);
    t.setFilter(GL_NEAREST, GL_NEAREST);
    return t;
}

Texture Texture::createCube(GLenum internalFormat, int size, int levels) {
    GIS_ASSERT(size > 0 && levels > 0);
    Texture t = allocate(GL_TEXTURE_CUBE_MAP, internalFormat, size, size, levels, 1);
    t.setFilter(GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR);
    glTextureParameteri(t.id(), GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    glTextureParameteri(t.id(), GL_TEXTURE_MAX_LEVEL, levels - 1);
    return t;
}

void Texture::setFilter(GLenum minFilter, GLenum magFilter) {
    glTextureParameteri(id(), GL_TEXTURE_MIN_FILTER, static_cast<GLint>(minFilter));
    glTextureParameteri(id(), GL_TEXTURE_MAG_FILTER, static_cast<GLint>(magFilter));
}

void Texture::setWrap(GLenum wrap) {
    glTextureParameteri(id(), GL_TEXTURE_WRAP_S, static_cast<GLint>(wrap));
    glTextureParameteri(id(), GL_TEXTURE_WRAP_T, static_cast<GLint>(wrap));
}

void Texture::generateMipmap() {
    glGenerateTextureMipmap(id());
}

Framebuffer Framebuffer::create() {
    GLuint id = 0;
    glCreateFramebuffers(1, &id);
    return Framebuffer(id);
}

Framebuffer Framebuffer::of(const std::string& label, std::initializer_list<const Texture*> colors,
                            const Texture* depth) {
    Framebuffer fbo = create();
    int index = 0;
    for (const Texture* t : colors) fbo.attachColor(index++, *t);
    if (depth) {
        if (depth->format() == GL_DEPTH24_STENCIL8)
            fbo.attachDepthStencil(*depth);
        else
            fbo.attachDepth(*depth);
    }
    fbo.finish(index, label);
    return fbo;
}

Framebuffer Framebuffer::ofLayer(const std::string& label, std::initializer_list<const Texture*> colors,
                                 const Texture* depth, int layer) {
    Framebuffer fbo = create();
    int index = 0;
    for (const Texture* t : colors) fbo.attachColorLayer(index++, *t, layer);
    if (depth) fbo.attachDepthLayer(*depth, layer);
    fbo.finish(index, label + " (layer " + std::to_string(layer) + ")");
    return fbo;
}

void Framebuffer::attachColor(int index, const Texture& texture, int level) {
    glNamedFramebufferTexture(id(), GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(index), texture.id(), level);
}

void Framebuffer::attachDepth(const Texture& texture, int level) {
    glNamedFramebufferTexture(id(), GL_DEPTH_ATTACHMENT, texture.id(), level);
}

void Framebuffer::attachDepthStencil(const Texture& texture, int level) {
    glNamedFramebufferTexture(id(), GL_DEPTH_STENCIL_ATTACHMENT, texture.id(), level);
}

void Framebuffer::attachColorLayer(int index, const Texture& texture, int layer, int level) {
    glNamedFramebufferTextureLayer(id(), GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(index), texture.id(),
                                   level, layer);
}

void Framebuffer::attachDepthLayer(const Texture& texture, int layer, int level) {
    glNamedFramebufferTextureLayer(id(), GL_DEPTH_ATTACHMENT, texture.id(), level, layer);
}

bool Framebuffer::tryFinish(int colorCount) {
    GLenum buffers[8];
    GIS_ASSERT(colorCount >= 0 && colorCount <= 8);
    for (int i = 0; i < colorCount; ++i) buffers[i] = GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i);
    if (colorCount == 0)
        glNamedFramebufferDrawBuffer(id(), GL_NONE);
    else
        glNamedFramebufferDrawBuffers(id(), colorCount, buffers);
    return glCheckNamedFramebufferStatus(id(), GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
}

void Framebuffer::finish(int colorCount, const std::string& label) {
    GLenum buffers[8];
    GIS_ASSERT(colorCount >= 0 && colorCount <= 8);
    for (int i = 0; i < colorCount; ++i) buffers[i] = GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i);
    if (colorCount == 0)
        glNamedFramebufferDrawBuffer(id(), GL_NONE);
    else
        glNamedFramebufferDrawBuffers(id(), colorCount, buffers);
    GLenum status = glCheckNamedFramebufferStatus(id(), GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
        throw Error("gl: framebuffer '" + label + "' is incomplete (status 0x" + std::to_string(status) +
                    ")");
}

VertexArray VertexArray::create() {
    GLuint id = 0;
    glCreateVertexArrays(1, &id);
    return VertexArray(id);
}

Query Query::create(GLenum target) {
    GLuint id = 0;
    glCreateQueries(target, 1, &id);
    return Query(id);
}

TransformFeedback TransformFeedback::create() {
    GLuint id = 0;
    glCreateTransformFeedbacks(1, &id);
    return TransformFeedback(id);
}

Sampler Sampler::create() {
    GLuint id = 0;
    glCreateSamplers(1, &id);
    return Sampler(id);
}

namespace {
std::string collectErrors() {
    std::string errors;
    for (int i = 0; i < 16; ++i) {
        GLenum e = glGetError();
        if (e == GL_NO_ERROR) break;
        char buf[16];
        std::snprintf(buf, sizeof buf, "0x%04x", e);
        errors += (errors.empty() ? "" : ", ") + std::string(buf);
    }
    return errors;
}
} // namespace

void checkErrors(const char* where) {
    std::string e = collectErrors();
    if (!e.empty()) throw Error(std::string("gl: error ") + e + " in " + where);
}

bool logErrors(const char* where) {
    std::string e = collectErrors();
    if (e.empty()) return true;
    logError(std::string("gl: error ") + e + " in " + where);
    return false;
}

} // namespace gis::gl
