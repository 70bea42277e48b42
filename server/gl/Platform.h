// Headless OpenGL 4.5 core contexts. Two implementations behind one interface:
//  - EGL (default): Mesa's surfaceless platform, else EGL_EXT_platform_device (the NVIDIA driver's
//    path; GI_EGL_DEVICE picks the device index), else the default display.
//  - OSMesa: libOSMesa loaded with dlopen, so binaries do not depend on it unless it is used.
// Nothing outside server/gl includes EGL or OSMesa headers. GL entry points come through our
// generated loader (GlApi.h), filled once per process from the first backend used; mixing backends
// in one process is refused with a clear error.
#pragma once

#include <memory>
#include <string>

namespace gis::gl {

enum class Backend { Egl, OsMesa };

Backend parseBackend(const std::string& name); ///< "egl" | "osmesa"; throws gis::InputError
std::string backendName(Backend backend);
/// GI_GL environment variable if set, else EGL.
Backend defaultBackend();

struct ContextInfo {
    std::string backend;  ///< "egl-surfaceless", "egl-device", "osmesa", ...
    std::string vendor;
    std::string renderer;
    std::string version;
};

/// One GL context, current on at most one thread at a time. Not thread-safe itself.
class Context {
public:
    virtual ~Context();
    /// Makes this context current on the calling thread (Context::current() then returns it).
    void makeCurrent();
    void releaseCurrent();
    const ContextInfo& info() const { return mInfo; }
    /// Reads vendor/renderer/version strings; the context must be current.
    void refreshInfo();
    /// A context of the same backend that shares this one's objects (buffers, textures, programs),
    /// current on no thread: for work another thread does while this one goes on
    /// (gl/Background.h). Any thread may call it. Throws gis::Error when the driver refuses.
    virtual std::unique_ptr<Context> createShared() const = 0;
    /// The context made current on the calling thread through this interface (createContext,
    /// makeCurrent), or null.
    static Context* current();

protected:
    virtual void bind() = 0;   ///< the platform's make-current
    virtual void unbind() = 0; ///< the platform's release
    ContextInfo mInfo;
};

/// Creates a context and makes it current on the calling thread. Throws gis::Error naming every
/// display/library that was tried when none works.
std::unique_ptr<Context> createContext(Backend backend);

} // namespace gis::gl
