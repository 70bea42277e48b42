#include "gl/PassTimer.h"

#include <algorithm>

#include "core/Error.h"

namespace gis::gl {

PassTimer::PassTimer(bool useQueries) : mUseQueries(useQueries) {
    if (mUseQueries) {
        GLint bits = 0;
        glGetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &bits);
        mUseQueries = bits > 0;
    }
}

void PassTimer::beginFrame() {
    GIS_ASSERT(!mOpen);
    mUsed = 0;
    mFrameClock.reset();
}

void PassTimer::begin(const std::string& name) {
    GIS_ASSERT(!mOpen);
    if (mUsed == mSlots.size()) mSlots.push_back({});
    Slot& s = mSlots[mUsed];
    s.name = name;
    s.startMs = mFrameClock.elapsedMs();
    if (mUseQueries) {
        if (!s.query) s.query = Query::create(GL_TIME_ELAPSED);
        glBeginQuery(GL_TIME_ELAPSED, s.query.id());
    } else {
        glFinish();
    }
    mOpen = true;
    mCpu.reset();
}

void PassTimer::end() {
    GIS_ASSERT(mOpen);
    Slot& s = mSlots[mUsed];
    s.cpuMs = mCpu.elapsedMs();
    if (mUseQueries) {
        glEndQuery(GL_TIME_ELAPSED);
    } else {
        glFinish();
        s.fallbackGpuMs = mCpu.elapsedMs();
    }
    mOpen = false;
    ++mUsed;
}

std::vector<PassTiming> PassTimer::resolve() {
    GIS_ASSERT(!mOpen);
    std::vector<PassTiming> out;
    out.reserve(mUsed);
    for (size_t i = 0; i < mUsed; ++i) {
        Slot& s = mSlots[i];
        double gpuMs = s.fallbackGpuMs;
        if (mUseQueries) {
            GLuint64 ns = 0;
            glGetQueryObjectui64v(s.query.id(), GL_QUERY_RESULT, &ns);
            gpuMs = static_cast<double>(ns) * 1e-6;
        }
        // A pass cannot take longer than the wall time from its start to the results being read.
        // llvmpipe sometimes reports an absolute clock for a new context's first pass: replace such
        // a value by the wall time until the next pass started, an upper bound.
        const double nowMs = mFrameClock.elapsedMs();
        if (!(gpuMs <= nowMs - s.startMs + 1.0)) {
            const double nextStart = i + 1 < mUsed ? mSlots[i + 1].startMs : nowMs;
            gpuMs = std::max(nextStart - s.startMs, 0.0);
        }
        out.push_back({s.name, gpuMs, s.cpuMs});
    }
    return out;
}

} // namespace gis::gl
