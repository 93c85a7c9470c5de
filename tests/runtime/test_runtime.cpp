// The single-header runtime reading the sidecar that the library writes: it must return the
// node's cluster at every clustering viewpoint, by keyframe and by time, and refuse bad bytes.
// The implementation is compiled as C99 in runtime_c_check.c: the C++ side only includes it.
#include "animorder_runtime.h"

#include "animorder/animated_mesh.h"
#include "animorder/clustering.h"
#include "animorder/methods.h"
#include "animorder/procedural_character.h"
#include "animorder/sidecar.h"
#include "animorder/triangle_order.h"

#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <vector>

using namespace animorder;

namespace {
struct Fixture {
    AnimatedMesh mesh = make_procedural_character();
    AnimatedMethodResult result;
    std::string bytes;
    Fixture() {
        ClusteringSettings s;
        s.clusters = 3;
        s.views = 42;
        s.resolution = 48;
        s.max_iterations = 3;
        result = run_han_sander(mesh, /*joint=*/false, 0.85, 16, s);
        bytes = serialize_sidecar(mesh, result.buffers, result.framing);
    }
};
const Fixture& fixture() {
    static const Fixture f;
    return f;
}
// A 4-byte aligned copy, as an application would load it.
std::vector<uint32_t> aligned(const std::string& bytes) {
    std::vector<uint32_t> words((bytes.size() + 3) / 4);
    if (!bytes.empty()) std::memcpy(words.data(), bytes.data(), bytes.size());
    return words;
}
}  // namespace

TEST(Runtime, SelectsTheNodesClusterAtEveryClusteringViewpoint) {
    const Fixture& f = fixture();
    const std::vector<uint32_t> words = aligned(f.bytes);
    animorder_runtime rt;
    ASSERT_EQ(animorder_runtime_open(&rt, words.data(), f.bytes.size()), 0);
    EXPECT_EQ(rt.clip_count, f.mesh.clips.size());
    EXPECT_EQ(rt.buffer_count, 3 * f.mesh.clips.size());
    for (size_t c = 0; c < f.mesh.clips.size(); ++c) {
        const ClusteringResult& run = f.result.runs[c];
        const size_t views = run.directions.size() / 3;
        const float radius = f.result.run_radius[c];
        for (size_t k = 0; k < f.mesh.clips[c].keyframe_count; ++k) {
            const float* centre = &f.result.framing.centres[3 * (f.mesh.clips[c].first_keyframe + k)];
            for (size_t v = 0; v < views; ++v) {
                // The camera where the clustering put it: centre + 3R · direction, in model space.
                float camera[3];
                for (int d = 0; d < 3; ++d) camera[d] = centre[d] + 3 * radius * run.directions[3 * v + d];
                const int expected = int(3 * c + run.assignment[k * views + v]);
                ASSERT_EQ(animorder_select_keyframe(&rt, uint32_t(c), double(k), camera, nullptr), expected)
                    << "clip " << c << " keyframe " << k << " view " << v;
                ASSERT_EQ(animorder_select_time(&rt, uint32_t(c), double(k) / 30.0, camera, centre), expected);
            }
        }
    }
}

TEST(Runtime, BuffersAreTheOrdersAppliedToTheMesh) {
    const Fixture& f = fixture();
    const std::vector<uint32_t> words = aligned(f.bytes);
    animorder_runtime rt;
    ASSERT_EQ(animorder_runtime_open(&rt, words.data(), f.bytes.size()), 0);
    ASSERT_EQ(rt.index_count, f.mesh.indices.size());
    std::vector<uint32_t> expected(f.mesh.indices.size());
    for (size_t b = 0; b < rt.buffer_count; ++b) {
        apply_triangle_order(expected.data(), f.mesh.indices.data(), f.result.buffers.orders[b].data(),
                             f.mesh.triangle_count());
        const uint32_t* got = animorder_buffer(&rt, int(b));
        ASSERT_NE(got, nullptr);
        EXPECT_TRUE(std::equal(expected.begin(), expected.end(), got)) << "buffer " << b;
    }
    EXPECT_EQ(animorder_buffer(&rt, int(rt.buffer_count)), nullptr);
    EXPECT_EQ(animorder_buffer(&rt, -1), nullptr);
}

TEST(Runtime, RefusesCorruptOrTruncatedBytes) {
    const Fixture& f = fixture();
    animorder_runtime rt;
    for (size_t cut : {size_t(0), size_t(10), size_t(40), f.bytes.size() / 2, f.bytes.size() - 1})
        EXPECT_LT(animorder_runtime_open(&rt, f.bytes.data(), cut), 0) << "cut at " << cut;
    std::string bad = f.bytes;
    bad[0] = 'X';
    EXPECT_EQ(animorder_runtime_open(&rt, bad.data(), bad.size()), -1);
    const std::vector<uint32_t> words = aligned(f.bytes);
    ASSERT_EQ(animorder_runtime_open(&rt, words.data(), f.bytes.size()), 0);
    const float at_centre[3] = {0, 0, 0}, centre[3] = {0, 0, 0};
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, 0, at_centre, centre), -1);
    EXPECT_EQ(animorder_select_keyframe(&rt, 99, 0, at_centre, nullptr), -1);
}

// --- Hostile bytes: a tiny sidecar built by hand, and headers whose sizes wrap. ---------------
namespace {
// Little-endian fields written independently of the tool's writer (src/io/sidecar.cpp): a value's
// bytes are its host bytes, and these tests run on little-endian hosts only.
static_assert(sizeof(uint32_t) == 4 && sizeof(float) == 4, "32-bit fields");
template <typename T>
void set_field(std::string& bytes, size_t at, T value) {
    std::memcpy(&bytes[at], &value, sizeof value);
}
template <typename T>
void append_field(std::string& bytes, T value) {
    bytes.resize(bytes.size() + sizeof value);
    set_field(bytes, bytes.size() - sizeof value, value);
}
void put_u32(std::string& out, uint32_t v) { append_field(out, v); }
void put_f32(std::string& out, float f) { append_field(out, f); }
void set_u32(std::string& bytes, size_t at, uint32_t v) { set_field(bytes, at, v); }
void set_f32(std::string& bytes, size_t at, float f) { set_field(bytes, at, f); }
std::string header(uint32_t buffers, uint32_t indices, uint32_t clips) {
    std::string out = "AOR1";
    put_u32(out, 1);
    put_u32(out, buffers);
    put_u32(out, indices);
    put_u32(out, clips);
    return out;
}

// Offsets in the tiny sidecar below.
constexpr size_t kClip = 20, kBuffers = 52, kCells = 100, kCentres = 124, kTinySize = 148;

// 4 buffers of 3 indices, one clip of 2 keyframes on a 3 × 4 grid at 10 keyframes/s, buffer
// base 0. Cells are 0 except (f,i,j) = (0,1,1) → 1, (0,1,2) → 2, (0,1,0) → 3, (1,2,0) → 3, at
// (f·3 + i)·4 + j. Keyframe 0 is centred at the origin, keyframe 1 at (10, 0, 0).
std::string tiny_sidecar() {
    std::string out = header(4, 3, 1);
    for (uint32_t v : {2u, 3u, 4u}) put_u32(out, v);  // keyframes, theta_steps, phi_steps
    put_f32(out, 10.0f);                              // sample rate
    for (uint32_t v : {0u, uint32_t(kCells), uint32_t(kCentres), 0u}) put_u32(out, v);
    for (uint32_t b = 0; b < 4; ++b)
        for (uint32_t i = 0; i < 3; ++i) put_u32(out, 10 * b + i);
    std::string cells(24, '\0');
    cells[5] = 1;
    cells[6] = 2;
    cells[4] = 3;
    cells[20] = 3;
    out += cells;
    for (float v : {0.f, 0.f, 0.f, 10.f, 0.f, 0.f}) put_f32(out, v);
    return out;
}
int open_bytes(const std::string& bytes) {
    animorder_runtime rt;
    const std::vector<uint32_t> words = aligned(bytes);
    return animorder_runtime_open(&rt, words.data(), bytes.size());
}
}  // namespace

TEST(RuntimeHostile, TinyHandBuiltSidecarAnswersTheHandWorkedCells) {
    const std::string bytes = tiny_sidecar();
    ASSERT_EQ(bytes.size(), kTinySize);
    const std::vector<uint32_t> words = aligned(bytes);
    animorder_runtime rt;
    ASSERT_EQ(animorder_runtime_open(&rt, words.data(), bytes.size()), 0);
    EXPECT_EQ(rt.buffer_count, 4u);
    EXPECT_EQ(rt.index_count, 3u);
    EXPECT_EQ(rt.clip_count, 1u);
    const float up[3] = {0, 5, 0}, right[3] = {5, 0, 0}, back[3] = {0, 0, -5};
    const float almost_front[3] = {-0.001f, 0, 5};                       // φ just under 2π rounds to cell j = 0
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, 0, up, nullptr), 0);     // θ 0 → i 0, j 0
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, 0, right, nullptr), 1);  // θ π/2, φ π/2 → (1, 1)
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, 0, back, nullptr), 2);   // θ π/2, φ π → (1, 2)
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, 0, almost_front, nullptr), 3);  // (1, 0)
    // Keyframe 1, its stored centre (10, 0, 0): straight below → θ π → i 2, j 0.
    const float below_second[3] = {10, -5, 0};
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, 1, below_second, nullptr), 3);
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, 0.6, below_second, nullptr), 3);  // rounds to 1
    EXPECT_EQ(animorder_select_time(&rt, 0, 0.1, below_second, nullptr), 3);      // 0.1 s × 10 = 1
    // At keyframe 0 (0.04 s × 10 = 0.4) the same camera is seen from the origin: θ = acos(−5/√125)
    // ≈ 2.034 → i = floor(1.295 + 0.5) = 1, φ = π/2 → j 1: cell (0, 1, 1) = 1.
    EXPECT_EQ(animorder_select_time(&rt, 0, 0.04, below_second, nullptr), 1);
    // Clamped and NaN keyframes and times.
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, 1e300, below_second, nullptr), 3);
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, inf, below_second, nullptr), 3);
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, -inf, right, nullptr), 1);
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, nan, right, nullptr), 1);
    EXPECT_EQ(animorder_select_time(&rt, 0, nan, right, nullptr), 1);
    EXPECT_EQ(animorder_select_time(&rt, 0, -5, right, nullptr), 1);
    EXPECT_EQ(animorder_select_time(&rt, 0, 1e308, below_second, nullptr), 3);
    // Buffers: 10·b + i.
    for (int b = 0; b < 4; ++b) {
        const uint32_t* indices = animorder_buffer(&rt, b);
        ASSERT_NE(indices, nullptr);
        EXPECT_EQ(indices[0], uint32_t(10 * b));
        EXPECT_EQ(indices[2], uint32_t(10 * b + 2));
    }
}

TEST(RuntimeHostile, QueriesRefuseBadArgumentsWithoutReadingOutOfBounds) {
    const std::string bytes = tiny_sidecar();
    const std::vector<uint32_t> words = aligned(bytes);
    animorder_runtime rt;
    ASSERT_EQ(animorder_runtime_open(&rt, words.data(), bytes.size()), 0);
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const float right[3] = {5, 0, 0}, nan_camera[3] = {nan, 0, 0}, inf_camera[3] = {inf, 0, 0};
    const float nan_centre[3] = {0, nan, 0};
    EXPECT_EQ(animorder_select_keyframe(&rt, 1, 0, right, nullptr), -1);
    EXPECT_EQ(animorder_select_keyframe(&rt, UINT32_MAX, 0, right, nullptr), -1);
    EXPECT_EQ(animorder_select_time(&rt, 1, 0, right, nullptr), -1);
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, 0, nullptr, nullptr), -1);
    EXPECT_EQ(animorder_select_time(&rt, 0, 0, nullptr, nullptr), -1);
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, 0, nan_camera, nullptr), -1);
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, 0, inf_camera, nullptr), -1);
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, 0, right, nan_centre), -1);
    EXPECT_EQ(animorder_select_keyframe(nullptr, 0, 0, right, nullptr), -1);
    EXPECT_EQ(animorder_select_time(nullptr, 0, 0, right, nullptr), -1);
    EXPECT_EQ(animorder_buffer(&rt, 4), nullptr);
    EXPECT_EQ(animorder_buffer(&rt, INT32_MAX), nullptr);
    EXPECT_EQ(animorder_buffer(&rt, INT32_MIN), nullptr);
    EXPECT_EQ(animorder_buffer(nullptr, 0), nullptr);
    // A runtime the application changed after opening: checked against its bytes again.
    animorder_runtime changed = rt;
    changed.clip_count = 1000;
    EXPECT_EQ(animorder_select_keyframe(&changed, 0, 0, right, nullptr), -1);
    changed = rt;
    changed.index_count = 0x80000000u;
    EXPECT_EQ(animorder_buffer(&changed, 1), nullptr);
    changed = rt;
    changed.size = 100;  // the tables cut off
    EXPECT_EQ(animorder_select_keyframe(&changed, 0, 0, right, nullptr), -1);
    // A failed open leaves a runtime with nothing in it.
    animorder_runtime failed = rt;
    EXPECT_EQ(animorder_runtime_open(&failed, words.data(), 19), -2);
    EXPECT_EQ(failed.data, nullptr);
    EXPECT_EQ(failed.clip_count, 0u);
    EXPECT_EQ(failed.buffer_count, 0u);
    EXPECT_EQ(animorder_select_keyframe(&failed, 0, 0, right, nullptr), -1);
    EXPECT_EQ(animorder_buffer(&failed, 0), nullptr);
    EXPECT_EQ(animorder_runtime_open(nullptr, words.data(), bytes.size()), -2);
    EXPECT_EQ(animorder_runtime_open(&failed, nullptr, bytes.size()), -2);
    // Loaded one byte off 4-byte alignment: it opens and selects, but no misaligned pointer.
    std::vector<uint32_t> shifted_words(words.size() + 1);
    unsigned char* shifted = reinterpret_cast<unsigned char*>(shifted_words.data()) + 1;
    std::memcpy(shifted, bytes.data(), bytes.size());
    ASSERT_EQ(animorder_runtime_open(&rt, shifted, bytes.size()), 0);
    EXPECT_EQ(animorder_select_keyframe(&rt, 0, 0, right, nullptr), 1);
    EXPECT_EQ(animorder_buffer(&rt, 0), nullptr);
}

// buffer_count × index_count × 4 = 2^31 · 2^31 · 4 = 2^64 wrapped to 0 in 64 bits: a 20-byte file
// opened with success and animorder_buffer(1) pointed 8 GiB past it.
TEST(RuntimeHostile, BufferSizeThatWrapsIsTruncated) {
    EXPECT_EQ(open_bytes(header(0x80000000u, 0x80000000u, 0)), -2);
    EXPECT_EQ(open_bytes(header(0x40000000u, 0x40000000u, 0)), -2);  // 2^62, no wrap, too big
    EXPECT_EQ(open_bytes(header(0xffffffffu, 0xffffffffu, 0xffffffffu)), -2);
    EXPECT_EQ(open_bytes(header(1, 1, 0)), -2);  // 4 bytes of indices missing
    std::string one = header(1, 3, 0);
    for (uint32_t v : {7u, 8u, 9u}) put_u32(one, v);
    EXPECT_EQ(open_bytes(one), 0);
    // Any number of empty buffers fits, but buffer ids are ints.
    EXPECT_EQ(open_bytes(header(0x80000000u, 0, 0)), -4);
    EXPECT_EQ(open_bytes(header(0x7fffffffu, 0, 0)), 0);
}

// A sidecar without a buffer opened with success and animorder_buffer(rt, 0), the fallback, was
// NULL; one of 1 or 2 indices a buffer drew a partial triangle.
TEST(RuntimeHostile, NoBufferOrPartialTrianglesAreRefused) {
    EXPECT_EQ(open_bytes(header(0, 0, 0)), -4);
    EXPECT_EQ(open_bytes(header(0, 3, 0)), -4);
    for (uint32_t indices : {1u, 2u, 4u}) {
        std::string bytes = header(1, indices, 0);
        for (uint32_t i = 0; i < indices; ++i) put_u32(bytes, i);
        EXPECT_EQ(open_bytes(bytes), -4) << indices << " indices";
    }
}

// keyframes × theta × phi = 4 · 2^31 · 2^31 = 2^64 wrapped to 0: the table passed the bounds check
// and animorder_select_keyframe read gigabytes past the bytes.
TEST(RuntimeHostile, TableSizeThatWrapsIsOutOfBounds) {
    std::string bytes = header(1, 3, 1);
    for (uint32_t v : {4u, 0x80000000u, 0x80000000u}) put_u32(bytes, v);
    put_f32(bytes, 30.0f);
    for (uint32_t v : {0u, 64u, 64u, 0u}) put_u32(bytes, v);  // base, cells, centres, reserved
    for (uint32_t i = 0; i < 3; ++i) put_u32(bytes, i);
    bytes.append(48, '\0');  // 4 centres
    ASSERT_EQ(bytes.size(), 112u);
    EXPECT_EQ(open_bytes(bytes), -3);
    // The same with a table size that only just fits in 64 bits.
    set_u32(bytes, kClip, 1);
    set_u32(bytes, kClip + 4, 0xffffffffu);
    set_u32(bytes, kClip + 8, 0xffffffffu);
    EXPECT_EQ(open_bytes(bytes), -3);
    // And a keyframe count whose table and centres are gigabytes.
    set_u32(bytes, kClip + 0, 0x40000000u);
    set_u32(bytes, kClip + 4, 2);
    set_u32(bytes, kClip + 8, 1);
    EXPECT_EQ(open_bytes(bytes), -3);
}

TEST(RuntimeHostile, CorruptHeadersAreRefusedWithTheirCode) {
    const std::string good = tiny_sidecar();
    ASSERT_EQ(open_bytes(good), 0);
    for (size_t cut = 0; cut < good.size(); ++cut) EXPECT_LT(open_bytes(good.substr(0, cut)), 0) << "cut at " << cut;
    EXPECT_EQ(open_bytes(good.substr(0, 19)), -2);
    EXPECT_EQ(open_bytes(good.substr(0, kBuffers + 47)), -2);  // inside the index buffers
    EXPECT_EQ(open_bytes(good.substr(0, kCentres + 23)), -3);  // inside the centres
    std::string bytes = good;
    bytes[3] = '2';
    EXPECT_EQ(open_bytes(bytes), -1);  // magic
    bytes = good;
    set_u32(bytes, 4, 2);
    EXPECT_EQ(open_bytes(bytes), -1);  // version
    bytes = good;
    set_u32(bytes, 16, 3);
    EXPECT_EQ(open_bytes(bytes), -2);  // clip records past the end... of the buffers
    bytes = good;
    set_u32(bytes, kClip + 20, kCentres + 1);
    EXPECT_EQ(open_bytes(bytes), -3);  // table past the end
    bytes = good;
    set_u32(bytes, kClip + 20, kBuffers);
    EXPECT_EQ(open_bytes(bytes), -3);  // table inside the buffers
    bytes = good;
    set_u32(bytes, kClip + 24, kTinySize - 23);
    EXPECT_EQ(open_bytes(bytes), -3);  // centres past the end
    bytes = good;
    set_u32(bytes, kClip + 24, 0xfffffff0u);
    EXPECT_EQ(open_bytes(bytes), -3);
    bytes = good;
    set_u32(bytes, kClip + 24, kCells);
    EXPECT_EQ(open_bytes(bytes), 0);  // centres over the cells: in bounds, allowed
    bytes = good;
    set_u32(bytes, kClip, 0);
    EXPECT_EQ(open_bytes(bytes), -3);  // no keyframes
    bytes = good;
    set_u32(bytes, kClip + 4, 1);
    EXPECT_EQ(open_bytes(bytes), -3);  // theta_steps < 2
    bytes = good;
    set_u32(bytes, kClip + 8, 0);
    EXPECT_EQ(open_bytes(bytes), -3);  // phi_steps 0
    bytes = good;
    set_u32(bytes, kClip + 16, 4);
    EXPECT_EQ(open_bytes(bytes), -4);  // buffer base past the buffers
    bytes = good;
    set_u32(bytes, kClip + 16, 1);
    EXPECT_EQ(open_bytes(bytes), -4);  // base 1 + cell 3 = buffer 4
    bytes = good;
    bytes[kCells + 7] = 4;
    EXPECT_EQ(open_bytes(bytes), -4);  // a cell naming buffer 4
    for (float rate : {0.0f, -10.0f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
        bytes = good;
        set_f32(bytes, kClip + 12, rate);
        EXPECT_EQ(open_bytes(bytes), -4) << "sample rate " << rate;
    }
}

// Two clips sharing one table: within bounds each, but together more than the bytes hold (the
// open-time cell scan stays linear in the size).
TEST(RuntimeHostile, ClipsWhoseTablesTogetherExceedTheBytesAreRefused) {
    std::string bytes = header(1, 0, 2);
    for (int c = 0; c < 2; ++c) {
        for (uint32_t v : {1u, 2u, 8u}) put_u32(bytes, v);
        put_f32(bytes, 30.0f);
        for (uint32_t v : {0u, 84u, 100u, 0u}) put_u32(bytes, v);
    }
    bytes.append(16 + 12, '\0');
    ASSERT_EQ(bytes.size(), 112u);
    EXPECT_EQ(open_bytes(bytes), -3);
    bytes.append(28, '\0');  // room for both
    EXPECT_EQ(open_bytes(bytes), 0);
}

extern "C" int animorder_runtime_c_check(void);

TEST(Runtime, ImplementationIsPlainC) { EXPECT_EQ(animorder_runtime_c_check(), 0); }
