// Back-to-front orders of blended primitives (issue 18): hand-worked clusters, the measured
// order from hand-written fragments, and the reversal static methods ship.
#include "animorder/animated_mesh.h"
#include "animorder/blend_orders.h"
#include "animorder/invalid_input.h"
#include "animorder/methods.h"
#include "animorder/rasterizer.h"
#include "animorder/viewpoints.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
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

namespace {

// A node's transparent pass written by hand: each pixel's blended triangles nearest first
// (kTieBit-style top bit: the same depth as the previous fragment).
BlendFragments hand_node(const std::vector<std::vector<uint32_t>>& pixels) {
    BlendFragments f;
    f.covered = pixels.size();
    f.starts.push_back(0);
    for (size_t p = 0; p < pixels.size(); ++p) {
        f.pixels.push_back(uint32_t(p));
        f.fragments.insert(f.fragments.end(), pixels[p].begin(), pixels[p].end());
        f.starts.push_back(uint32_t(f.fragments.size()));
    }
    return f;
}

uint64_t missorted_pairs(const BlendFragments& node, const std::vector<uint32_t>& order) {
    std::vector<uint32_t> rank(order.size());
    for (size_t i = 0; i < order.size(); ++i) rank[order[i]] = uint32_t(i);
    BlendCounts c;
    score_blend(&c, node, rank.data(), 1);
    return c.missorted_pairs;
}

constexpr uint32_t kTie = 0x80000000u;

}  // namespace

TEST(BlendOrders, MeasuredOrderMinimisesMissortedPairsOverTheClustersNodes) {
    const AnimatedMesh mesh = layers();  // triangle 0 opaque, 1..3 blended
    // Cluster 0's node: 3 in front of 2 in three pixels, 2 in front of 1 in two (and behind it in
    // one), 1 in front of 3 in two, and a pixel where 1 and 2 tie (no pair). A pair is mis-sorted
    // when its nearer triangle is drawn first; by hand, for each back-to-front order of 1, 2, 3:
    // 1,2,3: 1 + 2 = 3; 1,3,2: 3 + 1 + 2 = 6; 2,1,3: 2 + 2 = 4; 2,3,1: 2; 3,1,2: 3 + 1 = 4;
    // 3,2,1: 3 + 2 = 5. The least: 2, 3, 1 (the distance sort has no say: these are fragments).
    const BlendFragments cluster0 =
        hand_node({{3, 2}, {3, 2}, {3, 2}, {2, 1}, {2, 1}, {1, 2}, {1, 3}, {1, 3}, {1, 2 | kTie}});
    // Cluster 1's node sees the layers the other way: 1 in front of 2 in front of 3.
    const BlendFragments cluster1 = hand_node({{1, 2}, {2, 3}, {1, 3}});
    std::vector<uint32_t> identity = {0, 1, 2, 3};
    std::vector<std::vector<uint32_t>> orders = {identity, identity, identity};  // cluster 2: no node
    measured_blended_orders(mesh, {cluster0, cluster1}, {0, 1}, orders, 1);
    EXPECT_EQ(orders[0], (std::vector<uint32_t>{0, 2, 3, 1}));
    EXPECT_EQ(missorted_pairs(cluster0, orders[0]), 2u);
    EXPECT_EQ(orders[1], (std::vector<uint32_t>{0, 3, 2, 1}));  // back to front: 3, 2, 1
    EXPECT_EQ(missorted_pairs(cluster1, orders[1]), 0u);
    EXPECT_EQ(orders[2], identity);  // a cluster without nodes keeps its order
    // Independent check: no permutation of the blended triangles mis-sorts fewer pairs.
    std::vector<uint32_t> blended = {1, 2, 3};
    uint64_t least = UINT64_MAX;
    do {
        least = std::min(least, missorted_pairs(cluster0, {0, blended[0], blended[1], blended[2]}));
    } while (std::next_permutation(blended.begin(), blended.end()));
    EXPECT_EQ(least, 2u);
    // Both nodes in one cluster: their pixels add up (cluster 1's three pairs against cluster 0's).
    orders = {identity};
    measured_blended_orders(mesh, {cluster0, cluster1}, {0, 0}, orders, 1);
    blended = {1, 2, 3};
    least = UINT64_MAX;
    do {
        const std::vector<uint32_t> o = {0, blended[0], blended[1], blended[2]};
        least = std::min(least, missorted_pairs(cluster0, o) + missorted_pairs(cluster1, o));
    } while (std::next_permutation(blended.begin(), blended.end()));
    EXPECT_EQ(missorted_pairs(cluster0, orders[0]) + missorted_pairs(cluster1, orders[0]), least);
    // Mismatched inputs are refused.
    EXPECT_THROW(measured_blended_orders(mesh, {cluster0}, {0, 1}, orders, 1), InvalidInput);
}
