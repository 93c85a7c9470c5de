// static-sander07: the occlusion-potential rank (Sander et al. 2007, equation 4) on hand-worked
// patches, and the whole method's guarantees (permutation, winding, determinism, bad input).
#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/procedural_character.h"
#include "animorder/static_sander07.h"
#include "support/meshes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace animorder;

namespace {
// Unit right triangles in the plane z = h. up: CCW seen from +z (normal +z); else normal −z.
void add_triangle(std::vector<float>& positions, std::vector<uint32_t>& ib, float x, float h, bool up, float size = 1) {
    const uint32_t base = uint32_t(positions.size() / 3);
    const float corners[3][3] = {{x, 0, h}, {x + size, 0, h}, {x, size, h}};
    for (const auto& c : corners) positions.insert(positions.end(), c, c + 3);
    if (up)
        ib.insert(ib.end(), {base, base + 1, base + 2});
    else
        ib.insert(ib.end(), {base, base + 2, base + 1});
}

std::vector<uint32_t> sort_each_triangle_a_patch(const std::vector<float>& positions, const std::vector<uint32_t>& ib) {
    const size_t n = ib.size() / 3;
    std::vector<uint32_t> starts(n + 1), order(n);
    for (size_t i = 0; i <= n; ++i) starts[i] = uint32_t(i);
    sort_patches_sander07(order.data(), ib.data(), ib.size(), positions.data(), positions.size() / 3, 12, starts.data(),
                          n);
    return order;
}
}  // namespace

TEST(StaticSander07, OutwardFacingPatchesFarFromTheCentreComeFirst) {
    // Patch 0 at z=−1 facing +z (towards the centre: rank −1), patch 1 at z=+1 facing +z (rank
    // +1), patch 2 at z=+1 facing −z (rank −1), patch 3 at z=−1 facing −z (rank +1). Equal areas
    // put the centroid's z at 0. Descending rank, ties by patch id: 1, 3, 0, 2.
    std::vector<float> positions;
    std::vector<uint32_t> ib;
    add_triangle(positions, ib, 0, -1, true);
    add_triangle(positions, ib, 0, +1, true);
    add_triangle(positions, ib, 0, +1, false);
    add_triangle(positions, ib, 0, -1, false);
    EXPECT_EQ(sort_each_triangle_a_patch(positions, ib), (std::vector<uint32_t>{1, 3, 0, 2}));
}

TEST(StaticSander07, MeshCentroidIsAreaWeighted) {
    // A: area 8 at z=0 facing +z; B: area 0.5 at z=2 facing −z; C: area 0.005 at z=10 facing −z.
    // Rank of a +z patch is z − c, of a −z patch c − z, so the centroid height c decides A vs B.
    // Area-weighted c = (0 + 1 + 0.05)/8.505 = 0.123: A −0.12, B −1.88, C −9.9 → order A, B, C.
    // An unweighted centroid (c = 4) would give A −4, B +2: B first.
    std::vector<float> positions;
    std::vector<uint32_t> ib;
    add_triangle(positions, ib, 0, 0, true, 4);
    add_triangle(positions, ib, 10, 2, false, 1);
    add_triangle(positions, ib, 20, 10, false, 0.1f);
    EXPECT_EQ(sort_each_triangle_a_patch(positions, ib), (std::vector<uint32_t>{0, 1, 2}));
}

TEST(StaticSander07, PatchNormalIsTheAreaWeightedAverageNotTheSum) {
    // Patch 0 = two triangles at z=+1: area 2 facing +z and area 0.5 facing −z, so
    // N = (2 − 0.5)/2.5 = +0.6 (a plain sum of area vectors would be 1.5). Patch 1 = one triangle
    // of area 2 at z=−1 facing −z (N = −1). Mesh centroid c = (2.5·1 − 2)/4.5 = 0.111.
    // rank0 = (1 − 0.111)·0.6 = 0.533, rank1 = (−1 − 0.111)·(−1) = 1.111 → patch 1 first
    // (the sum would give rank0 = 1.333 and put patch 0 first).
    std::vector<float> positions;
    std::vector<uint32_t> ib;
    add_triangle(positions, ib, 0, 1, true, 2);
    add_triangle(positions, ib, 5, 1, false, 1);
    add_triangle(positions, ib, 10, -1, false, 2);
    const std::vector<uint32_t> starts{0, 2, 3};
    std::vector<uint32_t> order(2);
    sort_patches_sander07(order.data(), ib.data(), ib.size(), positions.data(), positions.size() / 3, 12, starts.data(),
                          2);
    EXPECT_EQ(order, (std::vector<uint32_t>{1, 0}));
}

TEST(StaticSander07, StrideSkipsInterleavedAttributes) {
    // Same scene as the first test with a 6-float vertex (position + garbage normal).
    std::vector<float> positions;
    std::vector<uint32_t> ib;
    add_triangle(positions, ib, 0, -1, true);
    add_triangle(positions, ib, 0, +1, true);
    std::vector<float> interleaved;
    for (size_t v = 0; v < positions.size() / 3; ++v) {
        interleaved.insert(interleaved.end(), positions.begin() + 3 * v, positions.begin() + 3 * v + 3);
        interleaved.insert(interleaved.end(), {99.f, -99.f, 1e6f});
    }
    const std::vector<uint32_t> starts{0, 1, 2};
    std::vector<uint32_t> order(2);
    sort_patches_sander07(order.data(), ib.data(), ib.size(), interleaved.data(), positions.size() / 3, 24,
                          starts.data(), 2);
    EXPECT_EQ(order, (std::vector<uint32_t>{1, 0}));
}

TEST(StaticSander07, WholeMethodIsAPermutationKeepingWinding) {
    const AnimatedMesh mesh = make_procedural_character();
    for (double lambda : {0.0, 0.85, 3.0}) {
        std::vector<uint32_t> order(mesh.triangle_count());
        const StaticOrderResult r = order_static_sander07(order.data(), mesh.indices.data(), mesh.indices.size(),
                                                          mesh.keyframe(0), mesh.vertex_count, 12, lambda);
        EXPECT_TRUE(test::is_permutation_of_iota(order));
        EXPECT_TRUE(test::same_triangles_same_winding(mesh.indices, test::applied(mesh.indices, order)));
        EXPECT_GT(r.patch_count, 0u);
        std::vector<uint32_t> again(mesh.triangle_count());
        order_static_sander07(again.data(), mesh.indices.data(), mesh.indices.size(), mesh.keyframe(0),
                              mesh.vertex_count, 12, lambda);
        EXPECT_EQ(order, again);
    }
}

TEST(StaticSander07, EmptyAndDegenerateInput) {
    EXPECT_NO_THROW(order_static_sander07(nullptr, nullptr, 0, nullptr, 0, 12));
    // A zero-area triangle next to a real one: still a permutation, no NaN rank trouble.
    const std::vector<float> positions{0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 2, 2};
    const std::vector<uint32_t> ib{0, 1, 2, 3, 3, 3, 0, 3, 1};
    std::vector<uint32_t> order(3);
    order_static_sander07(order.data(), ib.data(), ib.size(), positions.data(), 4, 12);
    EXPECT_TRUE(test::is_permutation_of_iota(order));
}

TEST(StaticSander07, RejectsNonFinitePositionsAndBadStride) {
    const std::vector<float> positions{0, 0, 0, 1, 0, 0, 0, std::nanf(""), 0};
    const std::vector<uint32_t> ib{0, 1, 2};
    std::vector<uint32_t> order(1);
    EXPECT_THROW(order_static_sander07(order.data(), ib.data(), 3, positions.data(), 3, 12), InvalidInput);
    const std::vector<float> good{0, 0, 0, 1, 0, 0, 0, 1, 0};
    EXPECT_THROW(order_static_sander07(order.data(), ib.data(), 3, good.data(), 3, 8), InvalidInput);
}
