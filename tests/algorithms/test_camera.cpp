// The node camera: the bounding sphere exactly fits the square viewport, depth stays inside the
// near/far range, and every view direction (poles included) gives a valid camera.
#include "animorder/camera.h"
#include "animorder/invalid_input.h"
#include "animorder/viewpoints.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace animorder;

TEST(Camera, BoundingSphereJustFitsTheViewport) {
    const float radius = 2.5f;
    const std::vector<float> views = icosphere_directions(2);
    const std::vector<float> points = random_sphere_directions(4000, 3);
    for (size_t v = 0; v < views.size() / 3; v += 9) {
        const Mat4d vp = node_view_projection(&views[3 * v], radius);
        std::vector<float> on_sphere(points.size());
        for (size_t i = 0; i < points.size(); ++i) on_sphere[i] = points[i] * radius;
        std::vector<float> clip(on_sphere.size() / 3 * 4);
        const float origin[3] = {0, 0, 0};
        transform_to_clip(clip.data(), on_sphere.data(), on_sphere.size() / 3, origin, vp);
        double max_extent = 0;
        for (size_t i = 0; i < clip.size() / 4; ++i) {
            const float* c = &clip[4 * i];
            ASSERT_GT(c[3], 0.0f);
            const double x = c[0] / c[3], y = c[1] / c[3], z = c[2] / c[3];
            EXPECT_LE(std::fabs(x), 1.0 + 1e-5);
            EXPECT_LE(std::fabs(y), 1.0 + 1e-5);
            EXPECT_GT(z, -1.0);
            EXPECT_LT(z, 1.0);
            max_extent = std::max({max_extent, std::fabs(x), std::fabs(y)});
        }
        EXPECT_GT(max_extent, 0.98);  // the silhouette reaches the border: the fit is tight
    }
}

TEST(Camera, LooksAtTheOriginFromThreeRadii) {
    const float dir[3] = {0, 0, 1};
    const Mat4d vp = node_view_projection(dir, 1.0f);
    // The origin projects to the viewport centre at eye distance w = 3R.
    EXPECT_NEAR(vp[12], 0.0, 1e-12);
    EXPECT_NEAR(vp[13], 0.0, 1e-12);
    EXPECT_NEAR(vp[15], 3.0, 1e-12);
    // +X in the model appears to the right when looking down −Z with +Y up.
    EXPECT_GT(vp[0], 0.0);
    EXPECT_GT(vp[5], 0.0);
}

TEST(Camera, PolesUseAnotherUpVector) {
    for (float s : {1.0f, -1.0f}) {
        const float dir[3] = {0, s, 0};
        const Mat4d vp = node_view_projection(dir, 1.0f);
        for (double m : vp) EXPECT_TRUE(std::isfinite(m));
        EXPECT_NEAR(vp[15], 3.0, 1e-9);
    }
    const float zero[3] = {0, 0, 1};
    EXPECT_THROW(node_view_projection(zero, 0.0f), InvalidInput);
}
