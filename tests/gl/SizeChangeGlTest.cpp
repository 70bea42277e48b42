// A frame of a size used before renders on the targets it had then (gl/RecentTargets.h: the
// renderer's G-buffer, direct and composite targets, the eye hierarchy's atlas): what they still
// hold from that earlier frame must not show in the new one, which must equal a frame on new ones.
#include <gtest/gtest.h>

#include "GlTestSupport.h"

namespace gis::test {
namespace {

void otherView(FrameState& s) {
    s.camera.position = {0.35f, 1.1f, 2.6f};
    s.camera.target = {-0.1f, 0.9f, 0.0f};
}

TEST(SizeChange, TargetsTakenBackShowNothingOfTheirEarlierFrame) {
    for (const char* technique : {"multires_gather", "rsm_gather", "hier_isr"}) {
        SCOPED_TRACE(technique);
        // The first view at 96 x 80, another size, then a different view at 96 x 80 again, on the
        // targets the first view left.
        renderScene("builtin:cornell", technique, 96, 80);
        renderScene("builtin:cornell", technique, 80, 64);
        const FrameOutput takenBack = renderScene("builtin:cornell", technique, 96, 80, {}, otherView);
        // Enough other sizes that 96 x 80's targets are no longer kept: the same view on new ones.
        for (int i = 0; i < 6; ++i) renderScene("builtin:cornell", technique, 64 + 8 * i, 48);
        const FrameOutput fresh = renderScene("builtin:cornell", technique, 96, 80, {}, otherView);
        ASSERT_EQ(takenBack.rgba8.size(), fresh.rgba8.size());
        EXPECT_EQ(takenBack.rgba8, fresh.rgba8);
        EXPECT_EQ(takenBack.linear, fresh.linear);
        EXPECT_EQ(badValues(takenBack), 0u);
    }
}

} // namespace
} // namespace gis::test
