// Triangle identity: permutations by vertex indices (hand-worked cases: rotations allowed,
// mirrored windings and multiset changes refused) and matching by corner data (shuffled,
// rotated, perturbed copies; a changed or missing triangle left unmatched) and the nearest
// triangle by centroid (hand-worked distances, and a brute-force search on random triangles).
#include "animorder/triangle_matching.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

using namespace animorder;

TEST(TrianglePermutation, RotationsAreTheSameTriangleAndEachBaseTriangleIsUsedOnce) {
    const std::vector<uint32_t> base = {0, 1, 2, 2, 3, 0, 4, 5, 6};
    // Triangle 2 first, triangle 0 rotated once, triangle 1 rotated twice.
    const std::vector<uint32_t> order = {4, 5, 6, 1, 2, 0, 0, 2, 3};
    EXPECT_EQ(triangle_permutation(base.data(), order.data(), 3), (std::vector<uint32_t>{2, 0, 1}));
}

TEST(TrianglePermutation, RefusesAFlippedWindingAMissingTriangleOrADuplicate) {
    const std::vector<uint32_t> base = {0, 1, 2, 2, 3, 0};
    const std::vector<uint32_t> flipped = {0, 2, 1, 2, 3, 0};
    const std::vector<uint32_t> doubled = {0, 1, 2, 1, 2, 0};
    const std::vector<uint32_t> other = {0, 1, 2, 2, 3, 1};
    EXPECT_TRUE(triangle_permutation(base.data(), flipped.data(), 2).empty());
    EXPECT_TRUE(triangle_permutation(base.data(), doubled.data(), 2).empty());
    EXPECT_TRUE(triangle_permutation(base.data(), other.data(), 2).empty());
}

TEST(TrianglePermutation, RepeatedTrianglesArePairedInSequence) {
    const std::vector<uint32_t> base = {0, 1, 2, 0, 1, 2, 3, 4, 5};
    const std::vector<uint32_t> order = {3, 4, 5, 1, 2, 0, 0, 1, 2};
    EXPECT_EQ(triangle_permutation(base.data(), order.data(), 3), (std::vector<uint32_t>{2, 0, 1}));
}

namespace {

// Triangles as corners of 3 floats: triangle t at x offset 10·t.
std::vector<float> strip(size_t count) {
    std::vector<float> v;
    for (size_t t = 0; t < count; ++t) {
        const float x = 10.0f * float(t);
        for (float c : {x, 0.f, 0.f, x + 1, 0.f, 0.f, x, 1.f, 0.f}) v.push_back(c);
    }
    return v;
}

}  // namespace

TEST(MatchTriangles, FindsShuffledRotatedAndSlightlyMovedCopies) {
    const std::vector<float> from = strip(3);
    // to: triangle 2 (corners rotated by one: c1 c2 c0, moved by 1e-4), then 0, then 1.
    std::vector<float> to;
    for (float c : {21.f, 0.f, 0.f, 20.f, 1.f, 0.f, 20.f, 0.f, 0.f}) to.push_back(c + 1e-4f);
    for (size_t i = 0; i < 18; ++i) to.push_back(from[i]);
    const TriangleMatch m = match_triangles(from, to, 3, 1e-3f);
    EXPECT_EQ(m.matched, 3u);
    EXPECT_EQ(m.from_of_to, (std::vector<int64_t>{2, 0, 1}));
}

TEST(MatchTriangles, LeavesAMirroredMovedOrExtraTriangleUnmatched) {
    const std::vector<float> from = strip(2);
    std::vector<float> to = {0, 0, 0, 0, 1, 0, 1, 0, 0};  // triangle 0 mirrored (winding flipped)
    for (float c : {10.f, 0.f, 0.f, 11.f, 0.f, 0.f, 10.f, 1.5f, 0.f}) to.push_back(c);  // a corner moved 0.5
    for (float c : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) to.push_back(c);      // triangle 0 itself
    for (float c : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) to.push_back(c);      // and again: no second match
    const TriangleMatch m = match_triangles(from, to, 3, 1e-3f);
    EXPECT_EQ(m.from_of_to, (std::vector<int64_t>{-1, -1, 0, -1}));
    EXPECT_EQ(m.matched, 1u);
}

TEST(MatchTriangles, ExtraDimensionsMustMatchToo) {
    // Two coincident triangles told apart by a second keyframe (dims 6).
    const std::vector<float> from = {0, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 0,
                                     0, 0, 0, 0, 0, 5, 1, 0, 0, 1, 0, 5, 0, 1, 0, 0, 1, 5};
    const std::vector<float> to = {0, 0, 0, 0, 0, 5, 1, 0, 0, 1, 0, 5, 0, 1, 0, 0, 1, 5,
                                   0, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 0};
    const TriangleMatch m = match_triangles(from, to, 6, 1e-3f);
    EXPECT_EQ(m.from_of_to, (std::vector<int64_t>{1, 0}));
}

// The strip's centroids lie at x = 10·t + 1/3, y = 1/3: a triangle whose centroid is at x = 4
// is nearer to triangle 0 (distance 3.68) than to triangle 1 (6.34), one at 6 to triangle 1
// (4.35 against 5.68); several triangles may name one (29 and 100: triangle 2); a second keyframe
// (dims 6) decides between triangles that coincide in the first.
TEST(NearestTriangles, HandWorkedCentroidDistances) {
    const std::vector<float> from = strip(3);
    std::vector<float> to;
    for (const float x : {4.0f, 6.0f, 29.0f, 100.0f})
        for (float c : {x - 1, 0.f, 0.f, x + 1, 0.f, 0.f, x, 0.f, 0.f}) to.push_back(c);  // centroid (x, 0, 0)
    const NearestTriangles n = nearest_triangles(from, to, 3);
    EXPECT_EQ(n.from_of_to, (std::vector<uint32_t>{0, 1, 2, 2}));
    ASSERT_EQ(n.distance.size(), 4u);
    EXPECT_NEAR(n.distance[0], std::hypot(4.0 - 1.0 / 3, 1.0 / 3), 1e-5);
    EXPECT_NEAR(n.distance[1], std::hypot(10.0 + 1.0 / 3 - 6, 1.0 / 3), 1e-5);
    EXPECT_NEAR(n.distance[3], std::hypot(100.0 - 20 - 1.0 / 3, 1.0 / 3), 1e-4);
    EXPECT_TRUE(nearest_triangles({}, to, 3).from_of_to.empty());
    EXPECT_TRUE(nearest_triangles(from, {}, 3).from_of_to.empty());
    // Two triangles at the same place in keyframe 0, apart in keyframe 1.
    const std::vector<float> two = {0, 0, 0, 0, 0, 0, 3, 0, 0, 3, 0, 0, 0, 3, 0, 0, 3, 0,
                                    0, 0, 0, 0, 0, 9, 3, 0, 0, 3, 0, 9, 0, 3, 0, 0, 3, 9};
    const std::vector<float> probe = {0, 0, 0, 0, 0, 8, 3, 0, 0, 3, 0, 8, 0, 3, 0, 0, 3, 8};
    EXPECT_EQ(nearest_triangles(two, probe, 6).from_of_to, (std::vector<uint32_t>{1}));
}

// Against a brute-force search on random triangles (3 and 9 values per corner).
TEST(NearestTriangles, MatchesBruteForce) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1, 1);
    for (const size_t dims : {size_t(3), size_t(9)}) {
        std::vector<float> from(700 * 3 * dims), to(300 * 3 * dims);
        for (float& v : from) v = u(rng);
        for (float& v : to) v = u(rng);
        const NearestTriangles n = nearest_triangles(from, to, dims);
        ASSERT_EQ(n.from_of_to.size(), 300u);
        const auto centroid = [&](const std::vector<float>& v, size_t t, size_t i) {
            return (double(v[3 * t * dims + i]) + v[(3 * t + 1) * dims + i] + v[(3 * t + 2) * dims + i]) / 3;
        };
        for (size_t t = 0; t < 300; ++t) {
            double best = INFINITY;
            size_t best_s = 0;
            for (size_t s = 0; s < 700; ++s) {
                double d = 0;
                for (size_t i = 0; i < dims; ++i) d += std::pow(centroid(to, t, i) - centroid(from, s, i), 2);
                if (d < best) best = d, best_s = s;
            }
            EXPECT_EQ(n.from_of_to[t], best_s) << dims << " " << t;
            EXPECT_NEAR(n.distance[t], std::sqrt(best), 1e-9) << dims << " " << t;
        }
    }
}
