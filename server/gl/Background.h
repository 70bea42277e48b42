// GL objects made on a helper thread, in a context that shares the asking thread's objects, while
// the asking thread goes on answering input. llvmpipe zeroes new storage inside the creating call:
// a 447 MB light-tree buffer took 240 ms and 13 views' 512^2 RSM arrays 85-97 ms, each one call that
// no interrupt check can cut. A driver that makes storage at once (NVIDIA's) is ready almost as
// soon as asked; the same path serves both.
//
// Only objects GL shares between contexts may be made there: buffers, textures, samplers, programs.
// Framebuffers and vertex arrays are containers, which stay with the context that made them: the
// asking thread attaches what was made.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "core/Log.h"

namespace gis::gl {

/// Storage of at least this many bytes that a frame input may stop needs is made in the background
/// (its owners' rule): 32 MiB is about 17 ms on llvmpipe at the 447 MB buffer's rate, within a
/// refinement slice.
inline constexpr long long kBackgroundBytes = 32ll << 20;

namespace detail {
/// The thread and shared context behind Background<T>: runs `work` with a context sharing
/// Context::current()'s objects current, then glFinish (the asking context sees the objects once
/// the making one has finished them: GL's rule for shared objects). `work` returns "" or what
/// failed; a GL error after it fails it too. Throws gis::Error when no shared context can be made
/// (none is current on the calling thread, or the driver refuses).
class BackgroundJob {
public:
    explicit BackgroundJob(std::function<std::string()> work);
    ~BackgroundJob(); ///< joins
    BackgroundJob(const BackgroundJob&) = delete;
    BackgroundJob& operator=(const BackgroundJob&) = delete;
    bool done() const;
    void wait();
    const std::string& error() const; ///< after wait(): "" or what failed

private:
    struct State;
    std::unique_ptr<State> mState;
};
} // namespace detail

/// One object (or struct of them) of type T being made in the background.
template <class T> class Background {
public:
    Background() = default;
    /// Starts `make` on a new thread (see the file's header for what it may make).
    static Background start(std::function<T()> make) {
        Background out;
        out.mResult = std::make_unique<std::optional<T>>();
        std::optional<T>* result = out.mResult.get();
        out.mJob = std::make_unique<detail::BackgroundJob>([result, make = std::move(make)]() -> std::string {
            try {
                result->emplace(make());
                return {};
            } catch (const std::exception& e) {
                return e.what();
            }
        });
        return out;
    }
    Background(Background&&) noexcept = default;
    Background& operator=(Background&& other) noexcept {
        if (this != &other) {
            reset();
            mResult = std::move(other.mResult);
            mJob = std::move(other.mJob);
        }
        return *this;
    }
    /// Waits for the helper (at most the rest of one making); what was made and not taken is
    /// deleted here, in the asking context.
    ~Background() { reset(); }

    bool started() const { return static_cast<bool>(mJob); }
    /// Whether the making is over (made or failed); never blocks.
    bool ready() const { return mJob && mJob->done(); }
    /// What was made, waiting for it when not ready; leaves this not started. Nothing when making
    /// failed (error() then says why).
    std::optional<T> take() {
        if (!mJob) return std::nullopt;
        mJob->wait();
        mError = mJob->error();
        std::optional<T> out = mError.empty() ? std::move(*mResult) : std::nullopt;
        reset();
        return out;
    }
    const std::string& error() const { return mError; }

private:
    void reset() {
        mJob.reset(); // joins before the result it writes goes
        mResult.reset();
    }
    std::unique_ptr<std::optional<T>> mResult;
    std::unique_ptr<detail::BackgroundJob> mJob;
    std::string mError;
};

/// Objects of a Key (a size, a shape) made where input may stop the frame: made in the background
/// while `stop` is asked every millisecond. A stop leaves the making going on, and the next call for
/// the same key takes it; a call for another key drops it. A making that fails in the background is
/// made in the frame, with a warning naming `what`.
template <class Key, class T> class BackgroundMaker {
public:
    explicit BackgroundMaker(std::string what) : mWhat(std::move(what)) {}
    /// `make()`'s result for `key`, of `bytes`: made here when `stop` is empty or `bytes` is under
    /// `backgroundBytes`, else in the background. Nothing when `stop` said yes first. `make` runs on
    /// another thread: it must own what it reads.
    template <class Make>
    std::optional<T> make(const Key& key, double bytes, double backgroundBytes,
                          const std::function<bool()>& stop, Make&& make) {
        if (!stop || bytes < backgroundBytes) return make();
        if (mPending.started() && !(mKey == key)) mPending = {};
        if (!mPending.started()) {
            try {
                mPending = Background<T>::start(make);
            } catch (const std::exception& e) {
                failed(e.what());
                return make();
            }
            mKey = key;
            ++mStarts;
        }
        while (!mPending.ready()) {
            if (stop()) return std::nullopt;
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        std::optional<T> made = mPending.take();
        if (made) return made;
        failed(mPending.error());
        return make();
    }
    /// Makings started in the background so far, and those that failed there (made in the frame).
    int starts() const { return mStarts; }
    int failures() const { return mFailures; }

private:
    void failed(const std::string& why) {
        ++mFailures;
        logWarn(mWhat + ": made in the frame, not in the background (" + why + ")");
    }
    std::string mWhat;
    Background<T> mPending;
    Key mKey{};
    int mStarts = 0;
    int mFailures = 0;
};

} // namespace gis::gl
