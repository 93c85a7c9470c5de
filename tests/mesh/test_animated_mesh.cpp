// The AnimatedMesh invariants: a good mesh passes, each defect is named.
#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

using namespace animorder;

namespace {
AnimatedMesh good() {
    AnimatedMesh m;
    m.vertex_count = 4;
    m.indices = {0, 1, 2, 2, 1, 3};
    m.primitives = {{"a", 0, 3}, {"b", 3, 3}};
    m.keyframe_positions = std::vector<float>(2 * 4 * 3, 0.5f);
    m.clips = {{"clip", 1.0 / 30, 30, 0, 2}};
    return m;
}

void expect_rejected(const std::function<void(AnimatedMesh&)>& damage, const std::string& message) {
    AnimatedMesh m = good();
    damage(m);
    try {
        validate_animated_mesh(m);
        FAIL() << "accepted: " << message;
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
}
}  // namespace

TEST(AnimatedMesh, AcceptsAConsistentMesh) {
    EXPECT_NO_THROW(validate_animated_mesh(good()));
    AnimatedMesh spare = good();  // keyframes no clip uses are allowed
    spare.keyframe_positions.resize(3 * 4 * 3, 0.25f);
    EXPECT_NO_THROW(validate_animated_mesh(spare));
}

TEST(AnimatedMesh, NamesEachDefect) {
    expect_rejected([](AnimatedMesh& m) { m.indices[5] = 9; }, "index 2 of primitive 'b' is 9, vertex count is 4");
    expect_rejected(
        [](AnimatedMesh& m) {
            m.indices.push_back(0);
            m.primitives[1].index_count = 4;
        },
        "not a multiple of 3");
    expect_rejected([](AnimatedMesh& m) { m.primitives[1].first_index = 2; }, "does not continue");
    expect_rejected([](AnimatedMesh& m) { m.primitives.pop_back(); }, "cover 3 of 6");
    expect_rejected([](AnimatedMesh& m) { m.keyframe_positions.pop_back(); }, "not a whole number of keyframes");
    expect_rejected([](AnimatedMesh& m) { m.clips[0].keyframe_count = 3; }, "clip 'clip'");
    expect_rejected([](AnimatedMesh& m) { m.clips[0].first_keyframe = 2; }, "clip 'clip' spans keyframes 2..4");
    expect_rejected([](AnimatedMesh& m) { m.clips[0].keyframe_count = 0; }, "clip 'clip'");
    expect_rejected([](AnimatedMesh& m) { m.keyframe_positions[13] = NAN; }, "keyframe 1: position of vertex 0");
}

TEST(AnimatedMesh, NamesTheFirstPositionThatIsNotFinite) {
    // 500 keyframes of 4 vertices (6,000 floats: more than one of the blocks the check tests at
    // once). Float 5,000 is keyframe 5000 / 12 = 416, vertex 5000 / 3 % 4 = 2; float 5,500 lies
    // further on and is not named.
    for (const float bad : {NAN, INFINITY, -INFINITY}) {
        expect_rejected(
            [bad](AnimatedMesh& m) {
                m.keyframe_positions.assign(500 * 4 * 3, 0.5f);
                m.keyframe_positions[5500] = NAN;
                m.keyframe_positions[5000] = bad;
            },
            "keyframe 416: position of vertex 2 is not finite");
    }
    // The largest finite float, the smallest subnormal and −0 are positions like any other.
    AnimatedMesh extreme = good();
    extreme.keyframe_positions[0] = 3.4028235e38f;
    extreme.keyframe_positions[1] = -3.4028235e38f;
    extreme.keyframe_positions[2] = 1e-45f;
    extreme.keyframe_positions[3] = -0.0f;
    EXPECT_NO_THROW(validate_animated_mesh(extreme));
}

// The partial checks: of listed keyframes only (cluster_nodes of one clip), of the topology only
// (build_mesh_patches); each still refuses what it reads.
TEST(AnimatedMesh, PartialChecksReadWhatTheirCallersRead) {
    AnimatedMesh m = good();
    m.keyframe_positions.resize(3 * 4 * 3, 0.25f);
    m.keyframe_positions[2 * 12 + 7] = NAN;  // keyframe 2, vertex 2
    EXPECT_NO_THROW(validate_animated_mesh(m, {0, 1}));
    EXPECT_NO_THROW(validate_mesh_topology(m));
    for (const std::vector<uint32_t>& listed : {std::vector<uint32_t>{2}, std::vector<uint32_t>{1, 2}}) {
        try {
            validate_animated_mesh(m, listed);
            FAIL() << "accepted keyframe 2";
        } catch (const InvalidInput& e) {
            EXPECT_STREQ(e.what(), "keyframe 2: position of vertex 2 is not finite");
        }
    }
    try {
        validate_animated_mesh(m, {3});
        FAIL() << "accepted keyframe 3";
    } catch (const InvalidInput& e) {
        EXPECT_STREQ(e.what(), "keyframe 3 does not exist (the mesh has 3)");
    }
    m.keyframe_positions[2 * 12 + 7] = 0.25f;
    m.indices[5] = 9;
    EXPECT_THROW(validate_animated_mesh(m, {0}), InvalidInput);
    EXPECT_THROW(validate_mesh_topology(m), InvalidInput);
}

// Clips that share a name (Mixamo names every animation "mixamo.com") are all kept when that name
// is asked, in the mesh's order, each with its own keyframes (the last of them alone was kept).
TEST(AnimatedMesh, SelectingANameSeveralClipsShareKeepsThemAll) {
    AnimatedMesh m = good();
    m.keyframe_positions.resize(4 * 4 * 3);
    for (size_t k = 0; k < 4; ++k)
        std::fill(m.keyframe_positions.begin() + ptrdiff_t(k * 12),
                  m.keyframe_positions.begin() + ptrdiff_t(k * 12 + 12), float(k));
    m.clips = {{"mixamo.com", 0, 30, 0, 1}, {"idle", 1.0 / 30, 30, 1, 2}, {"mixamo.com", 0, 30, 3, 1}};
    const AnimatedMesh s = select_clips(m, {"mixamo.com"});
    ASSERT_EQ(s.clips.size(), 2u);
    EXPECT_EQ(s.clips[0].first_keyframe, 0u);
    EXPECT_EQ(s.clips[1].first_keyframe, 1u);
    ASSERT_EQ(s.keyframe_count(), 2u);
    EXPECT_EQ(s.keyframe(0)[0], 0.0f);
    EXPECT_EQ(s.keyframe(1)[0], 3.0f);
    EXPECT_NO_THROW(validate_animated_mesh(s));
    EXPECT_EQ(select_clips(m, {"mixamo.com", "idle", "mixamo.com"}).clips.size(), 3u);  // a name twice: once
}
