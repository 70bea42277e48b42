// Move-only RAII owners of GL objects. Destructors delete (the owning context must be current);
// a default-constructed owner holds nothing and needs no context, so GL-free code can hold them.
// Only server/gl and the pass code that issues draw calls read id().
#pragma once

#include <initializer_list>
#include <string>
#include <utility>

#include "gl/GlApi.h"

namespace gis::gl {

template <class Traits> class Object {
public:
    Object() = default;
    explicit Object(GLuint id) : mId(id) {}
    ~Object() { reset(); }
    Object(const Object&) = delete;
    Object& operator=(const Object&) = delete;
    Object(Object&& o) noexcept : mId(std::exchange(o.mId, 0)) {}
    Object& operator=(Object&& o) noexcept {
        if (this != &o) {
            reset();
            mId = std::exchange(o.mId, 0);
        }
        return *this;
    }
    GLuint id() const { return mId; }
    explicit operator bool() const { return mId != 0; }
    void reset() {
        if (mId) Traits::destroy(mId);
        mId = 0;
    }
    /// Gives up ownership without deleting.
    GLuint release() { return std::exchange(mId, 0); }

private:
    GLuint mId = 0;
};

struct BufferTraits {
    static void destroy(GLuint id) { glDeleteBuffers(1, &id); }
};
struct TextureTraits {
    static void destroy(GLuint id) { glDeleteTextures(1, &id); }
};
struct FramebufferTraits {
    static void destroy(GLuint id) { glDeleteFramebuffers(1, &id); }
};
struct VertexArrayTraits {
    static void destroy(GLuint id) { glDeleteVertexArrays(1, &id); }
};
struct ProgramTraits {
    static void destroy(GLuint id) { glDeleteProgram(id); }
};
struct QueryTraits {
    static void destroy(GLuint id) { glDeleteQueries(1, &id); }
};
struct TransformFeedbackTraits {
    static void destroy(GLuint id) { glDeleteTransformFeedbacks(1, &id); }
};
struct SamplerTraits {
    static void destroy(GLuint id) { glDeleteSamplers(1, &id); }
};

class Buffer : public Object<BufferTraits> {
public:
    Buffer() = default;
    /// Immutable-size storage (glNamedBufferStorage with dynamic updates allowed).
    static Buffer create(GLsizeiptr bytes, const void* data = nullptr,
                         GLbitfield flags = GL_DYNAMIC_STORAGE_BIT);
    GLsizeiptr size() const { return mSize; }
    void upload(GLintptr offset, GLsizeiptr bytes, const void* data);

private:
    using Object::Object;
    GLsizeiptr mSize = 0;
};

class Texture : public Object<TextureTraits> {
public:
    Texture() = default;
    static Texture create2D(GLenum internalFormat, int width, int height, int levels = 1);
    static Texture create2DArray(GLenum internalFormat, int width, int height, int layers);
    /// A cube map of `size`^2 texels per face and `levels` mip levels, filtered for samplerCube:
    /// trilinear minification, linear magnification, clamp-to-edge on all three axes.
    static Texture createCube(GLenum internalFormat, int size, int levels);
    int width() const { return mWidth; }
    int height() const { return mHeight; }
    GLenum format() const { return mFormat; }
    int levels() const { return mLevels; }
    int layers() const { return mLayers; } ///< array layers (6 for a cube map, 1 for a 2D texture)
    /// Nearest or linear filtering and clamp-to-edge wrapping.
    void setFilter(GLenum minFilter, GLenum magFilter);
    void setWrap(GLenum wrap);
    /// Fills levels 1.. from level 0 (box filter).
    void generateMipmap();

private:
    using Object::Object;
    /// Immutable storage of `target` (2D, 2D array or cube) with clamp-to-edge wrapping.
    static Texture allocate(GLenum target, GLenum internalFormat, int width, int height, int levels,
                            int layers);
    int mWidth = 0, mHeight = 0, mLevels = 0, mLayers = 0;
    GLenum mFormat = 0;
};

/// A buffer's bytes read as texels (GL_TEXTURE_BUFFER; samplerBuffer in GLSL): a view, not a copy,
/// so the buffer must outlive the texture's use.
class BufferTexture : public Object<TextureTraits> {
public:
    BufferTexture() = default;
    static BufferTexture create();
    /// Views `bytes` of `buffer` from `offset` as `internalFormat` texels. `offset` must be a multiple
    /// of 256, the largest GL_TEXTURE_BUFFER_OFFSET_ALIGNMENT an implementation may ask for.
    void view(const Buffer& buffer, GLenum internalFormat, GLintptr offset, GLsizeiptr bytes);

private:
    using Object::Object;
};

class Framebuffer : public Object<FramebufferTraits> {
public:
    Framebuffer() = default;
    static Framebuffer create();
    /// A complete target: `colors` at attachments 0.., `depth` (a GL_DEPTH24_STENCIL8 texture is
    /// attached as depth and stencil) and the draw buffers selected; throws gis::Error naming `label`.
    static Framebuffer of(const std::string& label, std::initializer_list<const Texture*> colors,
                          const Texture* depth = nullptr);
    /// of() for layer `layer` of array textures: that layer of every colour texture and of `depth`.
    static Framebuffer ofLayer(const std::string& label, std::initializer_list<const Texture*> colors,
                               const Texture* depth, int layer);
    void attachColor(int index, const Texture& texture, int level = 0);
    void attachDepth(const Texture& texture, int level = 0);
    void attachDepthStencil(const Texture& texture, int level = 0); ///< GL_DEPTH24_STENCIL8 texture
    /// Attaches one layer of an array texture, or one face (layer 0..5: +X, -X, +Y, -Y, +Z, -Z) of a
    /// cube map, as colour attachment `index`.
    void attachColorLayer(int index, const Texture& texture, int layer, int level = 0);
    /// Attaches one layer of a depth array texture as the depth attachment.
    void attachDepthLayer(const Texture& texture, int layer, int level = 0);
    /// Selects the draw buffers 0..count-1 and checks completeness; throws gis::Error naming `label`.
    void finish(int colorCount, const std::string& label);
    /// finish() for targets (re)allocated on the per-frame path, which never throws: returns whether
    /// the framebuffer is complete.
    [[nodiscard]] bool tryFinish(int colorCount);

private:
    using Object::Object;
};

class VertexArray : public Object<VertexArrayTraits> {
public:
    VertexArray() = default;
    static VertexArray create();

private:
    using Object::Object;
};

class Query : public Object<QueryTraits> {
public:
    Query() = default;
    static Query create(GLenum target);

private:
    using Object::Object;
};

class TransformFeedback : public Object<TransformFeedbackTraits> {
public:
    TransformFeedback() = default;
    static TransformFeedback create();

private:
    using Object::Object;
};

class Sampler : public Object<SamplerTraits> {
public:
    Sampler() = default;
    static Sampler create();

private:
    using Object::Object;
};

/// Throws gis::Error when glGetError reports anything; `where` names the pass.
void checkErrors(const char* where);
/// Like checkErrors but only logs: for the per-frame path, which never throws. Returns false on error.
bool logErrors(const char* where);

} // namespace gis::gl
