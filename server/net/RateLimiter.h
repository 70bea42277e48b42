// Owns per-client request throttling: a thread-safe token bucket with an injectable clock.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <stdexcept>

namespace gis {

/// Token bucket: holds up to `burst` tokens (starting full), refilled at `ratePerSecond`; each
/// allowed event takes one. A rate of 0 disables limiting.
class RateLimiter {
public:
    /// Throws std::invalid_argument for a negative or non-finite rate or burst. A burst below 1 is
    /// raised to 1, since a bucket that can never hold a whole token would refuse everything.
    RateLimiter(double ratePerSecond, double burst)
        : mRate(ratePerSecond), mBurst(std::max(burst, 1.0)), mTokens(mBurst) {
        if (!(ratePerSecond >= 0) || !std::isfinite(ratePerSecond) || !(burst >= 0) || !std::isfinite(burst))
            throw std::invalid_argument("RateLimiter: rate and burst must be finite and >= 0");
    }

    /// Takes a token if one is available at `nowSeconds` (any monotonic origin, fixed per limiter).
    /// Time that goes backwards refills nothing and does not move the reference point, so a clock
    /// step back cannot mint tokens when time moves forward again.
    bool allow(double nowSeconds) {
        if (mRate == 0) return true;
        std::lock_guard lock(mMutex);
        if (!mStarted) {
            mStarted = true;
            mLast = nowSeconds;
        } else if (nowSeconds > mLast) {
            mTokens = std::min(mBurst, mTokens + (nowSeconds - mLast) * mRate);
            mLast = nowSeconds;
        }
        // Refills computed from inexact intervals (0.3 - 0.2 = 0.0999...) can land a hair under a
        // whole token; a tiny tolerance keeps "rate 10, one call per 0.1 s" always allowed.
        if (mTokens < 1 - 1e-9) return false;
        mTokens = std::max(0.0, mTokens - 1);
        return true;
    }

    /// allow() on std::chrono::steady_clock.
    bool allow() {
        using Seconds = std::chrono::duration<double>;
        return allow(
            std::chrono::duration_cast<Seconds>(std::chrono::steady_clock::now().time_since_epoch()).count());
    }

    double ratePerSecond() const { return mRate; }
    double burst() const { return mBurst; }

private:
    const double mRate;
    const double mBurst;
    std::mutex mMutex;
    double mTokens;
    double mLast = 0;
    bool mStarted = false;
};

} // namespace gis
