// The node camera: the bounding sphere exactly fits the square viewport, depth stays inside the
// near/far range, and every view direction (poles included) gives a valid camera.
#include "animorder/camera.h"
#include "animorder/invalid_input.h"
#include "animorder/viewpoints.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
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

// transform_to_clip works in blocks of vertices (and an AVX2 copy where the CPU has it): both
// copies must give, bit for bit, the plain per-vertex statement of a vertex shader's multiply,
// for every count (blocks cut short included) and coordinates of any sign and size.
TEST(Camera, TransformIsThePlainPerVertexProductBitForBit) {
    const float direction[3] = {0.3f, -0.8f, 0.52f};
    const Mat4d vp = node_view_projection(direction, 1.7f);
    float m[16];
    for (int i = 0; i < 16; ++i) m[i] = float(vp[i]);
    const float centre[3] = {0.25f, -1.5f, 3.0f};
    uint32_t state = 7;
    const auto next = [&state] {
        state = state * 1664525u + 1013904223u;
        return float(int32_t(state >> 8) - (1 << 23)) / float(1 << 21);  // about ±4, many bits set
    };
    for (size_t count : {size_t(0), size_t(1), size_t(2), size_t(7), size_t(8), size_t(9), size_t(15), size_t(16),
                         size_t(17), size_t(1001)}) {
        std::vector<float> positions(3 * count);
        for (float& p : positions) p = next();
        std::vector<float> expected(4 * count + 4, -7.0f), simd(4 * count + 4, -7.0f), portable(4 * count + 4, -7.0f);
        for (size_t v = 0; v < count; ++v) {
            const float x = positions[3 * v] - centre[0], y = positions[3 * v + 1] - centre[1],
                        z = positions[3 * v + 2] - centre[2];
            for (int row = 0; row < 4; ++row) {
                volatile float xy = m[row] * x;  // one rounding per operation, whatever the compiler
                volatile float t = m[4 + row] * y;
                volatile float s = xy + t;
                volatile float u = m[8 + row] * z;
                volatile float su = s + u;
                expected[4 * v + row] = su + m[12 + row];
            }
        }
        transform_to_clip(simd.data(), positions.data(), count, centre, vp);
        transform_to_clip_portable(portable.data(), positions.data(), count, centre, vp);
        for (size_t i = 0; i < expected.size(); ++i) {  // the 4 floats past the end stay untouched
            uint32_t a, b, c;
            std::memcpy(&a, &expected[i], 4);
            std::memcpy(&b, &simd[i], 4);
            std::memcpy(&c, &portable[i], 4);
            ASSERT_EQ(a, b) << "count " << count << ", float " << i;
            ASSERT_EQ(a, c) << "count " << count << ", float " << i;
        }
    }
}

// CentredKeyframe: the positions minus the centre, one array per coordinate, bit for bit as
// transform_to_clip's first step (plain float subtractions); kept while the same keyframe follows
// (not centred again: a change in place goes unseen), centred again when the positions (by
// address), their count or the centre change; and the node's matrix rounded to float entry by entry.
TEST(Camera, CentredKeyframeFollowsItsKeyframeAndCentre) {
    std::vector<float> a = {1.5f, -2.25f, 3.0f, 0.1f, 0.2f, 0.3f, -7.0f, 8.5f, 1e-3f};
    std::vector<float> b = {4.0f, 5.0f, 6.0f, 7.0f, 8.0f, 9.0f, 1.0f, 2.0f, 3.0f};
    const float c1[3] = {0.5f, 0.25f, -1.0f}, c2[3] = {0.1f, 0.2f, 0.3f};
    const float direction[3] = {0.0f, 0.6f, 0.8f};
    const Mat4d vp = node_view_projection(direction, 2.0f);
    CentredKeyframe centred;
    const auto expect_centred = [&](const std::vector<float>& p, size_t count, const float* c, const char* what) {
        const NodeRasterizer::CentredVertices v = centred.vertices(vp);
        for (size_t i = 0; i < count; ++i) {
            const float* got[3] = {v.x, v.y, v.z};
            for (int k = 0; k < 3; ++k) {
                const float want = p[3 * i + size_t(k)] - c[k];
                ASSERT_EQ(std::memcmp(&got[k][i], &want, 4), 0) << what << ", vertex " << i << ", coordinate " << k;
            }
        }
        for (int i = 0; i < 16; ++i) ASSERT_EQ(v.view_projection[i], float(vp[size_t(i)])) << what;
    };
    centred.centre(a.data(), 3, c1);
    expect_centred(a, 3, c1, "first keyframe");
    centred.centre(a.data(), 3, c2);
    expect_centred(a, 3, c2, "the same positions, another centre");
    centred.centre(b.data(), 3, c2);
    expect_centred(b, 3, c2, "other positions, the same centre");
    centred.centre(b.data(), 2, c2);
    expect_centred(b, 2, c2, "fewer vertices");
    // The same keyframe again (same address, count and centre): kept, not centred again, so a
    // change made in place is not seen (the contract: positions must not change meanwhile).
    const std::vector<float> before = b;
    b[0] = 100.0f;
    centred.centre(b.data(), 2, c2);
    expect_centred(before, 2, c2, "the same keyframe again");
}
