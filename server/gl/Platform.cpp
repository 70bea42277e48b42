#include "gl/Platform.h"

#include <cstdlib>
#include <mutex>
#include <optional>

#include "core/Error.h"
#include "gl/LoaderState.h"

namespace gis::gl {

std::unique_ptr<Context> createEglContext();
std::unique_ptr<Context> createOsMesaContext();

Backend parseBackend(const std::string& name) {
    if (name == "egl") return Backend::Egl;
    if (name == "osmesa") return Backend::OsMesa;
    throw InputError("--gl", "unknown GL backend '" + name + "': use 'egl' or 'osmesa'");
}

std::string backendName(Backend backend) { return backend == Backend::Egl ? "egl" : "osmesa"; }

Backend defaultBackend() {
    if (const char* env = std::getenv("GI_GL"); env && *env) {
        try {
            return parseBackend(env);
        } catch (const InputError& e) {
            throw InputError("GI_GL", e.reason());
        }
    }
    return Backend::Egl;
}

namespace {
thread_local Context* tCurrent = nullptr;
} // namespace

Context::~Context() {
    if (tCurrent == this) tCurrent = nullptr;
}

void Context::makeCurrent() {
    bind();
    tCurrent = this;
}

void Context::releaseCurrent() {
    unbind();
    if (tCurrent == this) tCurrent = nullptr;
}

Context* Context::current() { return tCurrent; }

void Context::refreshInfo() { detail::fillContextInfo(mInfo); }

std::unique_ptr<Context> createContext(Backend backend) {
    auto context = backend == Backend::Egl ? createEglContext() : createOsMesaContext();
    tCurrent = context.get(); // both platforms return it current
    return context;
}

namespace detail {
namespace {
std::mutex gLoaderMutex;
std::optional<Backend> gLoadedBackend;
} // namespace

void ensureEntryPoints(Backend backend, GetProcFn getProc) {
    std::lock_guard lock(gLoaderMutex);
    if (gLoadedBackend) {
        if (*gLoadedBackend != backend)
            throw Error("gl: this process already uses the '" + backendName(*gLoadedBackend) +
                        "' backend; EGL and OSMesa cannot be mixed in one process");
        return;
    }
    std::string missing = loadGlEntryPoints(getProc);
    if (!missing.empty())
        throw Error("gl: the " + backendName(backend) + " driver lacks OpenGL 4.5 core entry points: " + missing);
    gLoadedBackend = backend;
}

void fillContextInfo(ContextInfo& info) {
    auto str = [](GLenum name) {
        const GLubyte* s = glGetString(name);
        return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
    };
    info.vendor = str(GL_VENDOR);
    info.renderer = str(GL_RENDERER);
    info.version = str(GL_VERSION);
}
} // namespace detail

} // namespace gis::gl
