// The IQM loader: a tiny skinned model built here whose keyframes are worked out by hand, hostile
// files (frame counts without data, absurd frame rates, offsets past the end, bad joints) as
// one-line errors, the loading budget, and the IQM character of ../shared/data.
#include "animorder/animated_mesh.h"
#include "animorder/iqm_loader.h"
#include "animorder/load.h"
#include "support/binary_loader.h"
#include "support/files.h"
#include "support/meshes.h"

#include "support/require.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

using namespace animorder;
namespace fs = std::filesystem;

namespace {

// Header fields (Lee Salzman's iqm.h) by byte offset.
enum : size_t {
    kNumText = 28,
    kOfsText = 32,
    kNumArrays = 44,
    kNumVertexes = 48,
    kOfsArrays = 52,
    kNumTriangles = 56,
    kOfsTriangles = 60,
    kNumJoints = 68,
    kOfsJoints = 72,
    kNumPoses = 76,
    kOfsPoses = 80,
    kNumAnims = 84,
    kOfsAnims = 88,
    kNumFrames = 92,
    kNumChannels = 96,
    kOfsFrames = 100
};
// Where tiny_iqm() puts its sections.
enum : size_t {
    kText = 124,
    kArrays = 132,
    kPositions = 192,
    kBlendIndices = 228,
    kBlendWeights = 240,
    kTriangles = 252,
    kJoints = 264,
    kPoses = 312,
    kAnims = 400,
    kFrames = 420
};

// Three vertices (0,0,0), (1,0,0), (0,1,0), one triangle, one joint at the origin that carries
// every vertex, and one animation "slide" of two frames at 10 frames per second in which the
// joint's x translation (the only channel: offset 0, scale 1) goes from 0 to 3.
test::ByteImage tiny_iqm() {
    test::ByteImage m;
    const char magic[16] = "INTERQUAKEMODEL";
    for (size_t i = 0; i < 16; ++i) m.put<char>(i, magic[i]);
    m.put<uint32_t>(16, 2);
    m.put<uint32_t>(kNumText, 8);
    m.put<uint32_t>(kOfsText, kText);
    const char text[8] = {'\0', 's', 'l', 'i', 'd', 'e', '\0', '\0'};
    for (size_t i = 0; i < 8; ++i) m.put<char>(kText + i, text[i]);
    m.put<uint32_t>(kNumArrays, 3);
    m.put<uint32_t>(kNumVertexes, 3);
    m.put<uint32_t>(kOfsArrays, kArrays);
    const uint32_t arrays[3][5] = {{0, 0, 7, 3, kPositions}, {4, 0, 1, 4, kBlendIndices}, {5, 0, 1, 4, kBlendWeights}};
    for (size_t a = 0; a < 3; ++a)
        for (size_t i = 0; i < 5; ++i) m.put<uint32_t>(kArrays + 20 * a + 4 * i, arrays[a][i]);
    const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    for (size_t i = 0; i < 9; ++i) m.put<float>(kPositions + 4 * i, positions[i]);
    for (size_t v = 0; v < 3; ++v) {
        m.put<uint32_t>(kBlendIndices + 4 * v, 0);
        m.put<uint32_t>(kBlendWeights + 4 * v, 255);  // weight bytes 255, 0, 0, 0
    }
    m.put<uint32_t>(kNumTriangles, 1);
    m.put<uint32_t>(kOfsTriangles, kTriangles);
    for (size_t i = 0; i < 3; ++i) m.put<uint32_t>(kTriangles + 4 * i, uint32_t(i));
    m.put<uint32_t>(kNumJoints, 1);
    m.put<uint32_t>(kOfsJoints, kJoints);
    m.put<int32_t>(kJoints + 4, -1);                                          // no parent
    m.put<float>(kJoints + 32, 1.0f);                                         // rotation w
    for (size_t c = 0; c < 3; ++c) m.put<float>(kJoints + 36 + 4 * c, 1.0f);  // scale
    m.put<uint32_t>(kNumPoses, 1);
    m.put<uint32_t>(kOfsPoses, kPoses);
    m.put<int32_t>(kPoses, -1);
    m.put<uint32_t>(kPoses + 4, 1);                                          // channel mask: translate x only
    m.put<float>(kPoses + 8 + 4 * 6, 1.0f);                                  // offset of rotation w
    for (size_t c = 7; c < 10; ++c) m.put<float>(kPoses + 8 + 4 * c, 1.0f);  // offsets of scale
    m.put<float>(kPoses + 48, 1.0f);                                         // scale of translate x
    m.put<uint32_t>(kNumAnims, 1);
    m.put<uint32_t>(kOfsAnims, kAnims);
    m.put<uint32_t>(kAnims, 1);  // name "slide"
    m.put<uint32_t>(kAnims + 4, 0);
    m.put<uint32_t>(kAnims + 8, 2);
    m.put<float>(kAnims + 12, 10.0f);
    m.put<uint32_t>(kNumFrames, 2);
    m.put<uint32_t>(kNumChannels, 1);
    m.put<uint32_t>(kOfsFrames, kFrames);
    m.put<uint16_t>(kFrames, 0);
    m.put<uint16_t>(kFrames + 2, 3);
    return m;
}

class IqmLoader : public test::BinaryLoaderTest {
protected:
    IqmLoader()
        : BinaryLoaderTest("animorder-iqm", [](const std::string& f, const LoadOptions& o) { return load_iqm(f, o); }) {
    }
};

}  // namespace

// An animation of 20 million frames at 20 million frames a second is one second: 31 keyframes, each
// the interpolation of its two frames, which alone are skinned (every frame was skinned and kept
// first: 20 million small arrays, 1.6 GB, where a 110-million-frame file of 420 bytes ran out of
// memory within the loading budget). No channel is keyed, so every keyframe is the bind pose.
TEST_F(IqmLoader, OnlyTheFramesTheKeyframesInterpolateAreSkinned) {
    test::ByteImage m = tiny_iqm();
    m.put<uint32_t>(kPoses + 4, 0);
    m.put<uint32_t>(kNumChannels, 0);
    m.put<uint32_t>(kNumFrames, 20000000);
    m.put<uint32_t>(kAnims + 8, 20000000);
    m.put<float>(kAnims + 12, 2e7f);
    const AnimatedMesh a = load_iqm(write("many.iqm", m));
    ASSERT_EQ(a.clips.size(), 1u);
    EXPECT_EQ(a.clips[0].keyframe_count, 31u);
    for (size_t k = 0; k < a.keyframe_count(); ++k) test::expect_position(a, k, 1, 1, 0, 0);
}

TEST_F(IqmLoader, TinyModelSlidesAsWorkedOutByHand) {
    const AnimatedMesh m = load_iqm(write("tiny.iqm", tiny_iqm()));
    ASSERT_EQ(m.clips.size(), 1u);
    EXPECT_EQ(m.clips[0].name, "slide");
    EXPECT_EQ(m.clips[0].keyframe_count, 4u);  // 0.1 s at 30/s, both ends
    EXPECT_EQ(m.joint_count, 1u);
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 2, 1}));  // clockwise → counter-clockwise
    // Keyframe k is at frame k/3: the joint (and every vertex) moved by 3 · k/3 = k along x.
    const float rest[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    for (size_t k = 0; k < 4; ++k)
        for (size_t i = 0; i < 9; ++i)
            EXPECT_NEAR(m.keyframe(k)[i], rest[i] + (i % 3 == 0 ? double(k) : 0.0), 1e-5)
                << "keyframe " << k << " float " << i;
}

TEST_F(IqmLoader, HostileFilesGiveOneLineErrors) {
    {
        test::ByteImage m = tiny_iqm();  // two billion frames of no channels: no data to check, 77 GB to sample
        m.put<uint32_t>(kPoses + 4, 0);  // nothing animated: no frame data is ever read
        m.put<uint32_t>(kNumChannels, 0);
        m.put<uint32_t>(kNumFrames, 0x7FFFFFFF);
        m.put<uint32_t>(kAnims + 8, 0x7FFFFFFF);
        expect_error("frames.iqm", m, "is absurdly long");  // 89 million seconds at 30 keyframes a second
    }
    {
        // The pose keys two channels a frame (translate x and y), the header says one: each frame's
        // second value would be read from the next frame.
        test::ByteImage m = tiny_iqm();
        m.put<uint32_t>(kPoses + 4, 3);
        m.put<float>(kPoses + 52, 1.0f);
        expect_error("mask.iqm", m, "its poses animate 2 channels a frame, its header says 1");
    }
    expect_field_error(tiny_iqm(), "slow.iqm", kAnims + 12, float(1e-30f),
                       "absurdly long");  // 10^30 s at 30 keyframes per second
    expect_field_error(tiny_iqm(), "fast.iqm", kAnims + 12, float(INFINITY), "frame rate");
    {
        test::ByteImage m = tiny_iqm();
        m.put<uint32_t>(kNumFrames, 0xFFFFFFFF);
        m.put<uint32_t>(kNumChannels, 0xFFFFFFFF);
        expect_error("channels.iqm", m, "frames past its end");
    }
    expect_field_error(tiny_iqm(), "offset.iqm", kOfsTriangles, uint32_t(0xFFFFFFF0), "triangles past its end");
    expect_field_error(tiny_iqm(), "positions.iqm", kArrays + 16, uint32_t(0xFFFFFFF0),
                       "positions past its end");  // positions far past the end
    {
        test::ByteImage m = tiny_iqm();
        m.put<uint32_t>(kArrays + 20, 0);  // the blend indices array is a second POSITION array
        m.put<uint32_t>(kArrays + 28, 7);
        m.put<uint32_t>(kArrays + 32, 3);
        expect_error("twice.iqm", m, "two POSITION");
    }
    expect_field_error(tiny_iqm(), "index.iqm", kTriangles + 4, uint32_t(3), "names a vertex past 3");
    expect_field_error(tiny_iqm(), "joint.iqm", kBlendIndices, uint32_t(1), "names joint 1");
    expect_field_error(tiny_iqm(), "parent.iqm", kJoints + 4, int32_t(0), "parent");  // its own parent
    expect_field_error(tiny_iqm(), "missing.iqm", kAnims + 4, uint32_t(1),
                       "names missing frames");  // frames 1 and 2 of two
    test::ByteImage m = tiny_iqm();
    m.bytes.resize(100);
    expect_error("short.iqm", m, "no IQM header");
    LoadOptions zero_rate;
    zero_rate.sample_rate = 0;
    expect_error("rate.iqm", tiny_iqm(), "sample rate", zero_rate);
}

// Every byte of the tiny file set in turn to 0x00, 0x7F, 0x80 and 0xFF (counts, offsets, indices,
// floats become huge, negative, NaN): each copy loads or fails with a LoadError, nothing else
// (under scripts/test-sanitized.sh: no memory error, no undefined behaviour).
TEST_F(IqmLoader, EveryByteMutatedLoadsOrFailsCleanly) {
    expect_every_byte_mutation_loads_or_fails(tiny_iqm(), "mutated.iqm");
}

TEST_F(IqmLoader, LoadingBudgetIsCheckedBeforeSampling) {
    test::ByteImage m = tiny_iqm();  // 1000 frames per second slowed to 10^-3: 1000 s, 30001 keyframes
    m.put<float>(kAnims + 12, 1e-3f);
    LoadOptions small;
    small.max_keyframe_bytes = 30001 * 3 * 12 - 1;
    expect_error("budget.iqm", m, "loading budget", small);
    small.max_keyframe_bytes = 30001 * 3 * 12;
    EXPECT_EQ(load_iqm(write("fits.iqm", m), small).keyframe_count(), 30001u);
}

TEST(IqmCharacters, MrFixitLoads) {
    const fs::path file = fs::path(ANIMORDER_SOURCE_DIR) / ".." / "shared" / "data" / "iqm-mrfixit" / "mrfixit.iqm";
    ANIMORDER_REQUIRE_DATA(file);
    const AnimatedMesh m = load_iqm(file.string());
    EXPECT_GT(m.triangle_count(), 100u);
    EXPECT_GT(m.joint_count, 0u);
    EXPECT_GE(m.clips.size(), 1u);
    EXPECT_NO_THROW(validate_animated_mesh(m));
}
