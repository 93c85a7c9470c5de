// Triangle identity: permutations by vertex indices (hand-worked cases: rotations allowed,
// mirrored windings and multiset changes refused) and matching by corner data (shuffled,
// rotated, perturbed copies; a changed or missing triangle left unmatched).
#include "animorder/triangle_matching.h"

#include <gtest/gtest.h>

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
