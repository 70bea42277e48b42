#include "scene/Frustum.h"

#include <limits>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

namespace gis {
namespace {

glm::mat4 camera() {
    // At (0, 0, 5) looking down -z, 60 degrees, near 0.1, far 20.
    return glm::perspective(glm::radians(60.0f), 1.0f, 0.1f, 20.0f) *
           glm::lookAt(glm::vec3(0, 0, 5), glm::vec3(0), glm::vec3(0, 1, 0));
}

bool outside(const glm::mat4& m, glm::vec3 centre, float half) {
    return Frustum(m).outside(centre - glm::vec3(half), centre + glm::vec3(half));
}

TEST(Frustum, KeepsWhatTheCameraSeesAndCullsTheRest) {
    const glm::mat4 m = camera();
    EXPECT_FALSE(outside(m, {0, 0, 0}, 0.5f));      // in front
    EXPECT_FALSE(outside(m, {0, 0, 5}, 0.5f));      // around the eye (straddles the near plane)
    EXPECT_TRUE(outside(m, {0, 0, 8}, 0.5f));       // behind the eye
    EXPECT_TRUE(outside(m, {10, 0, 0}, 0.5f));      // far to the right
    EXPECT_TRUE(outside(m, {0, -10, 0}, 0.5f));     // far below
    EXPECT_TRUE(outside(m, {0, 0, -30}, 0.5f));     // beyond the far plane
    EXPECT_FALSE(outside(m, {3.2f, 0, 0}, 0.5f));   // the edge at z = 0 is at x = 5 tan(30) = 2.89
    EXPECT_FALSE(outside(m, {0, 0, -14.8f}, 0.5f)); // reaches the far plane at z = -15
}

TEST(Frustum, OrthographicLightViews) {
    const glm::mat4 m = glm::ortho(-2.0f, 2.0f, -2.0f, 2.0f, 0.5f, 10.0f) *
                        glm::lookAt(glm::vec3(0, 5, 0), glm::vec3(0), glm::vec3(0, 0, -1));
    EXPECT_FALSE(outside(m, {0, 0, 0}, 0.1f));
    EXPECT_FALSE(outside(m, {1.95f, 0, 0}, 0.1f));
    EXPECT_TRUE(outside(m, {2.5f, 0, 0}, 0.1f));
    EXPECT_TRUE(outside(m, {0, 6, 0}, 0.1f)); // above the light: before its near plane
}

TEST(Frustum, NeverCullsOnNonFiniteInput) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_FALSE(Frustum(camera()).outside(glm::vec3(nan), glm::vec3(nan)));
    glm::mat4 bad = camera();
    bad[0][0] = nan;
    bad[0][3] = nan;
    EXPECT_FALSE(Frustum(bad).outside(glm::vec3(10.0f), glm::vec3(11.0f)));
}

} // namespace
} // namespace gis
