#include "session/GlWorkerPool.h"

#include <optional>

#include "core/Log.h"
#include "render/FrameRenderer.h"
#include "session/RenderGate.h"

namespace gis {

GlWorkerPool::GlWorkerPool(gl::Backend backend, int workers, std::size_t maxQueued, RenderGate* gate)
    : mBackend(backend), mMaxQueued(maxQueued), mGate(gate) {
    for (int i = 0; i < std::max(1, workers); ++i) mWorkers.emplace_back([this] { workerMain(); });
}

GlWorkerPool::~GlWorkerPool() {
    {
        std::lock_guard lock(mMutex);
        mStop = true;
    }
    if (mGate) mGate->wakeAll();
    mCv.notify_all();
    for (auto& t : mWorkers) t.join();
    for (auto& e : mQueue) e.onFailure("the server is shutting down");
}

bool GlWorkerPool::submit(Job job, Failure onFailure) {
    {
        std::lock_guard lock(mMutex);
        if (mStop || mQueue.size() >= mMaxQueued + mWorkers.size()) return false;
        mQueue.push_back({std::move(job), std::move(onFailure), std::chrono::steady_clock::now()});
    }
    mCv.notify_one();
    return true;
}

std::size_t GlWorkerPool::queued() const {
    std::lock_guard lock(mMutex);
    return mQueue.size();
}

void GlWorkerPool::workerMain() {
    // The context is made on the first job: an idle server holds no GL memory for the API.
    std::unique_ptr<gl::Context> context;
    std::unique_ptr<FrameRenderer> renderer;
    while (true) {
        Entry entry;
        {
            std::unique_lock lock(mMutex);
            mCv.wait(lock, [&] { return mStop || !mQueue.empty(); });
            if (mStop) break;
            entry = std::move(mQueue.front());
            mQueue.pop_front();
        }
        if (!renderer) {
            try {
                context = gl::createContext(mBackend);
                renderer = std::make_unique<FrameRenderer>();
            } catch (const std::exception& e) {
                logError(std::string("render worker: ") + e.what());
                entry.onFailure(std::string("the renderer could not start: ") + e.what());
                context.reset();
                continue;
            }
        }
        std::optional<RenderGate::Permit> permit;
        if (mGate) {
            permit = mGate->acquire(mStop);
            if (!permit) {
                entry.onFailure("the server is shutting down");
                break;
            }
        }
        const double queueMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - entry.queuedAt)
                .count();
        entry.job(*renderer, queueMs);
    }
    renderer.reset(); // GL objects die while the context is current
    context.reset();
}

} // namespace gis
