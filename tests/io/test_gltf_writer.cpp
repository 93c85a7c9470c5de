// glTF output: the orders written into the file they came from. It must validate with the Khronos
// glTF Validator, read back with the same vertices and keyframes, hold every order as a
// permutation of the original triangles with their winding, keep what it does not touch, and be
// byte-identical for the same input.
#include "animorder/animated_mesh.h"
#include "animorder/clustering.h"
#include "animorder/gltf_extension.h"
#include "animorder/gltf_loader.h"
#include "animorder/gltf_writer.h"
#include "animorder/load.h"
#include "animorder/methods.h"
#include "animorder/procedural_character.h"
#include "animorder/sidecar.h"
#include "animorder/triangle_order.h"
#include "animorder/viewpoints.h"
#include "support/meshes.h"

#define ANIMORDER_RUNTIME_IMPLEMENTATION
#include "animorder_runtime.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include "support/files.h"
#include "support/require.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

using namespace animorder;
namespace fs = std::filesystem;

namespace {

const std::string kData = test::shared_data_path().string();

struct Written {
    AnimatedMesh mesh;
    AnimatedMethodResult method;
    fs::path path;
};

Written optimise_and_write(const std::string& input, const fs::path& output) {
    Written w;
    w.mesh = load_gltf(input);
    ClusteringSettings s;
    s.clusters = 3;
    s.views = 12;
    s.resolution = 48;
    s.max_iterations = 3;
    w.method = run_han_sander(w.mesh, false, 0.85, 16, s);
    w.path = output;
    std::ofstream(output, std::ios::binary) << gltf_with_orders(
        input, output.string(), w.mesh, w.method.buffers, 1, w.method.framing, "single", output.extension() == ".glb");
    return w;
}

class GltfWriter : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("animorder-writer-" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    fs::path dir_;
};

}  // namespace

TEST_F(GltfWriter, OutputValidatesAndReadsBackWithEveryOrder) {
    for (const char* name : {"gltf-cesiumman/CesiumMan.glb", "glb-robot-expressive/RobotExpressive.glb",
                             "gltf-morph-stress-test/MorphStressTest.gltf"}) {
        SCOPED_TRACE(name);
        ANIMORDER_REQUIRE_DATA(kData + name);
        const fs::path out = dir_ / (std::string("out") + fs::path(name).extension().string());
        const Written w = optimise_and_write(kData + name, out);

        // The output may not add a single validator error to those of the input (MorphStressTest
        // in ../shared/data lacks its PNG files: the same missing-image errors in both).
        // Both reports go to the scratch folder: ../shared/data is read only.
        std::string report, input_report, why;
        ANIMORDER_REQUIRE_OR_SKIP("validator", test::validator_available(why), why);
        const bool valid = test::validate_gltf(out, report, dir_);
        test::validate_gltf(kData + name, input_report, dir_);
        std::printf("%s output: %sinput: %s", name, report.c_str(), input_report.c_str());
        const nlohmann::json r = nlohmann::json::parse(report), in = nlohmann::json::parse(input_report);
        if (!valid) {
            EXPECT_EQ(r["errors"], in["errors"]) << report;
            for (const auto& m : r["messages"]) EXPECT_EQ(m["code"], "IO_ERROR") << report;
        }

        // Same vertices and keyframes; the drawn indices are the fallback order.
        const AnimatedMesh back = load_gltf(out.string());
        EXPECT_EQ(back.vertex_count, w.mesh.vertex_count);
        EXPECT_EQ(back.keyframe_positions, w.mesh.keyframe_positions);
        std::vector<uint32_t> fallback(w.mesh.indices.size());
        apply_triangle_order(fallback.data(), w.mesh.indices.data(), w.method.buffers.orders[1].data(),
                             w.mesh.triangle_count());
        EXPECT_EQ(back.indices, fallback);
        EXPECT_TRUE(test::same_triangles_same_winding(w.mesh.indices, back.indices));
    }
}

TEST_F(GltfWriter, DeterministicAndLeavesTheRestAlone) {
    const std::string input = kData + "gltf-cesiumman/CesiumMan.glb";
    ANIMORDER_REQUIRE_DATA(input);
    const Written a = optimise_and_write(input, dir_ / "a.gltf");
    const Written b = optimise_and_write(input, dir_ / "b.gltf");
    const std::string text = test::slurp(a.path);
    EXPECT_EQ(text, test::slurp(b.path));
    // Materials, skins, animations and images are still there, and the extension describes the orders.
    for (const char* key : {"\"materials\"", "\"skins\"", "\"animations\"", "\"images\"",
                            "\"ANIMORDER_animated_triangle_orders\"", "\"orders\"", "\"extensionsUsed\""})
        EXPECT_NE(text.find(key), std::string::npos) << key;
}

TEST_F(GltfWriter, RefusesAMeshItWasNotReadFrom) {
    const std::string input = kData + "gltf-fox/Fox.glb";
    ANIMORDER_REQUIRE_DATA(input);
    const AnimatedMesh character = make_procedural_character();
    MethodBuffers buffers;
    std::vector<uint32_t> order(character.triangle_count());
    for (size_t i = 0; i < order.size(); ++i) order[i] = uint32_t(i);
    buffers.orders.push_back(order);
    const Framing framing = frame_animated_mesh(character);
    EXPECT_THROW(gltf_with_orders(input, (dir_ / "x.glb").string(), character, buffers, 0, framing, "original", true),
                 LoadError);
}

TEST_F(GltfWriter, TheExtensionHoldsEveryOrderAsOneIndexRangeAndTheTables) {
    const std::string input = kData + "gltf-cesiumman/CesiumMan.glb";
    ANIMORDER_REQUIRE_DATA(input);
    const Written w = optimise_and_write(input, dir_ / "ranges.glb");
    const OrdersExtensionCheck r = check_orders_extension(w.path.string());
    ASSERT_TRUE(r.errors.empty()) << r.errors.front();
    const MethodBuffers& buffers = w.method.buffers;
    EXPECT_EQ(r.buffer_count, buffers.orders.size());
    EXPECT_EQ(r.fallback, 1u);
    ASSERT_EQ(r.primitives.size(), w.mesh.primitives.size());
    for (size_t i = 0; i < w.mesh.primitives.size(); ++i) {
        const Primitive& p = w.mesh.primitives[i];
        const ExtensionPrimitive& e = r.primitives[i];
        EXPECT_EQ(e.component_type, 5123);  // CesiumMan's 3273 vertices fit in 16 bits
        // Order b is indices [b·n, (b+1)·n): the method's order b of this primitive, local.
        for (size_t b = 0; b < buffers.orders.size(); ++b) {
            std::vector<uint32_t> global(w.mesh.indices.size());
            apply_triangle_order(global.data(), w.mesh.indices.data(), buffers.orders[b].data(),
                                 w.mesh.triangle_count());
            for (size_t k = 0; k < p.index_count; ++k)
                ASSERT_EQ(e.orders[b * p.index_count + k], global[p.first_index + k] - p.vertex_base) << b << " " << k;
        }
    }
    ASSERT_EQ(r.clips.size(), w.mesh.clips.size());
    for (size_t c = 0; c < r.clips.size(); ++c) {
        EXPECT_EQ(r.clips[c].cells, buffers.tables[c].cells);
        EXPECT_EQ(r.clips[c].buffer_base, buffers.table_base[c]);
        EXPECT_EQ(r.clips[c].keyframes, w.mesh.clips[c].keyframe_count);
        EXPECT_EQ(r.clips[c].animation, int(c));
        const std::vector<float> centres(
            w.method.framing.centres.begin() + ptrdiff_t(3 * w.mesh.clips[c].first_keyframe),
            w.method.framing.centres.begin() +
                ptrdiff_t(3 * (w.mesh.clips[c].first_keyframe + w.mesh.clips[c].keyframe_count)));
        EXPECT_EQ(r.clips[c].centers, centres);
    }
}

// The extension's lookup as docs/extension/README.md states it, written out here from the text,
// against the C runtime reading the sidecar of the same run: the same buffer for every probe, and
// the sidecar's buffer b equal to every primitive's range b (offset by its vertex base).
namespace {

int extension_lookup(const ExtensionClip& c, double seconds_since_start, const float camera[3]) {
    double k = (seconds_since_start)*c.sample_rate;
    k = k != k ? 0.0 : std::floor(k + 0.5);
    const size_t f = k <= 0 ? 0 : (k >= double(c.keyframes - 1) ? c.keyframes - 1 : size_t(k));
    const double d[3] = {double(camera[0]) - c.centers[3 * f], double(camera[1]) - c.centers[3 * f + 1],
                         double(camera[2]) - c.centers[3 * f + 2]};
    const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    const double theta = std::acos(std::clamp(d[1] / length, -1.0, 1.0));
    double phi = std::atan2(d[0], d[2]);
    if (phi < 0) phi += 2 * M_PI;
    double x = std::floor(theta / M_PI * (c.theta_steps - 1) + 0.5);
    const size_t i = x <= 0 ? 0 : (x >= c.theta_steps - 1 ? c.theta_steps - 1 : size_t(x));
    x = std::floor(phi / (2 * M_PI) * c.phi_steps + 0.5);
    const size_t j = x <= 0 || x >= c.phi_steps ? 0 : size_t(x);
    return int(c.buffer_base + c.cells[(f * c.theta_steps + i) * c.phi_steps + j]);
}

}  // namespace

TEST_F(GltfWriter, TheExtensionAndTheSidecarAnswerAlike) {
    const std::string input = kData + "gltf-cesiumman/CesiumMan.glb";
    ANIMORDER_REQUIRE_DATA(input);
    const Written w = optimise_and_write(input, dir_ / "same.glb");
    const OrdersExtensionCheck r = read_orders_extension(w.path.string());
    const std::string sidecar = serialize_sidecar(w.mesh, w.method.buffers, w.method.framing);
    std::vector<uint32_t> aligned((sidecar.size() + 3) / 4);
    std::memcpy(aligned.data(), sidecar.data(), sidecar.size());
    animorder_runtime rt;
    ASSERT_EQ(animorder_runtime_open(&rt, aligned.data(), sidecar.size()), 0);
    ASSERT_EQ(rt.buffer_count, r.buffer_count);
    for (uint32_t b = 0; b < r.buffer_count; ++b) {
        const uint32_t* indices = animorder_buffer(&rt, int(b));
        for (size_t p = 0; p < w.mesh.primitives.size(); ++p) {
            const Primitive& prim = w.mesh.primitives[p];
            for (size_t k = 0; k < prim.index_count; ++k)
                ASSERT_EQ(indices[prim.first_index + k],
                          r.primitives[p].orders[b * prim.index_count + k] + prim.vertex_base);
        }
    }
    size_t probes = 0;
    for (uint32_t c = 0; c < r.clips.size(); ++c)
        for (double t : {-1.0, 0.0, 0.04, 0.5, 1.0, 100.0})
            for (int v = 0; v < 200; ++v) {
                const double a = v * 2.399963, z = 1.0 - 2.0 * (v + 0.5) / 200;  // Fibonacci sphere
                const float camera[3] = {float(3 * std::sqrt(1 - z * z) * std::cos(a)), float(3 * z),
                                         float(3 * std::sqrt(1 - z * z) * std::sin(a))};
                ASSERT_EQ(extension_lookup(r.clips[c], t, camera), animorder_select_time(&rt, c, t, camera, nullptr))
                    << c << " " << t << " " << v;
                ++probes;
            }
    EXPECT_EQ(probes, r.clips.size() * 1200);
}
