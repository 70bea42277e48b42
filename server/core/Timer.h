#pragma once

#include <chrono>

namespace gis {

/// Wall-clock stopwatch in milliseconds (steady clock).
class Stopwatch {
public:
    Stopwatch() : mStart(std::chrono::steady_clock::now()) {}
    void reset() { mStart = std::chrono::steady_clock::now(); }
    double elapsedMs() const {
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - mStart).count();
    }

private:
    std::chrono::steady_clock::time_point mStart;
};

} // namespace gis
