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
    std::memcpy(words.data(), bytes.data(), bytes.size());
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
        apply_triangle_order(expected.data(), f.mesh.indices.data(), f.result.buffers.orders[b].data(), f.mesh.triangle_count());
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

extern "C" int animorder_runtime_c_check(void);

TEST(Runtime, ImplementationIsPlainC) { EXPECT_EQ(animorder_runtime_c_check(), 0); }
