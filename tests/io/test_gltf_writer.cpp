// glTF output: the orders written into the file they came from. It must validate with the Khronos
// glTF Validator, read back with the same vertices and keyframes, hold every order as a
// permutation of the original triangles with their winding, keep what it does not touch, and be
// byte-identical for the same input.
#include "animorder/animated_mesh.h"
#include "animorder/clustering.h"
#include "animorder/gltf_loader.h"
#include "animorder/gltf_writer.h"
#include "animorder/load.h"
#include "animorder/methods.h"
#include "animorder/procedural_character.h"
#include "animorder/triangle_order.h"
#include "animorder/viewpoints.h"
#include "support/meshes.h"

#include <gtest/gtest.h>

#include "support/files.h"
#include "support/require.h"
#include <nlohmann/json.hpp>

#include <cstdlib>
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
    std::ofstream(output, std::ios::binary)
        << gltf_with_orders(input, output.string(), w.mesh, w.method.buffers, 1, w.method.framing, "single",
                            output.extension() == ".glb");
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
        apply_triangle_order(fallback.data(), w.mesh.indices.data(), w.method.buffers.orders[1].data(), w.mesh.triangle_count());
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
    for (const char* key : {"\"materials\"", "\"skins\"", "\"animations\"", "\"images\"", "\"ANIMORDER_animated_triangle_orders\"", "\"orders\"", "\"extensionsUsed\""})
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
