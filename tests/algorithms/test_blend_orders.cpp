// Back-to-front orders of blended primitives (issue 18): hand-worked clusters, and the
// reversal static methods ship.
#include "animorder/animated_mesh.h"
#include "animorder/blend_orders.h"
#include "animorder/invalid_input.h"
#include "animorder/methods.h"
#include "animorder/viewpoints.h"

#include <gtest/gtest.h>

#include <numeric>
#include <vector>

using namespace animorder;

namespace {

// An opaque triangle (0), then a blended double-sided primitive of three small parallel
// triangles at z = −1, 0, +1 (1, 2, 3), written out of order: z = 0, +1, −1.
AnimatedMesh layers() {
    AnimatedMesh m;
    m.name = "layers";
    const float z[4] = {-5, 0, 1, -1};
    for (int t = 0; t < 4; ++t) {
        const float x = t == 0 ? 3.0f : 0.0f;
        m.keyframe_positions.insert(m.keyframe_positions.end(), {x, 0, z[t], x + 0.1f, 0, z[t], x, 0.1f, z[t]});
        m.indices.insert(m.indices.end(), {uint32_t(3 * t), uint32_t(3 * t + 1), uint32_t(3 * t + 2)});
    }
    m.vertex_count = 12;
    m.primitives = {{"opaque", 0, 3}, {"veil", 3, 9}};
    m.primitives[1].double_sided = true;
    m.primitives[1].alpha_mode = AlphaMode::Blend;
    m.clips = {{"still", 0, 30, 0, 1}};
    return m;
}

}  // namespace

TEST(BlendOrders, EachClusterIsBackToFrontForItsViewsAndFlipsWithThem) {
    const AnimatedMesh mesh = layers();
    Framing framing;
    framing.centres = {0, 0, 0};  // no framing shift: eyes at 3R · direction around the origin
    framing.radii = {10};
    framing.radius = 10;
    ClusteringResult run;
    run.keyframes = {0};
    run.directions = {0, 0, 1, 0, 0, -1};  // node 0 looks from +z, node 1 from −z
    run.assignment = {0, 1};
    std::vector<uint32_t> identity(4);
    std::iota(identity.begin(), identity.end(), 0u);
    run.triangle_orders = {identity, identity};
    blended_orders_from_clusters(mesh, framing, framing.radius, run);
    // From +z the farthest is z = −1 (triangle 3), then z = 0 (1), then z = +1 (2); from −z the
    // reverse. The opaque triangle keeps its place.
    EXPECT_EQ(run.triangle_orders[0], (std::vector<uint32_t>{0, 3, 1, 2}));
    EXPECT_EQ(run.triangle_orders[1], (std::vector<uint32_t>{0, 2, 1, 3}));
    // A cluster no node takes keeps its order.
    run.assignment = {0, 0};
    run.triangle_orders = {identity, identity};
    blended_orders_from_clusters(mesh, framing, framing.radius, run);
    EXPECT_EQ(run.triangle_orders[1], identity);
}

TEST(BlendOrders, StaticMethodsShipBlendedPrimitivesReversed) {
    const AnimatedMesh mesh = layers();
    std::vector<uint32_t> order = {0, 1, 2, 3};
    reverse_blended_primitives(mesh, order);
    EXPECT_EQ(order, (std::vector<uint32_t>{0, 3, 2, 1}));
    std::vector<uint32_t> crossing = {1, 0, 2, 3};  // moves a triangle between primitives
    EXPECT_THROW(reverse_blended_primitives(mesh, crossing), InvalidInput);
    // run_method: the blended range of static-sander07's buffer is run_static_method's, reversed;
    // original keeps the input's.
    const StaticMethodResult sorted = run_static_method(mesh, Method::StaticSander07, {});
    std::vector<uint32_t> expected = sorted.order;
    std::reverse(expected.begin() + 1, expected.end());
    EXPECT_EQ(run_method(mesh, Method::StaticSander07).buffers.orders[0], expected);
    EXPECT_EQ(run_method(mesh, Method::Original).buffers.orders[0],
              run_static_method(mesh, Method::Original, {}).order);
}
