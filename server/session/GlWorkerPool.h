// Render workers for one-shot jobs (POST /api/render): a few threads, each with its own GL context
// and FrameRenderer created on first use, a bounded queue, and the server's RenderGate so that API
// renders and interactive sessions share one admission cap. A full queue refuses new jobs at once
// (the HTTP layer answers 503) instead of letting latency grow without bound.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "gl/Platform.h"

namespace gis {

class FrameRenderer;
class RenderGate;

class GlWorkerPool {
public:
    /// A job runs on a worker with its renderer, while holding a render permit. It must not throw
    /// (errors are the job's to report); `queueMs` is how long it waited for a worker and a permit.
    using Job = std::function<void(FrameRenderer& renderer, double queueMs)>;
    /// Called instead of the job when the worker cannot start a GL context.
    using Failure = std::function<void(const std::string& message)>;

    GlWorkerPool(gl::Backend backend, int workers, std::size_t maxQueued, RenderGate* gate);
    ~GlWorkerPool();
    GlWorkerPool(const GlWorkerPool&) = delete;
    GlWorkerPool& operator=(const GlWorkerPool&) = delete;

    /// Queues a job; false when `maxQueued` jobs already wait (nothing is queued then).
    bool submit(Job job, Failure onFailure);
    std::size_t queued() const;

private:
    struct Entry {
        Job job;
        Failure onFailure;
        std::chrono::steady_clock::time_point queuedAt;
    };
    void workerMain();

    const gl::Backend mBackend;
    const std::size_t mMaxQueued;
    RenderGate* mGate;
    mutable std::mutex mMutex;
    std::condition_variable mCv;
    std::deque<Entry> mQueue;
    std::atomic<bool> mStop{false};
    std::vector<std::thread> mWorkers;
};

} // namespace gis
