// The k-means update step alone (Han & Sander 2017, Algorithm 1 lines 20–24): a cluster's
// patches sorted by the integrated distance d(p), checked against distances worked out by hand.
// These are independent references: every expected order below follows from the numbers in the
// comments, not from the library.
#include "animorder/animorder.h"
#include "animorder/clustering.h"

#include <gtest/gtest.h>

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

}  // namespace
