#include "gl/Background.h"

#include <atomic>

#include "core/Error.h"
#include "gl/GlApi.h"
#include "gl/Platform.h"

namespace gis::gl::detail {

struct BackgroundJob::State {
    std::atomic<bool> done{false};
    std::string error; ///< written by the helper before done
    std::thread helper;
};

namespace {
std::string glErrorText(GLenum e) {
    switch (e) {
    case GL_OUT_OF_MEMORY:
        return "GL_OUT_OF_MEMORY";
    case GL_INVALID_ENUM:
        return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE:
        return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION:
        return "GL_INVALID_OPERATION";
    default:
        return "GL error " + std::to_string(e);
    }
}
} // namespace

BackgroundJob::BackgroundJob(std::function<std::string()> work) : mState(std::make_unique<State>()) {
    Context* asking = Context::current();
    if (!asking) throw Error("gl: no context is current on this thread to share objects with");
    std::unique_ptr<Context> shared = asking->createShared();
    State* state = mState.get();
    mState->helper = std::thread([state, work = std::move(work), context = std::move(shared)]() mutable {
        context->makeCurrent();
        std::string error = work();
        if (const GLenum e = glGetError(); e != GL_NO_ERROR && error.empty())
            error = "gl: making objects in the background failed (" + glErrorText(e) + ")";
        glFinish();
        context->releaseCurrent();
        context.reset();
        state->error = std::move(error);
        state->done.store(true, std::memory_order_release);
    });
}

BackgroundJob::~BackgroundJob() {
    wait();
}

bool BackgroundJob::done() const {
    return mState->done.load(std::memory_order_acquire);
}

void BackgroundJob::wait() {
    if (mState->helper.joinable()) mState->helper.join();
}

const std::string& BackgroundJob::error() const {
    return mState->error;
}

} // namespace gis::gl::detail
