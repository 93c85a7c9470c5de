// The MD2 loader: a tiny model built here whose keyframes are worked out by hand, hostile headers
// (overflowing counts, offsets past the end, indices out of range) as one-line errors, the loading
// budget, and the MD2 characters of ../shared/data.
#include "animorder/animated_mesh.h"
#include "animorder/load.h"
#include "animorder/md2_loader.h"
#include "support/binary_loader.h"
#include "support/files.h"

#include "support/require.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace animorder;
namespace fs = std::filesystem;

namespace {

// Header fields (id Software's md2.h) by byte offset.
enum : size_t {
    kFrameSize = 16,
    kVertices = 24,
    kTexCoords = 28,
    kTriangles = 32,
    kFrames = 40,
    kOfsTris = 52,
    kOfsFrames = 56,
    kOfsEnd = 64
};

// Three vertices, one triangle (0, 1, 2), one frame per name (two, "wave1" and "wave2", by
// default): frame f has scale (1, 1, 1), translate (0, 0, 10·f) and vertex bytes v0 = (0, 0, 0),
// v1 = (4, 0, 0), v2 = (0, 8 + 2·f, 0).
test::ByteImage tiny_md2(const std::vector<std::string>& names = {"wave1", "wave2"}) {
    const int32_t frames = int32_t(names.size());
    test::ByteImage m;
    m.put_text(0, "IDP2", 4);
    m.put<int32_t>(4, 8);
    const int32_t vertices = 3, frame_size = 40 + 4 * vertices;
    m.put<int32_t>(kFrameSize, frame_size);
    m.put<int32_t>(kVertices, vertices);
    m.put<int32_t>(kTexCoords, 0);
    m.put<int32_t>(kTriangles, 1);
    m.put<int32_t>(kFrames, frames);
    m.put<int32_t>(kOfsTris, 68);
    m.put<int32_t>(kOfsFrames, 68 + 12);
    const uint16_t tri[6] = {0, 1, 2, 0, 0, 0};
    for (size_t i = 0; i < 6; ++i) m.put<uint16_t>(68 + 2 * i, tri[i]);
    for (int f = 0; f < frames; ++f) {
        const size_t at = 80 + size_t(f) * size_t(frame_size);
        for (int c = 0; c < 3; ++c) m.put<float>(at + 4 * size_t(c), 1.0f);
        m.put<float>(at + 12, 0.0f);
        m.put<float>(at + 16, 0.0f);
        m.put<float>(at + 20, 10.0f * float(f));
        m.put_text(at + 24, names[size_t(f)].c_str(), 16);
        const unsigned char v[3][3] = {{0, 0, 0}, {4, 0, 0}, {0, static_cast<unsigned char>(8 + 2 * f), 0}};
        for (size_t i = 0; i < 3; ++i)
            for (size_t c = 0; c < 3; ++c) m.put<unsigned char>(at + 40 + 4 * i + c, v[i][c]);
    }
    m.bytes.resize(80 + size_t(frames) * size_t(frame_size));  // the last normal index byte
    m.put<int32_t>(kOfsEnd, int32_t(m.bytes.size()));
    return m;
}

class Md2Loader : public test::BinaryLoaderTest {
protected:
    Md2Loader()
        : BinaryLoaderTest("animorder-md2", [](const std::string& f, const LoadOptions& o) { return load_md2(f, o); }) {
    }
};

}  // namespace

TEST_F(Md2Loader, TinyModelResamplesAsWorkedOutByHand) {
    const AnimatedMesh m = load_md2(write("tiny.md2", tiny_md2()));
    ASSERT_EQ(m.clips.size(), 1u);
    EXPECT_EQ(m.clips[0].name, "wave");
    EXPECT_EQ(m.clips[0].keyframe_count, 4u);                // 0.1 s (two frames at 10/s) at 30/s, both ends
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 2, 1}));  // clockwise → counter-clockwise
    // Keyframe k is 1/3·k of the way from frame 0 to frame 1: v2 = (0, 8 + 2k/3, 10k/3).
    for (size_t k = 0; k < 4; ++k) {
        const float* p = m.keyframe(k);
        EXPECT_NEAR(p[3], 4.0, 1e-5);
        EXPECT_NEAR(p[5], 10.0 * double(k) / 3, 1e-5);
        EXPECT_NEAR(p[7], 8 + 2.0 * double(k) / 3, 1e-5) << k;
    }
}

// Quake II's action variants (faerie.md2's pain101 … pain304) are clips of their own, named by
// variant; numbers that start again start a clip; a three-digit count past 99 does not.
TEST_F(Md2Loader, VariantsAndRestartsAreClipsOfTheirOwn) {
    const AnimatedMesh m = load_md2(write("variants.md2", tiny_md2({"pain101", "pain102", "pain201", "pain202",
                                                                    "run099", "run100", "jump1", "jump1", "pain301"})));
    ASSERT_EQ(m.clips.size(), 6u);
    const char* names[] = {"pain1", "pain2", "run", "jump", "jump", "pain3"};
    for (size_t c = 0; c < 6; ++c) EXPECT_EQ(m.clips[c].name, names[c]) << c;
    EXPECT_EQ(m.clips[0].keyframe_count, 4u);  // two frames each: 0.1 s at 30/s, both ends
    EXPECT_EQ(m.clips[2].keyframe_count, 4u);
    EXPECT_EQ(m.clips[3].keyframe_count, 1u);  // one frame
    // pain2 starts at frame 2 (translate z = 20), not between pain1's last frame and it.
    EXPECT_NEAR(m.keyframe(m.clips[1].first_keyframe)[5], 20.0, 1e-5);
    EXPECT_NEAR(m.keyframe(m.clips[0].first_keyframe + 3)[5], 10.0, 1e-5);
}

TEST_F(Md2Loader, HostileHeadersGiveOneLineErrors) {
    expect_field_error(tiny_md2(), "overflow.md2", kVertices, int32_t(0x40000000),
                       "header counts are invalid");  // 40 + 4 · vertices overflows a 32-bit int
    {
        test::ByteImage m = tiny_md2();
        m.put<int32_t>(kVertices, 0x7FFFFFFF);
        m.put<int32_t>(kFrameSize, 0x7FFFFFFF);
        expect_error("huge.md2", m, "header counts are invalid");
    }
    expect_field_error(tiny_md2(), "frames.md2", kFrames, int32_t(0x7FFFFFFF), "truncated");
    expect_field_error(tiny_md2(), "offset.md2", kOfsFrames, int32_t(0x7FFFFFF0), "truncated");
    expect_field_error(tiny_md2(), "negative.md2", kOfsTris, int32_t(-12), "truncated");
    expect_field_error(tiny_md2(), "index.md2", 68 + 2, uint16_t(3), "names vertex 3, there are 3");
    expect_field_error(tiny_md2(), "nan.md2", 80, float(NAN), "NaN");
    test::ByteImage m = tiny_md2();
    m.bytes.resize(40);
    expect_error("short.md2", m, "no MD2 header");
    LoadOptions zero_rate;
    zero_rate.sample_rate = 0;
    expect_error("rate.md2", tiny_md2(), "sample rate", zero_rate);
}

// Every byte of the tiny file set in turn to 0x00, 0x7F, 0x80 and 0xFF (counts, offsets, indices,
// floats become huge, negative, NaN): each copy loads or fails with a LoadError, nothing else
// (under scripts/test-sanitized.sh: no memory error, no undefined behaviour).
TEST_F(Md2Loader, EveryByteMutatedLoadsOrFailsCleanly) {
    expect_every_byte_mutation_loads_or_fails(tiny_md2(), "mutated.md2");
}

TEST_F(Md2Loader, LoadingBudgetIsCheckedBeforeSampling) {
    LoadOptions small;
    small.max_keyframe_bytes = 4 * 3 * 12 - 1;  // one byte less than the four keyframes of three vertices
    expect_error("budget.md2", tiny_md2(), "loading budget", small);
    small.max_keyframe_bytes = 4 * 3 * 12;
    EXPECT_EQ(load_md2(write("fits.md2", tiny_md2()), small).keyframe_count(), 4u);
}

TEST(Md2Characters, EveryMd2InSharedDataLoads) {
    const fs::path data = fs::path(ANIMORDER_SOURCE_DIR) / ".." / "shared" / "data";
    ANIMORDER_REQUIRE_DATA(data);
    animorder::test::DataFiles files;  // every file is checked; the missing ones are named at the end
    for (const char* f : {"md2-dolphin/dolphin.md2", "md2-faerie/faerie.md2", "md2-sydney/sydney.md2"}) {
        SCOPED_TRACE(f);
        if (!files.present(data / f)) continue;
        AnimatedMesh m;
        ASSERT_NO_THROW(m = load_md2((data / f).string()));
        EXPECT_GT(m.triangle_count(), 100u);
        EXPECT_GE(m.clips.size(), 1u);
        EXPECT_NO_THROW(validate_animated_mesh(m));
    }
    ANIMORDER_REQUIRE_ALL_DATA(files);
}
