#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>

#include "core/Error.h"
#include "core/Log.h"
#include "gl/LoaderState.h"
#include "gl/Platform.h"

#ifndef EGL_PLATFORM_SURFACELESS_MESA
#define EGL_PLATFORM_SURFACELESS_MESA 0x31DD
#endif

namespace gis::gl {
namespace {

std::string eglErrorText() {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04x", static_cast<unsigned>(eglGetError()));
    return buf;
}

bool hasExtension(const char* list, const char* name) {
    if (!list) return false;
    size_t n = std::strlen(name);
    for (const char* p = list; (p = std::strstr(p, name)); p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
    return false;
}

// One display per process, initialised once and shared by every session's context: terminating it
// when one session ends would destroy the others' contexts.
struct SharedDisplay {
    EGLDisplay display = EGL_NO_DISPLAY;
    std::string kind;
    std::string error;
};

SharedDisplay openDisplay() {
    SharedDisplay out;
    std::string tried;
    const char* clientExt = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    auto getPlatformDisplay =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    auto tryInit = [&](EGLDisplay d, const std::string& kind) {
        EGLint major = 0, minor = 0;
        if (d != EGL_NO_DISPLAY && eglInitialize(d, &major, &minor)) {
            out.display = d;
            out.kind = kind;
            return true;
        }
        tried += (tried.empty() ? "" : "; ") + kind + " (" + (d == EGL_NO_DISPLAY ? "no display" : eglErrorText()) + ")";
        return false;
    };
    const char* deviceEnv = std::getenv("GI_EGL_DEVICE");
    if (!deviceEnv && getPlatformDisplay && hasExtension(clientExt, "EGL_MESA_platform_surfaceless")) {
        if (tryInit(getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr),
                    "egl-surfaceless"))
            return out;
    }
    if (getPlatformDisplay && hasExtension(clientExt, "EGL_EXT_platform_device")) {
        auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        EGLDeviceEXT devices[16];
        EGLint count = 0;
        if (queryDevices && queryDevices(16, devices, &count) && count > 0) {
            int first = 0, last = count - 1;
            if (deviceEnv) first = last = std::atoi(deviceEnv);
            for (int i = first; i <= last && i < count && i >= 0; ++i)
                if (tryInit(getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr),
                            "egl-device" + std::to_string(i)))
                    return out;
        } else {
            tried += (tried.empty() ? "" : "; ") + std::string("egl-device (no devices)");
        }
    }
    if (tryInit(eglGetDisplay(EGL_DEFAULT_DISPLAY), "egl-default")) return out;
    out.error = "gl: no EGL display could be initialised (tried: " + tried +
                "). Install libegl1-mesa-dev/libgl1-mesa-dri, or use --gl osmesa";
    return out;
}

const SharedDisplay& sharedDisplay() {
    static std::once_flag once;
    static SharedDisplay display;
    std::call_once(once, [] { display = openDisplay(); });
    return display;
}

const EGLint kContextAttribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                  EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};

class EglContext final : public Context {
public:
    EglContext(EGLDisplay display, EGLConfig config, EGLContext context, const std::string& kind)
        : mDisplay(display), mConfig(config), mContext(context) {
        mInfo.backend = kind;
    }
    ~EglContext() override {
        if (eglGetCurrentContext() == mContext) eglMakeCurrent(mDisplay, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(mDisplay, mContext);
    }
    std::unique_ptr<Context> createShared() const override {
        // The rendering API is per thread in EGL: the calling thread may not have bound it yet.
        if (!eglBindAPI(EGL_OPENGL_API)) throw Error("gl: eglBindAPI(EGL_OPENGL_API) failed (" + eglErrorText() + ")");
        EGLContext shared = eglCreateContext(mDisplay, mConfig, mContext, kContextAttribs);
        if (shared == EGL_NO_CONTEXT)
            throw Error("gl: eglCreateContext sharing objects failed on " + mInfo.backend + " (" +
                        eglErrorText() + ")");
        auto result = std::make_unique<EglContext>(mDisplay, mConfig, shared, mInfo.backend);
        result->mInfo = mInfo;
        return result;
    }

private:
    void bind() override {
        eglBindAPI(EGL_OPENGL_API);
        if (!eglMakeCurrent(mDisplay, EGL_NO_SURFACE, EGL_NO_SURFACE, mContext))
            logError("gl: eglMakeCurrent failed (" + eglErrorText() + ")");
    }
    void unbind() override { eglMakeCurrent(mDisplay, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT); }

    EGLDisplay mDisplay;
    EGLConfig mConfig;
    EGLContext mContext;
};

GlProc eglGetProc(const char* name) { return reinterpret_cast<GlProc>(eglGetProcAddress(name)); }

} // namespace

std::unique_ptr<Context> createEglContext() {
    const SharedDisplay& shared = sharedDisplay();
    if (shared.display == EGL_NO_DISPLAY) throw Error(shared.error);
    EGLDisplay display = shared.display;
    if (!eglBindAPI(EGL_OPENGL_API)) throw Error("gl: eglBindAPI(EGL_OPENGL_API) failed: no desktop OpenGL in EGL");

    EGLConfig config = nullptr;
    EGLint count = 0;
    for (EGLint surfaceType : {EGL_PBUFFER_BIT, 0}) {
        const EGLint attribs[] = {EGL_SURFACE_TYPE, surfaceType, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_RED_SIZE, 8,
                                  EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_ALPHA_SIZE, 8, EGL_NONE};
        if (eglChooseConfig(display, attribs, &config, 1, &count) && count > 0) break;
    }
    if (count < 1) throw Error("gl: no EGL config with desktop OpenGL on " + shared.kind + " (" + eglErrorText() + ")");

    EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, kContextAttribs);
    if (context == EGL_NO_CONTEXT)
        throw Error("gl: eglCreateContext(OpenGL 4.5 core) failed on " + shared.kind + " (" + eglErrorText() + ")");
    auto result = std::make_unique<EglContext>(display, config, context, shared.kind);
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context))
        throw Error("gl: eglMakeCurrent without a surface failed on " + shared.kind + " (" + eglErrorText() + ")");
    detail::ensureEntryPoints(Backend::Egl, eglGetProc);
    result->refreshInfo();
    return result;
}

} // namespace gis::gl
