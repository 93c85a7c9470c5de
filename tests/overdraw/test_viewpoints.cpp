// Viewpoints and framing: counts, uniformity and determinism; framing by hand.
#include "animorder/invalid_input.h"
#include "animorder/viewpoints.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace animorder;

namespace {
double angle_between(const float* a, const float* b) {
    const double d = double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2];
    return std::acos(std::max(-1.0, std::min(1.0, d)));
}
}  // namespace

TEST(Viewpoints, IcosphereCountsAreUnitAndEvenlySpread) {
    const size_t counts[] = {12, 42, 162, 642};
    for (unsigned level = 0; level < 4; ++level) {
        const std::vector<float> d = icosphere_directions(level);
        ASSERT_EQ(d.size(), counts[level] * 3);
        EXPECT_EQ(icosphere_subdivisions_for(counts[level]), level);
        double min_angle = 10, max_nearest = 0, sx = 0, sy = 0, sz = 0;
        for (size_t i = 0; i < counts[level]; ++i) {
            const float* a = &d[3 * i];
            EXPECT_NEAR(std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), 1.0, 1e-6);
            sx += a[0], sy += a[1], sz += a[2];
            double nearest = 10;
            for (size_t j = 0; j < counts[level]; ++j)
                if (j != i) nearest = std::min(nearest, angle_between(a, &d[3 * j]));
            min_angle = std::min(min_angle, nearest);
            max_nearest = std::max(max_nearest, nearest);
        }
        EXPECT_GT(min_angle, 0.0);                // no duplicates
        EXPECT_LT(max_nearest / min_angle, 1.3);  // nearly uniform spacing
        EXPECT_NEAR(sx, 0.0, 1e-4);               // symmetric: centroid at the origin
        EXPECT_NEAR(sy, 0.0, 1e-4);
        EXPECT_NEAR(sz, 0.0, 1e-4);
    }
    // The icosahedron's neighbours are 63.43° apart.
    const std::vector<float> ico = icosphere_directions(0);
    EXPECT_NEAR(angle_between(&ico[0], &ico[3]), std::atan(2.0), 1e-6);
    EXPECT_THROW(icosphere_subdivisions_for(100), InvalidInput);
}

TEST(Viewpoints, RandomDirectionsAreUniformAndSeeded) {
    const std::vector<float> a = random_sphere_directions(20000, 7);
    EXPECT_EQ(a, random_sphere_directions(20000, 7));
    EXPECT_NE(a, random_sphere_directions(20000, 8));
    double mean[3] = {0, 0, 0};
    size_t upper = 0;
    for (size_t i = 0; i < 20000; ++i) {
        const float* d = &a[3 * i];
        EXPECT_NEAR(std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), 1.0, 1e-5);
        for (int c = 0; c < 3; ++c) mean[c] += d[c] / 20000.0;
        upper += d[1] > 0.5;  // the cap above y = 0.5 holds a quarter of the sphere's area
    }
    for (double m : mean) EXPECT_NEAR(m, 0.0, 0.02);
    EXPECT_NEAR(double(upper) / 20000.0, 0.25, 0.015);
}

TEST(Framing, CentresEachKeyframeOnItsBoxAndTakesTheLargestRadius) {
    // Two keyframes of 4 vertices; vertex 3 is unreferenced and far away: it must not count.
    const std::vector<float> keyframes = {
        0,  0, 0, 2,  0, 0, 0,  4, 0, 100,  100, 100,  // box centre (1, 2, 0), farthest 2.236
        10, 0, 0, 10, 6, 0, 10, 0, 2, -100, 0,   0};   // box centre (10, 3, 1), farthest 3.162
    const std::vector<uint32_t> ib{0, 1, 2};
    const Framing f = frame_keyframes(keyframes.data(), 2, 4, ib.data(), ib.size());
    EXPECT_EQ(f.centres, (std::vector<float>{1, 2, 0, 10, 3, 1}));
    EXPECT_NEAR(f.radius, std::sqrt(10.0), 1e-5);
    EXPECT_GE(double(f.radius), std::sqrt(10.0));
}

TEST(Framing, RejectsNonFinitePositions) {
    const std::vector<float> keyframes = {0, 0, 0, 1, 0, 0, 0, NAN, 0};
    const std::vector<uint32_t> ib{0, 1, 2};
    EXPECT_THROW(frame_keyframes(keyframes.data(), 1, 3, ib.data(), 3), InvalidInput);
}
