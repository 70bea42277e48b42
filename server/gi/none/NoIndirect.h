// Technique `none`: direct light only. The baseline every GI technique's cost and error is read
// against; it runs no pass and adds no radiance.
#pragma once

#include "gi/Technique.h"

namespace gis {

class NoIndirect final : public Technique {
public:
    void resize(int, int) override {}
    void execute(const FrameInputs&, const ParamSet&, gl::PassTimer&, Counters&) override {}
    const gl::Texture* indirect() const override { return nullptr; }
};

} // namespace gis
