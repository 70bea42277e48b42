// Temporal stability (digest S.4 case 15, issue #10): a static scene over 100 frames is bit-identical,
// a light moved by 1e-3 of the scene size per frame bounds the frame-to-frame change, and the
// flicker metric of 001 Fig. 5 (the difference between consecutive frames under light motion) is
// reported for grid VPLs (rsm_gather) against the light-space clustering of isr and hier_isr.
#include <cmath>
#include <cstdio>

#include "StabilityLab.h"
#include "StabilityScenes.h"

using namespace gis;
using namespace gis::stability;
namespace sc = gis::stability::scenes;

namespace {

/// The technique's indirect radiance, flattened (RGB only).
std::vector<double> indirectRgb(const Frame& f) {
    std::vector<double> v;
    v.reserve(f.indirect.rgba.size() / 4 * 3);
    for (size_t i = 0; i < f.indirect.rgba.size(); ++i)
        if (i % 4 != 3) v.push_back(f.indirect.rgba[i]);
    return v;
}

/// 001 Fig. 5's flicker measure: mean absolute difference between consecutive frames, relative to
/// the mean value (so techniques of different brightness compare).
double frameDifference(const std::vector<double>& a, const std::vector<double>& b) {
    double diff = 0, level = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        diff += std::abs(a[i] - b[i]);
        level += 0.5 * (a[i] + b[i]);
    }
    return level > 0 ? diff / level : 0.0;
}

class Temporal : public ::testing::TestWithParam<std::string> {
protected:
    void TearDown() override { endCell(HasFailure(), IsSkipped()); }
};

} // namespace

// 100 frames of a static scene: no uninitialised multiresolution texels, no frame-dependent state.
TEST_P(Temporal, C15_Static100Frames) {
    beginCell("C15_Temporal100", GetParam());
    RenderSpec s;
    s.scene = sc::builtin("cornell");
    s.technique = GetParam();
    s.width = 32;
    s.height = 32;
    const Frame first = render(s);
    int differing = 0;
    for (int i = 1; i < 100; ++i) {
        const Frame f = render(s);
        if (f.out.linear != first.out.linear || f.out.rgba8 != first.out.rgba8 ||
            f.indirect.rgba != first.indirect.rgba)
            ++differing;
    }
    EXPECT_EQ(differing, 0) << "frames differing from the first of 100";
    note("frames differing of 100", double(differing));
}

// A light moving 1e-3 of the scene size per frame: the frame-to-frame change stays small and is
// reported as the flicker metric.
TEST_P(Temporal, C15_LightMotionFlicker) {
    beginCell("C15_LightMotion", GetParam());
    const auto cornell = sc::builtin("cornell");
    const float step = 1e-3f * glm::length(cornell->bounds.max - cornell->bounds.min);
    RenderSpec s;
    s.scene = cornell;
    s.technique = GetParam();
    Light light = cornell->lights.front();
    std::vector<double> previous;
    double flicker = 0, worstFinal = 0;
    const int frames = 12;
    std::vector<float> previousFinal;
    for (int i = 0; i < frames; ++i) {
        light.position.x = cornell->lights.front().position.x + step * float(i);
        s.light = light;
        const Frame f = render(s);
        const std::vector<double> cur = indirectRgb(f);
        if (i > 0) {
            flicker += frameDifference(previous, cur) / (frames - 1);
            worstFinal = std::max(worstFinal, relativeRmse(previousFinal, f.out.linear));
        }
        previous = cur;
        previousFinal = f.out.linear;
    }
    note("flicker (001 Fig. 5: mean abs dI / mean I)", flicker);
    note("worst frame-to-frame rel. RMSE (final)", worstFinal);
    std::printf(
        "flicker %s: %.4g (indirect mean |dI|/I per frame), worst final rel. RMSE %.4g, step %.2g m\n",
        GetParam().c_str(), flicker, worstFinal, step);
    // The light moves 3.5 mm per frame in a 2 m box: the image may change by a few per cent at most.
    EXPECT_LT(worstFinal, 0.05);
    EXPECT_LT(flicker, 0.1);
}

INSTANTIATE_TEST_SUITE_P(Cheap, Temporal, ::testing::Values("rsm_gather", "isr", "hier_isr", "second_order"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });
