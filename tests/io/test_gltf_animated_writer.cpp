// glTF output of a whole animated mesh (keyframes as morph targets driven by one-hot weights):
// it must read back through load_gltf with the same triangles, clips and keyframes, be
// byte-identical for the same mesh, and pass the Khronos glTF Validator.
#include "animorder/animated_mesh.h"
#include "animorder/gltf_animated_writer.h"
#include "animorder/gltf_loader.h"
#include "animorder/invalid_input.h"
#include "animorder/load.h"
#include "animorder/procedural_character.h"
#include "animorder/subdivide_animated_mesh.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include "support/files.h"
#include "support/require.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

using namespace animorder;
namespace fs = std::filesystem;

namespace {

// A small animated mesh: two primitives (a tetrahedron and a lone triangle, sharing no vertex),
// one unreferenced vertex, and three keyframes in two clips at different rates.
AnimatedMesh small_mesh() {
    AnimatedMesh m;
    m.name = "small";
    m.vertex_count = 8;
    m.indices = {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2, 5, 6, 7};
    m.primitives = {{"tet", 0, 12}, {"flag", 12, 3}};
    m.primitives[1].double_sided = true;  // a blended double-sided flag: its material is written
    m.primitives[1].alpha_mode = AlphaMode::Blend;
    const float rest[] = {1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1, 9, 9, 9, 2, 0, 0, 3, 0, 0, 2, 1, 0};
    for (int k = 0; k < 3; ++k)
        for (size_t i = 0; i < 24; ++i)
            m.keyframe_positions.push_back(rest[i] + 0.25f * float(k) * float(i % 3 == 1) + 0.1f * float(k * (i % 5)));
    m.clips = {{"walk", 1.0 / 30, 30, 0, 2}, {"pose", 0, 24, 2, 1}};
    return m;
}

double radius(const AnimatedMesh& m) {
    double r = 0;
    for (float x : m.keyframe_positions) r = std::max(r, double(std::fabs(x)));
    return r;
}

// Same clips and keyframe counts; each triangle's corners at the same positions in every keyframe.
void expect_same_animation(const AnimatedMesh& a, const AnimatedMesh& b) {
    ASSERT_EQ(a.triangle_count(), b.triangle_count());
    ASSERT_EQ(a.keyframe_count(), b.keyframe_count());
    ASSERT_EQ(a.clips.size(), b.clips.size());
    for (size_t c = 0; c < a.clips.size(); ++c) {
        EXPECT_EQ(a.clips[c].name, b.clips[c].name);
        EXPECT_EQ(a.clips[c].first_keyframe, b.clips[c].first_keyframe);
        EXPECT_EQ(a.clips[c].keyframe_count, b.clips[c].keyframe_count);
    }
    ASSERT_EQ(a.primitives.size(), b.primitives.size());
    for (size_t p = 0; p < a.primitives.size(); ++p) {
        EXPECT_EQ(a.primitives[p].first_index, b.primitives[p].first_index);
        EXPECT_EQ(a.primitives[p].index_count, b.primitives[p].index_count);
        EXPECT_EQ(a.primitives[p].double_sided, b.primitives[p].double_sided) << p;
        EXPECT_EQ(a.primitives[p].alpha_mode, b.primitives[p].alpha_mode) << p;
    }
    const double tolerance = 1e-5 * radius(a);
    double worst = 0;
    for (size_t k = 0; k < a.keyframe_count(); ++k)
        for (size_t i = 0; i < a.indices.size(); ++i)
            for (int c = 0; c < 3; ++c)
                worst = std::max(worst, std::fabs(double(a.keyframe(k)[3 * a.indices[i] + size_t(c)]) -
                                                  double(b.keyframe(k)[3 * b.indices[i] + size_t(c)])));
    EXPECT_LE(worst, tolerance);
}

class GltfAnimatedWriter : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("animorder-animated-writer-" + std::to_string(::getpid()) + "-" +
                                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    fs::path write(const AnimatedMesh& m, const std::string& name) {
        const fs::path path = dir_ / name;
        std::ofstream(path, std::ios::binary) << gltf_animated_mesh(m, path.extension() == ".glb");
        return path;
    }
    fs::path dir_;
};

}  // namespace

TEST_F(GltfAnimatedWriter, SmallMeshReadsBackExactlyInBothForms) {
    const AnimatedMesh m = small_mesh();
    for (const char* name : {"small.glb", "small.gltf"}) {
        SCOPED_TRACE(name);
        const fs::path path = write(m, name);
        // Each clip is sampled at its own rate, as it was written.
        LoadOptions at_30, at_24;
        at_24.sample_rate = 24;
        const AnimatedMesh back30 = load_gltf(path.string(), at_30), back24 = load_gltf(path.string(), at_24);
        // The unreferenced vertex is not written; the rest keeps its order (primitives' vertices ascending).
        EXPECT_EQ(back30.vertex_count, 7u);
        EXPECT_EQ(back30.indices, (std::vector<uint32_t>{0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2, 4, 5, 6}));
        ASSERT_EQ(back30.clips.size(), 2u);
        EXPECT_EQ(back30.clips[0].name, "walk");
        EXPECT_EQ(back30.clips[0].keyframe_count, 2u);
        EXPECT_EQ(back24.clips[1].name, "pose");
        EXPECT_EQ(back24.clips[1].keyframe_count, 1u);
        for (size_t k = 0; k < 3; ++k) {
            const AnimatedMesh& back = k < 2 ? back30 : back24;
            for (size_t i = 0; i < m.indices.size(); ++i)
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(back.keyframe(k)[3 * back.indices[i] + size_t(c)],
                                m.keyframe(k)[3 * m.indices[i] + size_t(c)], 1e-5 * radius(m))
                        << "keyframe " << k << " index " << i;
        }
    }
}

TEST_F(GltfAnimatedWriter, SubdividedCharacterRoundTripsDeterministicAndValid) {
    const AnimatedMesh m = subdivide_animated_mesh(make_procedural_character(), 1);
    const fs::path a = write(m, "a.glb"), b = write(m, "b.glb");
    EXPECT_EQ(test::slurp_existing(a), test::slurp_existing(b));  // byte-deterministic
    expect_same_animation(m, load_gltf(a.string()));

    std::string report, why;
    ANIMORDER_REQUIRE_OR_SKIP("validator", test::validator_available(why), why);
    const bool valid = test::validate_gltf(a, report, dir_);
    std::printf("validator: %s", report.c_str());
    EXPECT_TRUE(valid) << report;
    EXPECT_EQ(nlohmann::json::parse(report)["errors"], 0) << report;
}

TEST_F(GltfAnimatedWriter, SmallGltfPassesTheValidator) {
    const fs::path path = write(small_mesh(), "small.gltf");
    std::string report, why;
    ANIMORDER_REQUIRE_OR_SKIP("validator", test::validator_available(why), why);
    const bool valid = test::validate_gltf(path, report, dir_);
    EXPECT_TRUE(valid) << report;
}

TEST_F(GltfAnimatedWriter, InvalidMeshThrows) {
    AnimatedMesh m = small_mesh();
    m.indices[2] = 99;
    EXPECT_THROW(gltf_animated_mesh(m, true), InvalidInput);
    AnimatedMesh empty;
    EXPECT_THROW(gltf_animated_mesh(empty, true), InvalidInput);
}
