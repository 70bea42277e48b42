// Per-pass timing: a GL_TIME_ELAPSED query around each pass (passes never nest), plus the CPU time
// spent issuing it. Falls back to CPU timing with glFinish when timer queries are unavailable.
#pragma once

#include <string>
#include <vector>

#include "core/Timer.h"
#include "gl/Objects.h"

namespace gis::gl {

struct PassTiming {
    std::string name;
    double gpuMs = 0; ///< GPU time from the timer query (or CPU time through glFinish as fallback)
    double cpuMs = 0; ///< CPU time spent issuing the pass
};

class PassTimer {
public:
    /// `useQueries` false forces the glFinish fallback (also chosen when queries are unsupported).
    explicit PassTimer(bool useQueries = true);
    void beginFrame();
    void begin(const std::string& name);
    void end();
    /// Waits for the results; call after the frame's last pass.
    std::vector<PassTiming> resolve();
    bool usesQueries() const { return mUseQueries; }
    /// Passes begun since beginFrame(): an index into resolve()'s list, so that a caller can tell
    /// which passes one stage of the frame issued.
    size_t passCount() const { return mUsed; }

private:
    struct Slot {
        std::string name;
        Query query;
        double cpuMs = 0;
        double fallbackGpuMs = 0;
        double startMs = 0; ///< wall clock since beginFrame()
    };
    Stopwatch mFrameClock;
    std::vector<Slot> mSlots;
    size_t mUsed = 0;
    bool mUseQueries;
    bool mOpen = false;
    Stopwatch mCpu;
};

} // namespace gis::gl
