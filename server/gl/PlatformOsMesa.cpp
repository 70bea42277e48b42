#include <dlfcn.h>

#include <mutex>
#include <string>
#include <vector>

#include "core/Error.h"
#include "gl/LoaderState.h"
#include "gl/Platform.h"

namespace gis::gl {
namespace {

// The few OSMesa declarations we need, from GL/osmesa.h (Mesa's stable ABI). That header includes
// the legacy GL/gl.h, which would hide half of glcorearb.h's typedefs from our loader.
using OSMesaContext = struct osmesa_context*;
using OSMESAproc = void (*)();
constexpr int OSMESA_RGBA = GL_RGBA;
constexpr int OSMESA_FORMAT = 0x22;
constexpr int OSMESA_DEPTH_BITS = 0x30;
constexpr int OSMESA_STENCIL_BITS = 0x31;
constexpr int OSMESA_ACCUM_BITS = 0x32;
constexpr int OSMESA_PROFILE = 0x33;
constexpr int OSMESA_CORE_PROFILE = 0x34;
constexpr int OSMESA_CONTEXT_MAJOR_VERSION = 0x36;
constexpr int OSMESA_CONTEXT_MINOR_VERSION = 0x37;

using CreateContextAttribsFn = OSMesaContext (*)(const int*, OSMesaContext);
using MakeCurrentFn = GLboolean (*)(OSMesaContext, void*, GLenum, GLsizei, GLsizei);
using DestroyContextFn = void (*)(OSMesaContext);
using GetProcAddressFn = OSMESAproc (*)(const char*);

struct OsMesaLibrary {
    void* handle = nullptr;
    CreateContextAttribsFn createContextAttribs = nullptr;
    MakeCurrentFn makeCurrent = nullptr;
    DestroyContextFn destroyContext = nullptr;
    GetProcAddressFn getProcAddress = nullptr;
    std::string error;
};

const OsMesaLibrary& library() {
    static std::once_flag once;
    static OsMesaLibrary lib;
    std::call_once(once, [] {
        std::string tried;
        for (const char* name : {"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"}) {
            lib.handle = dlopen(name, RTLD_NOW | RTLD_LOCAL);
            if (lib.handle) break;
            tried += std::string(tried.empty() ? "" : ", ") + name;
        }
        if (!lib.handle) {
            lib.error = "gl: OSMesa is not available (tried " + tried + "). Install libosmesa6, or use --gl egl";
            return;
        }
        lib.createContextAttribs =
            reinterpret_cast<CreateContextAttribsFn>(dlsym(lib.handle, "OSMesaCreateContextAttribs"));
        lib.makeCurrent = reinterpret_cast<MakeCurrentFn>(dlsym(lib.handle, "OSMesaMakeCurrent"));
        lib.destroyContext = reinterpret_cast<DestroyContextFn>(dlsym(lib.handle, "OSMesaDestroyContext"));
        lib.getProcAddress = reinterpret_cast<GetProcAddressFn>(dlsym(lib.handle, "OSMesaGetProcAddress"));
        if (!lib.createContextAttribs || !lib.makeCurrent || !lib.destroyContext || !lib.getProcAddress)
            lib.error = "gl: libOSMesa lacks OSMesaCreateContextAttribs (needs Mesa >= 12 built with core profiles)";
    });
    return lib;
}

GlProc osmesaGetProc(const char* name) { return reinterpret_cast<GlProc>(library().getProcAddress(name)); }

const int kContextAttribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 8,
                               OSMESA_ACCUM_BITS, 0, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                               OSMESA_CONTEXT_MAJOR_VERSION, 4, OSMESA_CONTEXT_MINOR_VERSION, 5, 0};

class OsMesaContextImpl final : public Context {
public:
    explicit OsMesaContextImpl(OSMesaContext ctx) : mContext(ctx), mBuffer(kSize * kSize * 4) { mInfo.backend = "osmesa"; }
    ~OsMesaContextImpl() override { library().destroyContext(mContext); }
    std::unique_ptr<Context> createShared() const override {
        OSMesaContext shared = library().createContextAttribs(kContextAttribs, mContext);
        if (!shared) throw Error("gl: OSMesaCreateContextAttribs sharing objects failed");
        auto result = std::make_unique<OsMesaContextImpl>(shared);
        result->mInfo = mInfo;
        return result;
    }

private:
    // OSMesa needs a client colour buffer to make a context current, even when all rendering
    // goes to framebuffer objects; a tiny one suffices.
    void bind() override { library().makeCurrent(mContext, mBuffer.data(), GL_UNSIGNED_BYTE, kSize, kSize); }
    void unbind() override { library().makeCurrent(nullptr, nullptr, GL_UNSIGNED_BYTE, 0, 0); }

    static constexpr int kSize = 4;
    OSMesaContext mContext;
    std::vector<unsigned char> mBuffer;
};

} // namespace

std::unique_ptr<Context> createOsMesaContext() {
    const OsMesaLibrary& lib = library();
    if (!lib.error.empty()) throw Error(lib.error);
    OSMesaContext ctx = lib.createContextAttribs(kContextAttribs, nullptr);
    if (!ctx) throw Error("gl: OSMesaCreateContextAttribs(OpenGL 4.5 core) failed");
    auto result = std::make_unique<OsMesaContextImpl>(ctx);
    result->makeCurrent();
    detail::ensureEntryPoints(Backend::OsMesa, osmesaGetProc);
    result->refreshInfo();
    return result;
}

} // namespace gis::gl
