// The procedural test meshes: sizes, closed manifolds, outward winding, no degenerate triangles.
#include "animorder/animated_mesh.h"
#include "animorder/procedural_shapes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

using namespace animorder;

namespace {
double signed_volume(const AnimatedMesh& m, size_t keyframe) {
    const float* p = m.keyframe(keyframe);
    double v = 0;
    for (size_t t = 0; t < m.indices.size(); t += 3) {
        const float *a = p + 3 * m.indices[t], *b = p + 3 * m.indices[t + 1], *c = p + 3 * m.indices[t + 2];
        v += (double(a[0]) * (double(b[1]) * c[2] - double(b[2]) * c[1]) -
              double(a[1]) * (double(b[0]) * c[2] - double(b[2]) * c[0]) +
              double(a[2]) * (double(b[0]) * c[1] - double(b[1]) * c[0])) /
             6.0;
    }
    return v;
}

// Every directed edge once and its twin present: closed, consistently wound 2-manifold.
bool closed_and_consistent(const AnimatedMesh& m) {
    std::map<std::pair<uint32_t, uint32_t>, int> edges;
    for (size_t t = 0; t < m.indices.size(); t += 3)
        for (int i = 0; i < 3; ++i) ++edges[{m.indices[t + i], m.indices[t + (i + 1) % 3]}];
    for (const auto& [e, count] : edges)
        if (count != 1 || !edges.count({e.second, e.first})) return false;
    return true;
}

double smallest_area(const AnimatedMesh& m) {
    const float* p = m.keyframe(0);
    double smallest = INFINITY;
    for (size_t t = 0; t < m.indices.size(); t += 3) {
        const float *a = p + 3 * m.indices[t], *b = p + 3 * m.indices[t + 1], *c = p + 3 * m.indices[t + 2];
        const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        smallest = std::min(smallest, 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]));
    }
    return smallest;
}

// One primitive over the whole buffer and one clip "static" of one keyframe, valid.
void expect_static_layout(const AnimatedMesh& m) {
    EXPECT_NO_THROW(validate_animated_mesh(m));
    ASSERT_EQ(m.primitives.size(), 1u);
    EXPECT_EQ(m.primitives[0].index_count, m.indices.size());
    ASSERT_EQ(m.clips.size(), 1u);
    EXPECT_EQ(m.clips[0].name, "static");
    EXPECT_EQ(m.clips[0].keyframe_count, 1u);
    EXPECT_EQ(m.keyframe_count(), 1u);
}
}  // namespace

TEST(ProceduralShapes, StaticLayout) {
    expect_static_layout(make_uv_sphere(1000));
    expect_static_layout(make_torus_knot(1000, 3, 5));
}

TEST(ProceduralShapes, SphereIsClosedOutwardAndNearTheTargetSize) {
    for (size_t target : {10000u, 50000u, 200000u}) {
        const AnimatedMesh s = make_uv_sphere(target);
        EXPECT_NEAR(double(s.triangle_count()), double(target), 0.03 * target);
        EXPECT_TRUE(closed_and_consistent(s));
        EXPECT_NEAR(signed_volume(s, 0), 4.0 / 3.0 * M_PI, 0.01 * 4.0 / 3.0 * M_PI);  // unit sphere, outward
        EXPECT_GT(smallest_area(s), 0.0);
        EXPECT_EQ(s.keyframe_count(), 1u);
    }
}

TEST(ProceduralShapes, TorusKnotIsClosedOutwardAndNearTheTargetSize) {
    for (size_t target : {10000u, 50000u, 200000u}) {
        const AnimatedMesh k = make_torus_knot(target);
        EXPECT_NEAR(double(k.triangle_count()), double(target), 0.03 * target);
        EXPECT_TRUE(closed_and_consistent(k));
        // A tube of radius 0.4 along the curve: volume ≈ π·0.4²·(curve length), positive.
        EXPECT_GT(signed_volume(k, 0), 10.0);
        EXPECT_GT(smallest_area(k), 0.0);
    }
}
