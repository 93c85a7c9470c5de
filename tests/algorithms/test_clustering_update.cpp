// The k-means update step alone (Han & Sander 2017, Algorithm 1 lines 20–24): a cluster's
// patches sorted by the integrated distance d(p), checked against distances worked out by hand.
// These are independent references: every expected order below follows from the numbers in the
// comments, not from the library.
#include "animorder/animated_mesh.h"
#include "animorder/clustering.h"
#include "animorder/invalid_input.h"
#include "animorder/mesh_patches.h"
#include "animorder/viewpoints.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

using namespace animorder;

namespace {

// Four single-triangle patches at two keyframes. Patch centroids (already framed):
//   keyframe row 0: P0 = (0,0,0)  P1 = (2,0,0)  P2 = (0,2,0)  P3 = (1,1,1)
//   keyframe row 1: P0 = (0,0,1)  P1 = (0,0,0)  P2 = (1,0,0)  P3 = (0,1,0)
const std::vector<float> kCentroids = {
    0, 0, 0, 2, 0, 0, 0, 2, 0, 1, 1, 1,  // row 0
    0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0,  // row 1
};
constexpr size_t kKeyframes = 2, kPatches = 4;

// Three nodes (keyframe row, eye):  n0 = (0, (2,2,0))  n1 = (0, (0,0,3))  n2 = (1, (0,0,3)).
// Distances |eye − centroid|:
//          P0               P1                P2                P3
//   n0  |(2,2,0)|=√8≈2.828 |(0,2,0)|=2      |(2,0,0)|=2       |(1,1,−1)|=√3≈1.732
//   n1  |(0,0,3)|=3       |(−2,0,3)|=√13≈3.606 |(0,−2,3)|=√13≈3.606 |(−1,−1,2)|=√6≈2.449
//   n2  |(0,0,2)|=2       |(0,0,3)|=3      |(−1,0,3)|=√10≈3.162 |(0,−1,3)|=√10≈3.162
const std::vector<uint32_t> kNodeKeyframes = {0, 0, 1};
const std::vector<float> kNodeEyes = {2, 2, 0, 0, 0, 3, 0, 0, 3};

// I3D visibility: each patch is one triangle with these normals (a triangle faces the eye when
// normal · (eye − centroid) > 0, the rule cluster_nodes applies to every triangle of a patch):
//   row 0: P0 (−1,−1,1)  P1 (0,1,1)  P2 (1,0,−1)  P3 (3,0,2)
//   row 1: P0 (0,0,1)    P1 (0,0,−1) P2 (1,0,0)   P3 (0,0,1)
//   n0: P0 (2,2,0)·(−1,−1,1) = −4 no   P1 (0,2,0)·(0,1,1) = 2 yes
//       P2 (2,0,0)·(1,0,−1) = 2 yes    P3 (1,1,−1)·(3,0,2) = 1 yes
//   n1: P0 (0,0,3)·(−1,−1,1) = 3 yes   P1 (−2,0,3)·(0,1,1) = 3 yes
//       P2 (0,−2,3)·(1,0,−1) = −3 no   P3 (−1,−1,2)·(3,0,2) = 1 yes
//   n2: P0 (0,0,2)·(0,0,1) = 2 yes     P1 (0,0,3)·(0,0,−1) = −3 no
//       P2 (−1,0,3)·(1,0,0) = −1 no    P3 (0,−1,3)·(0,0,1) = 3 yes
const std::vector<uint8_t> kVisible = {
    0, 1, 1, 1,  // n0
    1, 1, 0, 1,  // n1
    1, 0, 0, 1,  // n2
};

std::vector<uint32_t> order_of(const std::vector<uint32_t>& node_keyframes, const std::vector<float>& eyes,
                               DistanceVariant variant, const uint8_t* visible = nullptr,
                               const uint32_t* primitive = nullptr) {
    return integrated_distance_order(kCentroids.data(), kKeyframes, kPatches, node_keyframes.data(), eyes.data(),
                                     node_keyframes.size(), variant, visible, primitive);
}

TEST(ClusteringUpdate, JcgtSumsDistancesOverAllNodes) {
    // d(P0) = √8 + 3 + 2 ≈ 7.828, d(P1) = 2 + √13 + 3 ≈ 8.606,
    // d(P2) = 2 + √13 + √10 ≈ 8.768, d(P3) = √3 + √6 + √10 ≈ 7.344  →  P3, P0, P1, P2.
    EXPECT_EQ(order_of(kNodeKeyframes, kNodeEyes, DistanceVariant::Jcgt), (std::vector<uint32_t>{3, 0, 1, 2}));
}

TEST(ClusteringUpdate, JcgtOneNodeBreaksTiesByPatchId) {
    // Only n0: P3 √3 ≈ 1.732 < P1 2 = P2 2 (tie: lower id first) < P0 √8 ≈ 2.828.
    EXPECT_EQ(order_of({0}, {2, 2, 0}, DistanceVariant::Jcgt), (std::vector<uint32_t>{3, 1, 2, 0}));
}

TEST(ClusteringUpdate, JcgtIgnoresVisibility) {
    // The JCGT distance counts every node, facing or not: the same order as with no flags.
    EXPECT_EQ(order_of(kNodeKeyframes, kNodeEyes, DistanceVariant::Jcgt, kVisible.data()),
              (std::vector<uint32_t>{3, 0, 1, 2}));
}

TEST(ClusteringUpdate, I3dAveragesOverTheNodesThatSeeThePatch) {
    // P0 seen by n1, n2: (3 + 2)/2 = 2.5         P1 seen by n0, n1: (2 + √13)/2 ≈ 2.803
    // P2 seen by n0 only: 2/1 = 2                P3 seen by all: (√3 + √6 + √10)/3 ≈ 2.448
    // →  P2, P3, P0, P1 (the JCGT order was P3, P0, P1, P2).
    EXPECT_EQ(order_of(kNodeKeyframes, kNodeEyes, DistanceVariant::I3d, kVisible.data()),
              (std::vector<uint32_t>{2, 3, 0, 1}));
}

TEST(ClusteringUpdate, I3dPutsAPatchNoNodeSeesLast) {
    // As above with P2 hidden from n0 too: no node sees P2, so it goes last; the others keep
    // P3 ≈ 2.448 < P0 2.5 < P1 ≈ 2.803.
    std::vector<uint8_t> visible = kVisible;
    visible[0 * kPatches + 2] = 0;
    EXPECT_EQ(order_of(kNodeKeyframes, kNodeEyes, DistanceVariant::I3d, visible.data()),
              (std::vector<uint32_t>{3, 0, 1, 2}));
}

TEST(ClusteringUpdate, I3dWithoutFlagsIsTheMeanDistance) {
    // Every node sees every patch: d(p)/3, the same ranking as JCGT's sums.
    EXPECT_EQ(order_of(kNodeKeyframes, kNodeEyes, DistanceVariant::I3d), (std::vector<uint32_t>{3, 0, 1, 2}));
}

TEST(ClusteringUpdate, PrimitivesKeepFileOrder) {
    // P3 alone in primitive 1: the primitive-0 patches come first in their JCGT order (P0, P1,
    // P2), although P3 has the smallest integrated distance.
    const std::vector<uint32_t> primitive = {0, 0, 0, 1};
    EXPECT_EQ(order_of(kNodeKeyframes, kNodeEyes, DistanceVariant::Jcgt, nullptr, primitive.data()),
              (std::vector<uint32_t>{0, 1, 2, 3}));
    // P1 and P2 in primitive 0, P0 and P3 in primitive 1: P1 8.606 < P2 8.768, then
    // P3 7.344 < P0 7.828.
    const std::vector<uint32_t> split = {1, 0, 0, 1};
    EXPECT_EQ(order_of(kNodeKeyframes, kNodeEyes, DistanceVariant::Jcgt, nullptr, split.data()),
              (std::vector<uint32_t>{1, 2, 3, 0}));
}

TEST(ClusteringUpdate, NoNodesKeepsPatchIdOrder) {
    // An empty node list: every d(p) is 0 (JCGT), a tie everywhere, so patch id order.
    EXPECT_EQ(order_of({}, {}, DistanceVariant::Jcgt), (std::vector<uint32_t>{0, 1, 2, 3}));
}

TEST(ClusteringUpdate, RejectsAKeyframeRowOutOfRange) {
    EXPECT_THROW(order_of({0, 2}, {0, 0, 3, 0, 0, 3}, DistanceVariant::Jcgt), InvalidInput);
}

// ---------------------------------------------------------------------------------------------
// End to end through cluster_nodes with k = 1: the single cluster holds every node, so after one
// update its order must be the integrated-distance order worked out here.
//
// Two keyframes, two patches (both in primitive 0), positions before framing:
//   patch 0, A: one small triangle. Keyframe 0: (−1,−1,1) (0,2,1) (1,−1,1), clockwise seen from
//       +z, so it faces −z; centroid (0,0,1). Keyframe 1: the same turned 180° about the y axis,
//       (1,−1,−1) (0,2,−1) (−1,−1,−1), facing +z; centroid (0,0,−1).
//   patch 1, B: a big triangle (−3,−3,0) (3,−3,0) (0,6,0), counter-clockwise from +z (faces +z),
//       centroid (0,0,0), and a zero-area triangle (0,0,−1) (0,0,1) (0,0,1) that only pins the
//       bounding box (no area: no weight in the centroid, never rasterised). Both keyframes.
// Framing: the box is x ∈ [−3,3], y ∈ [−3,6], z ∈ [−1,1] at both keyframes, centre (0,1.5,0);
// R = |(−3,−3,0) − (0,1.5,0)| = √29.25 ≈ 5.408, eyes at 3R ≈ 16.225 along the 12 icosahedron
// directions (permutations of (0, ±1, ±φ)/√(1+φ²)). Framed centroids:
//   A: (0,−1.5,1) at keyframe 0, (0,−1.5,−1) at keyframe 1, averaged (0,−1.5,0);
//   B: (0,−1.5,0) at both, averaged (0,−1.5,0).
// Bootstrap: the averaged centroids coincide, so from any seed viewpoint the keys tie and the
// order is by id, A then B: [0, 1].
// Update, JCGT: with f(c) = Σ over the 12 eyes of |eye − c|, d(B) = 2 f((0,−1.5,0)) and
// d(A) = f((0,−1.5,1)) + f((0,−1.5,−1)); f is strictly convex, so d(A) > d(B) (numerically
// d(A) ≈ 391.00, d(B) ≈ 390.51): B then A, [1, 0].
// Update, I3D: B faces the 4 eyes with z > 0 at each keyframe, mean ≈ 16.285; A faces the 8 eyes
// with z ≤ 0 at keyframe 0 and the 8 with z ≥ 0 at keyframe 1, mean ≈ 16.631: again [1, 0].
// And the new order really is better, so k-means keeps it: at keyframe 0 A and B never face the
// same eye (no eye has 0 < z < 1; the 4 eyes with z = 0 see B exactly edge-on), so nothing
// overlaps; at keyframe 1 the 4 eyes with z > 0 see B in front of A, and drawing A first lets
// A's fragments pass under B: B first has strictly less overdraw.
AnimatedMesh two_patch_mesh() {
    AnimatedMesh m;
    m.name = "two patches";
    m.vertex_count = 9;
    m.indices = {0, 1, 2, 3, 4, 5, 6, 7, 8};  // A; B's big triangle; B's zero-area triangle
    Primitive p;
    p.name = "all";
    p.index_count = 9;
    p.vertex_count = 9;
    m.primitives = {p};
    Clip c;
    c.name = "flip";
    c.keyframe_count = 2;
    m.clips = {c};
    const std::vector<float> b = {-3, -3, 0, 3, -3, 0, 0, 6, 0, 0, 0, -1, 0, 0, 1, 0, 0, 1};
    const std::vector<float> a0 = {-1, -1, 1, 0, 2, 1, 1, -1, 1}, a1 = {1, -1, -1, 0, 2, -1, -1, -1, -1};
    for (const std::vector<float>* a : {&a0, &a1}) {
        m.keyframe_positions.insert(m.keyframe_positions.end(), a->begin(), a->end());
        m.keyframe_positions.insert(m.keyframe_positions.end(), b.begin(), b.end());
    }
    return m;
}

MeshPatches two_patches() {
    MeshPatches p;
    p.cache_order = {0, 1, 2};
    p.patch_starts = {0, 1, 3};  // A = triangle 0; B = triangles 1, 2
    p.patch_primitive = {0, 0};
    return p;
}

ClusteringResult cluster_two_patches(DistanceVariant distance, UpdateRule update, size_t max_iterations) {
    const AnimatedMesh mesh = two_patch_mesh();
    const Framing framing =
        frame_keyframes(mesh.keyframe_positions.data(), 2, mesh.vertex_count, mesh.indices.data(), mesh.indices.size());
    // The framing worked out above.
    EXPECT_EQ(framing.centres, (std::vector<float>{0, 1.5f, 0, 0, 1.5f, 0}));
    EXPECT_NEAR(framing.radius, std::sqrt(29.25), 1e-4);  // (frame_keyframes adds a 1e-6 margin)
    ClusteringSettings s;
    s.clusters = 1;
    s.views = 12;
    s.resolution = 64;
    s.distance = distance;
    s.update = update;
    s.max_iterations = max_iterations;
    return cluster_nodes(mesh, two_patches(), framing, {0, 1}, s);
}

TEST(ClusteringUpdateEndToEnd, BootstrapTiesGiveIdOrder) {
    // One iteration: the assignment only, so the bootstrap order comes back.
    const ClusteringResult r = cluster_two_patches(DistanceVariant::Jcgt, UpdateRule::Monotone, 1);
    EXPECT_EQ(r.patch_orders, (std::vector<std::vector<uint32_t>>{{0, 1}}));
}

TEST(ClusteringUpdateEndToEnd, JcgtSingleClusterTakesTheIntegratedOrder) {
    for (UpdateRule rule : {UpdateRule::Monotone, UpdateRule::Paper}) {
        const ClusteringResult r = cluster_two_patches(DistanceVariant::Jcgt, rule, 30);
        EXPECT_EQ(r.patch_orders, (std::vector<std::vector<uint32_t>>{{1, 0}}));
        EXPECT_EQ(r.triangle_orders, (std::vector<std::vector<uint32_t>>{{1, 2, 0}}));
        EXPECT_EQ(r.assignment, std::vector<uint32_t>(24, 0));
        EXPECT_TRUE(r.converged);
        EXPECT_EQ(r.best_iteration, 1u);
        ASSERT_EQ(r.iterations.size(), 2u);
        EXPECT_LT(r.iterations[1].mean_ovr, r.iterations[0].mean_ovr);
    }
}

TEST(ClusteringUpdateEndToEnd, I3dSingleClusterTakesTheIntegratedOrder) {
    const ClusteringResult r = cluster_two_patches(DistanceVariant::I3d, UpdateRule::Monotone, 30);
    EXPECT_EQ(r.patch_orders, (std::vector<std::vector<uint32_t>>{{1, 0}}));
    EXPECT_TRUE(r.converged);
}

}  // namespace
