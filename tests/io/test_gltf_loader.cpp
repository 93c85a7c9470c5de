// The glTF loader: small files built here whose keyframes are worked out by hand (skins, morph
// targets with sparse accessors, LINEAR/STEP/CUBICSPLINE), one-line errors for broken files, and
// every glTF character of ../shared/data.
#include "animorder/animated_mesh.h"
#include "animorder/gltf_loader.h"
#include "animorder/load.h"
#include "support/gltf_builder.h"
#include "support/meshes.h"

#include "support/load_error.h"
#include "support/require.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

using namespace animorder;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

using test::expect_position;

using test::Gltf;

class GltfLoader : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("animorder-gltf-" + std::to_string(::getpid()) + "-" +
                                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string write(const std::string& name, const std::string& content) {
        const fs::path p = dir_ / name;
        std::ofstream(p, std::ios::binary) << content;
        return p.string();
    }
    // Loading `content` fails with a one-line LoadError that starts with the file name and holds `message`.
    void expect_load_error(const std::string& name, const std::string& content, const std::string& message,
                           const LoadOptions& options = {}) {
        const std::string path = write(name, content);
        test::expect_one_line_load_error(path, message, [&] { load_gltf(path, options); });
    }
    fs::path dir_;
};

// A bar of two triangles along +Y from 0 to 2, skinned to two joints (root at 0, child at 1);
// vertices at y = 2 follow the child only. Clip: the child rotates 90° about Z from t=0 to t=1.
Gltf skinned_bar(const std::string& interpolation = "LINEAR") {
    Gltf g;
    const std::vector<float> pos = {0, 0, 0, 1, 0, 0, 1, 2, 0, 0, 2, 0};
    const std::vector<uint16_t> idx = {0, 1, 2, 0, 2, 3};
    const std::vector<uint16_t> joints = {0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    const std::vector<float> weights = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    const std::vector<float> ibm = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0,  0, 1,   // root at the origin
                                    1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1};  // child at y = 1
    const int p = g.floats(pos, "VEC3", 3), i = g.u16(idx, "SCALAR", 1), j = g.u16(joints, "VEC4", 4),
              w = g.floats(weights, "VEC4", 4), m = g.floats(ibm, "MAT4", 16);
    const double s = std::sqrt(0.5);
    std::vector<float> times = {0, 1}, rot = {0, 0, 0, 1, 0, 0, float(s), float(s)};
    if (interpolation == "CUBICSPLINE")
        rot = {0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, float(s), float(s), 0, 0, 0, 0};
    const int t = g.floats(times, "SCALAR", 1), r = g.floats(rot, "VEC4", 4);
    json primitive = {{"attributes", {{"POSITION", p}, {"JOINTS_0", j}, {"WEIGHTS_0", w}}}, {"indices", i}};
    g.doc["meshes"] = json::array({json{{"name", "bar"}, {"primitives", json::array({primitive})}}});
    g.doc["nodes"] =
        json::array({json{{"name", "root"}, {"children", {1}}}, json{{"name", "child"}, {"translation", {0, 1, 0}}},
                     // The skinned node's own transform must be ignored (glTF §3.7.3).
                     json{{"name", "skinned"}, {"mesh", 0}, {"skin", 0}, {"translation", {100, 0, 0}}}});
    g.doc["skins"] = json::array({json{{"joints", {0, 1}}, {"inverseBindMatrices", m}}});
    g.doc["scenes"] = json::array({json{{"nodes", {0, 2}}}});
    g.doc["scene"] = 0;
    json sampler = {{"input", t}, {"output", r}, {"interpolation", interpolation}};
    json channel = {{"sampler", 0}, {"target", {{"node", 1}, {"path", "rotation"}}}};
    json animation = {{"name", "bend"}, {"samplers", json::array({sampler})}, {"channels", json::array({channel})}};
    g.doc["animations"] = json::array({animation});
    return g;
}

}  // namespace

TEST_F(GltfLoader, SkinnedBarBendsAsWorkedOutByHand) {
    const AnimatedMesh m = load_gltf(write("bar.gltf", skinned_bar().text()));
    ASSERT_EQ(m.clips.size(), 1u);
    EXPECT_EQ(m.clips[0].name, "bend");
    EXPECT_EQ(m.clips[0].keyframe_count, 31u);  // 1 s at 30/s, both ends
    EXPECT_EQ(m.joint_count, 2u);
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
    // t = 0: bind pose (the skinned node's own translation is ignored, as the spec says).
    expect_position(m, 0, 2, 1, 2, 0);
    // t = 1: the child turned 90° about Z around (0, 1, 0): (1, 2) → (0, 1) + (−1, 1) = (−1, 2).
    expect_position(m, 30, 2, -1, 2, 0);
    expect_position(m, 30, 3, -1, 1, 0);
    expect_position(m, 30, 1, 1, 0, 0);  // the root's vertices stay
    // t = 0.5: slerp halfway, 45°: (1, 1) relative → (0, √2).
    expect_position(m, 15, 2, 0, 1 + std::sqrt(2.0), 0);
}

// joint_count counts the joint nodes of the skins the drawn nodes use, each once: a second skin of
// the same skeleton adds none, one of a second skeleton adds its own (it gave the largest skin's).
TEST_F(GltfLoader, JointsAreTheDistinctJointNodesOfEverySkin) {
    for (const bool second_skeleton : {false, true}) {
        SCOPED_TRACE(second_skeleton ? "a second skeleton" : "a second skin of the same skeleton");
        Gltf g = skinned_bar();
        json& nodes = g.doc["nodes"];
        nodes.push_back(json{{"name", "root2"}, {"children", {4}}});
        nodes.push_back(json{{"name", "child2"}, {"translation", {0, 1, 0}}});
        nodes.push_back(json{{"name", "skinned2"}, {"mesh", 0}, {"skin", 1}});
        json skin = g.doc["skins"][0];
        if (second_skeleton) skin["joints"] = {3, 4};
        g.doc["skins"].push_back(skin);
        g.doc["scenes"][0]["nodes"] = {0, 2, 3, 5};
        const AnimatedMesh m = load_gltf(write("two-skins.gltf", g.text()));
        EXPECT_EQ(m.triangle_count(), 4u);
        EXPECT_EQ(m.joint_count, second_skeleton ? 4u : 2u);
    }
}

TEST_F(GltfLoader, StepAndCubicSplineInterpolation) {
    const AnimatedMesh step = load_gltf(write("step.gltf", skinned_bar("STEP").text()));
    expect_position(step, 29, 2, 1, 2, 0);  // holds the first key until t = 1
    expect_position(step, 30, 2, -1, 2, 0);
    // Zero tangents: Hermite gives 3u² − 2u³ of the way; at u = 0.5 exactly halfway (then normalised).
    const AnimatedMesh cubic = load_gltf(write("cubic.gltf", skinned_bar("CUBICSPLINE").text()));
    expect_position(cubic, 30, 2, -1, 2, 0);
    const float* p = cubic.keyframe(15) + 6;
    EXPECT_NEAR(std::hypot(p[0], p[1] - 1), std::sqrt(2.0), 1e-4);  // a rigid rotation about the joint
    EXPECT_LT(p[0], 0.99);
    EXPECT_GT(p[0], -0.99);
}

// Also without the mesh's weights, which glTF makes optional (zeros, one per target).
TEST_F(GltfLoader, SparseMorphTargetWithAnimatedWeights) {
    for (const bool mesh_weights : {true, false}) {
        SCOPED_TRACE(mesh_weights ? "with mesh weights" : "without mesh weights");
        Gltf g;
        const std::vector<float> pos = {0, 0, 0, 1, 0, 0, 0, 1, 0};
        const std::vector<uint16_t> idx = {0, 1, 2};
        const int p = g.floats(pos, "VEC3", 3), i = g.u16(idx, "SCALAR", 1);
        // Sparse target: only vertex 2 moves, by (0, 0, 2).
        const std::vector<uint16_t> sparse_index = {2};
        const std::vector<float> sparse_value = {0, 0, 2};
        g.u16(sparse_index, "SCALAR", 1);
        g.floats(sparse_value, "VEC3", 3);
        json sparse = {
            {"count", 1}, {"indices", {{"bufferView", 2}, {"componentType", 5123}}}, {"values", {{"bufferView", 3}}}};
        g.doc["accessors"].push_back({{"componentType", 5126}, {"count", 3}, {"type", "VEC3"}, {"sparse", sparse}});
        const int target = int(g.doc["accessors"].size() - 1);
        const std::vector<float> times = {0, 2}, weights = {0, 1};
        const int t = g.floats(times, "SCALAR", 1), w = g.floats(weights, "SCALAR", 1);
        json primitive = {
            {"attributes", {{"POSITION", p}}}, {"indices", i}, {"targets", json::array({json{{"POSITION", target}}})}};
        g.doc["meshes"] = json::array({json{{"primitives", json::array({primitive})}}});
        if (mesh_weights) g.doc["meshes"][0]["weights"] = json::array({0.0});
        g.doc["nodes"] = json::array({json{{"mesh", 0}, {"translation", {0, 0, 5}}}});
        g.doc["scenes"] = json::array({json{{"nodes", json::array({0})}}});
        json sampler = {{"input", t}, {"output", w}};
        json channel = {{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}};
        g.doc["animations"] =
            json::array({json{{"samplers", json::array({sampler})}, {"channels", json::array({channel})}}});
        const AnimatedMesh m = load_gltf(write("morph.gltf", g.text()));
        EXPECT_EQ(m.morph_target_count, 1u);
        EXPECT_EQ(m.clips[0].keyframe_count, 61u);
        expect_position(m, 0, 2, 0, 1, 5);   // node translation applies (not skinned)
        expect_position(m, 30, 2, 0, 1, 6);  // weight 0.5 → +1
        expect_position(m, 60, 2, 0, 1, 7);
        expect_position(m, 60, 1, 1, 0, 5);  // untouched by the sparse target
    }
}

// A channel of a path the loader does not animate (an extension's, say) leaves its node's matrix
// in place: before, any channel but weights dropped it.
TEST_F(GltfLoader, AChannelOfAnotherPathKeepsTheNodesMatrix) {
    Gltf g;
    const int p = g.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3), i = g.u16({0, 1, 2}, "SCALAR", 1);
    const int t = g.floats({0, 1}, "SCALAR", 1), v = g.floats({0, 0, 0, 0, 3, 0}, "VEC3", 3);
    g.doc["meshes"] =
        json::array({json{{"primitives", json::array({json{{"attributes", {{"POSITION", p}}}, {"indices", i}}})}}});
    g.doc["nodes"] = json::array(
        {json{{"mesh", 0}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1}}}, json{{"name", "moved"}}});
    g.doc["scenes"] = json::array({json{{"nodes", json::array({0, 1})}}});
    json sampler = {{"input", t}, {"output", v}};
    g.doc["animations"] = json::array(
        {json{{"samplers", json::array({sampler})},
              {"channels", json::array({json{{"sampler", 0}, {"target", {{"node", 1}, {"path", "translation"}}}},
                                        json{{"sampler", 0}, {"target", {{"node", 0}, {"path", "pointer"}}}}})}}});
    const AnimatedMesh m = load_gltf(write("pointer.gltf", g.text()));
    ASSERT_EQ(m.clips.size(), 1u);
    expect_position(m, 0, 1, 1, 0, 5);  // the matrix's translation
    expect_position(m, m.keyframe_count() - 1, 1, 1, 0, 5);
}

TEST_F(GltfLoader, BrokenFilesGiveOneLineErrorsNamingTheFile) {
    auto expect_error = [&](const std::string& name, const std::string& content, const std::string& message) {
        const std::string path = write(name, content);
        test::expect_one_line_load_error(path, message, [&] { load_gltf(path); });
    };
    expect_error("empty.gltf", "", "empty or truncated");
    expect_error("junk.gltf", "this is not json", "not a readable glTF");
    expect_error("truncated.glb", "glTF\x02\0\0\0\xff\xff\0\0", "not a readable glTF");
    {
        // Arrays nested 20,000 deep inside an extension (a 40 KB file): tinygltf's recursive
        // conversion of extension values overflowed the stack (SIGSEGV); now refused before it reads.
        const std::string text = skinned_bar().text();
        const std::string deep = std::string(20000, '[') + std::string(20000, ']');
        expect_error("deep.gltf",
                     text.substr(0, text.size() - 1) +
                         R"(,"extensions":{"ANIMORDER_animated_triangle_orders":{"extras":)" + deep + "}}}",
                     "more than 512 levels deep");
        const std::string shallow = std::string(500, '[') + std::string(500, ']');
        const std::string ok = write("shallow.gltf", text.substr(0, text.size() - 1) + R"(,"asset":{"version":"2.0",)" +
                                                         R"("extras":)" + shallow + "}}");
        EXPECT_NO_THROW(load_gltf(ok));  // 501 levels: still read
    }
    {
        // Compressed geometry (gltfpack -c / -cc, Draco) is named, not misread; a required
        // extension that leaves the geometry readable is fine.
        for (const char* compression : {"EXT_meshopt_compression", "KHR_draco_mesh_compression"}) {
            Gltf g = skinned_bar();
            g.doc["extensionsUsed"] = {compression};
            g.doc["extensionsRequired"] = {compression};
            expect_error("compressed.gltf", g.text(), std::string("requires ") + compression);
        }
        Gltf g = skinned_bar();
        g.doc["extensionsUsed"] = {"KHR_mesh_quantization"};
        g.doc["extensionsRequired"] = {"KHR_mesh_quantization"};
        EXPECT_NO_THROW(load_gltf(write("quantised.gltf", g.text())));
    }
    {
        Gltf g = skinned_bar();
        g.doc["buffers"] = json::array({{{"byteLength", 4000}, {"uri", "missing.bin"}}});
        json d = g.doc;
        expect_error("missing.gltf", d.dump(), "not a readable glTF");
    }
    {
        Gltf g = skinned_bar();
        g.doc["accessors"][1]["count"] = 600;  // indices past their buffer view
        expect_error("range.gltf", g.text(), "runs past the end");
    }
    {
        Gltf g = skinned_bar();
        const std::vector<uint16_t> bad = {0, 1, 9};
        g.doc["meshes"][0]["primitives"][0]["indices"] = g.u16(bad, "SCALAR", 1);
        expect_error("index.gltf", g.text(), "is 9, but there are 4 vertices");
    }
    {
        Gltf g = skinned_bar();
        const std::vector<float> nan = {0, 0, 0, 1, 0, 0, NAN, 2, 0, 0, 2, 0};
        g.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = g.floats(nan, "VEC3", 3);
        expect_error("nan.gltf", g.text(), "NaN or infinite");
    }
    {
        // glTF 1.0 (assimp's "gltf" exporter writes it) is named, not read as an empty 2.0 file.
        Gltf g = skinned_bar();
        g.doc["asset"]["version"] = "1.0";
        g.doc["scene"] = "defaultScene";
        expect_error("one.gltf", g.text(), "is glTF 1.0; animorder reads glTF 2.0 (gltf-pipeline");
    }
    {
        // The character in scene 1, a marker alone in scene 0 and no default `scene`: the error
        // says which scene was read, why, and which one draws meshes.
        Gltf g = skinned_bar();
        g.doc["nodes"].push_back({{"name", "marker"}});
        g.doc["scenes"] = json::array({json{{"nodes", {g.doc["nodes"].size() - 1}}}, g.doc["scenes"][0]});
        g.doc.erase("scene");
        expect_error("second-scene.gltf", g.text(),
                     "no triangle mesh in scene 0 (the file names no default `scene`: the first, as viewers show); "
                     "scene 1 draws meshes: make it the file's `scene` to optimise it");
        g.doc["scene"] = 1;
        EXPECT_NO_THROW(load_gltf(write("scene-1.gltf", g.text())));
    }
    {
        Gltf g = skinned_bar();
        g.doc["meshes"][0]["primitives"][0]["mode"] = 1;  // LINES, and nothing else
        expect_error("lines.gltf", g.text(),
                     "no triangle mesh in scene 0 (the file's default `scene`) (points and lines");
        // Next to triangles, a lines primitive is left out (it was refused, and the file with it).
        g.doc["meshes"][0]["primitives"].push_back(g.doc["meshes"][0]["primitives"][0]);
        g.doc["meshes"][0]["primitives"][1].erase("mode");
        const AnimatedMesh m = load_gltf(write("lines-and-triangles.gltf", g.text()));
        ASSERT_EQ(m.primitives.size(), 1u);
        EXPECT_EQ(m.primitives[0].source_primitive, 1);
        EXPECT_EQ(m.triangle_count(), 2u);
    }
    {
        Gltf g = skinned_bar();
        g.doc["animations"][0]["channels"] = json::array();
        expect_error("still.gltf", g.text(), "animates nothing");
    }
    {
        Gltf g = skinned_bar();
        const std::vector<uint16_t> joints = {0, 0, 0, 0, 0, 0, 0, 0, 7, 0, 0, 0, 1, 0, 0, 0};
        g.doc["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] = g.u16(joints, "VEC4", 4);
        expect_error("joint.gltf", g.text(), "names joint 7");
    }
    {
        Gltf g = skinned_bar();  // was sampled as LINEAR
        g.doc["animations"][0]["samplers"][0]["interpolation"] = "QUADRATIC";
        expect_error("quadratic.gltf", g.text(), "interpolation 'QUADRATIC'");
    }
    {
        // tinygltf threw std::out_of_range ("vector::_M_range_check", naming no file) on a buffer of
        // byteLength 0 with a URI.
        Gltf g = skinned_bar();
        json doc = json::parse(g.text());
        doc["buffers"][0]["byteLength"] = 0;
        expect_error("empty-buffer.gltf", doc.dump(), "not a readable glTF");
    }
    {
        // A data URI of the wrong length: tinygltf's message quoted all of it (a 700 KB line).
        Gltf g = skinned_bar();
        json doc = json::parse(g.text());
        doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + std::string(200000, 'A');
        const std::string path = write("long-uri.gltf", doc.dump());
        try {
            load_gltf(path);
            ADD_FAILURE() << "loaded";
        } catch (const LoadError& e) {
            EXPECT_LT(std::string(e.what()).size(), 1000u) << std::string(e.what()).substr(0, 200);
            EXPECT_EQ(std::string(e.what()).rfind(path, 0), 0u);
        }
    }
    try {
        load_gltf((dir_ / "nowhere.glb").string());
        ADD_FAILURE();
    } catch (const LoadError& e) {
        EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos);
    }
}

// What the validator calls errors and engines misread or fail on, found by a sweep of the Khronos
// validator's cases: data of a type glTF does not allow there (read anyway, a float's bytes became
// shorts, unnormalized byte weights of 0..255 scaled the skin), an accessor off its component
// alignment (read as garbage floats; three.js throws), a channel or a child naming a missing node
// (the channel was skipped and written back: three.js throws on the output), and weights animated
// on a node without morph targets. Each is refused in one line naming what is wrong; the allowed
// variants (normalized byte weights, integer positions under KHR_mesh_quantization) load.
TEST_F(GltfLoader, DataEnginesMisreadIsRefusedByName) {
    auto expect_error = [&](const std::string& name, Gltf g, const std::string& message) {
        const std::string path = write(name, g.text());
        test::expect_one_line_load_error(path, message, [&] { load_gltf(path); });
    };
    const AnimatedMesh reference = load_gltf(write("bar.gltf", skinned_bar().text()));
    {
        Gltf g = skinned_bar();
        g.doc["animations"][0]["channels"][0]["target"]["node"] = 99;
        expect_error("channel.gltf", g, "clip 'bend' channel 0 targets node 99, but the file has 3 nodes");
    }
    {
        Gltf g = skinned_bar();
        g.doc["animations"][0]["samplers"][0]["input"] = g.u16({0, 1}, "SCALAR", 1);
        expect_error("times.gltf", g, "clip 'bend': key times (accessor 7) are unsigned shorts");
    }
    {
        // Byte weights must be normalized (0..255 as 0..1); normalized they give the float weights' skin.
        Gltf g = skinned_bar();
        const std::vector<uint8_t> bytes = {255, 0, 0, 0, 255, 0, 0, 0, 255, 0, 0, 0, 255, 0, 0, 0};
        const int w = g.add(bytes.data(), bytes.size(), 4, "VEC4", 5121);
        g.doc["meshes"][0]["primitives"][0]["attributes"]["WEIGHTS_0"] = w;
        expect_error("weights.gltf", g, "WEIGHTS_0 (accessor 7) are unnormalized unsigned bytes");
        g.doc["accessors"][size_t(w)]["normalized"] = true;
        const AnimatedMesh m = load_gltf(write("weights-normalized.gltf", g.text()));
        EXPECT_EQ(m.keyframe_positions, reference.keyframe_positions);
    }
    {
        // Integer positions need KHR_mesh_quantization; with it, the same bar.
        Gltf g = skinned_bar();
        g.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] =
            g.u16({0, 0, 0, 1, 0, 0, 1, 2, 0, 0, 2, 0}, "VEC3", 3);
        expect_error("quantised.gltf", g,
                     "POSITION (accessor 7) are unsigned shorts, which glTF does not allow there "
                     "(integer positions need KHR_mesh_quantization");
        g.doc["extensionsUsed"] = {"KHR_mesh_quantization"};
        const AnimatedMesh m = load_gltf(write("quantised-declared.gltf", g.text()));
        EXPECT_EQ(m.keyframe_positions, reference.keyframe_positions);
    }
    {
        Gltf g = skinned_bar();
        g.doc["accessors"][0]["byteOffset"] = 2;
        g.doc["accessors"][0]["count"] = 3;
        expect_error("unaligned.gltf", g, "accessor 0 starts at byte 2 of its buffer, not a multiple of its 4-byte");
    }
    {
        Gltf g = skinned_bar();
        g.doc["nodes"][0]["children"] = {1, 99};
        expect_error("child.gltf", g, "node 0 names child 99, but the file has 3 nodes");
        g.doc["nodes"][0]["children"] = {1};
        g.doc["nodes"][2]["children"] = {1};
        expect_error("parents.gltf", g, "node hierarchy is not a tree: node 1 is a child of node 0 and of node 2");
    }
    {
        Gltf g = skinned_bar();
        g.doc["meshes"][0].erase("name");
        g.doc["animations"][0]["channels"][0]["target"] = {{"node", 2}, {"path", "weights"}};
        expect_error("weights-unmorphed.gltf", g,
                     "clip 'bend' animates the morph weights of node 2, which draws no "
                     "morph targets");
        g = skinned_bar();
        g.doc["meshes"][0].erase("name");
        g.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] =
            g.u16({0, 0, 0, 1, 0, 0, 1, 2, 0, 0, 2, 0}, "VEC3", 3);
        expect_error("unnamed.gltf", g, ": mesh 0 primitive 0: POSITION (accessor 7)");
    }
}

// Regressions from hostile files: sizes, counts and offsets that wrapped or were used before they
// were checked (heap overflows, a SEGV, out-of-bounds reads, 32 GB allocations).
TEST_F(GltfLoader, HostileAccessorsGiveOneLineErrors) {
    {
        Gltf g = skinned_bar();  // count × 3 components wraps to 2
        g.doc["accessors"][0]["count"] = 6148914691236517206ull;
        expect_load_error("wrap.gltf", g.text(), "runs past the end of its buffer view");
    }
    {
        Gltf g = skinned_bar();
        g.doc["accessors"][0]["bufferView"] = 99;
        expect_load_error("view.gltf", g.text(), "names a missing buffer view");
    }
    {
        Gltf g = skinned_bar();  // offset + stride · (count − 1) + element wraps to a small number
        g.doc["accessors"][0]["byteOffset"] = 18446744073709551600ull;
        expect_load_error("offset.gltf", g.text(), "runs past the end of its buffer view");
    }
    {
        Gltf g = skinned_bar();
        g.doc["bufferViews"][0]["byteOffset"] = 18446744073709551600ull;
        expect_load_error("view-offset.gltf", g.text(), "runs past the end of its buffer");
    }
    {
        Gltf g = skinned_bar();  // 32 GB of doubles if allocated before the range check
        g.doc["accessors"][0]["count"] = 1000000000;
        expect_load_error("count.gltf", g.text(), "runs past the end of its buffer view");
    }
    {
        Gltf g = skinned_bar();
        g.doc["accessors"][0]["sparse"] = {
            {"count", -1}, {"indices", {{"bufferView", 1}, {"componentType", 5123}}}, {"values", {{"bufferView", 0}}}};
        expect_load_error("sparse-count.gltf", g.text(), "substitutes -1 of 4 elements");
    }
    {
        Gltf g = skinned_bar();
        g.doc["accessors"][0]["sparse"] = {
            {"count", 1}, {"indices", {{"bufferView", 0}, {"componentType", 5126}}}, {"values", {{"bufferView", 0}}}};
        expect_load_error("sparse-type.gltf", g.text(), "not unsigned integers");
    }
    {
        Gltf g = skinned_bar();  // no buffer view: a billion zeros, 24 GB of doubles
        g.doc["accessors"].push_back({{"componentType", 5126}, {"count", 1000000000}, {"type", "VEC3"}});
        g.doc["meshes"][0]["primitives"][0]["targets"] =
            json::array({json{{"POSITION", g.doc["accessors"].size() - 1}}});
        expect_load_error("zeros.gltf", g.text(), "more than the loading budget");
    }
    {
        Gltf g = skinned_bar();
        const std::vector<int8_t> bad = {0, 1, 2, 0, 2, -1};
        g.doc["meshes"][0]["primitives"][0]["indices"] = g.add(bad.data(), bad.size(), bad.size(), "SCALAR", 5120);
        expect_load_error("negative-index.gltf", g.text(), "are not unsigned integers");
    }
    {
        Gltf g = skinned_bar();
        const std::vector<int8_t> joints = {0, 0, 0, 0, 0, 0, 0, 0, -1, 0, 0, 0, 1, 0, 0, 0};
        g.doc["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] =
            g.add(joints.data(), joints.size(), 4, "VEC4", 5120);
        expect_load_error("negative-joint.gltf", g.text(), "are not unsigned integers");
    }
    {
        Gltf g = skinned_bar();
        g.doc["nodes"][2]["skin"] = 5;
        expect_load_error("skin.gltf", g.text(), "names a missing skin");
    }
    {
        Gltf g = skinned_bar();
        g.doc["skins"][0]["joints"] = {0, 7};
        expect_load_error("joint-node.gltf", g.text(), "missing joint node");
    }
    {
        Gltf g = skinned_bar();
        g.doc["animations"][0]["channels"][0]["sampler"] = 3;
        expect_load_error("sampler.gltf", g.text(), "names a missing sampler");
    }
    {
        Gltf g = skinned_bar();
        g.doc["nodes"][1]["children"] = {0};  // a cycle: root → child → root
        expect_load_error("cycle.gltf", g.text(), "repeated node");
    }
}

// Every size, count, offset and index of the accessors, buffer views and sparse substitutions
// set in turn to values a hostile file would use (negative, zero, just past a limit, near 2^31,
// 2^32, 2^63, 2^64): each file loads or fails with a LoadError, nothing else (under
// scripts/test-sanitized.sh: no memory error, no undefined behaviour).
// Data glTF lays out or types otherwise than the loader would read it: refused, not misread.
TEST_F(GltfLoader, LayoutsAndTypesThatWouldBeMisreadAreRefused) {
    {
        Gltf g = skinned_bar();  // positions (12-byte elements) 4 bytes apart would overlap
        g.doc["bufferViews"][0]["byteStride"] = 4;
        expect_load_error("stride.gltf", g.text(), "has a byteStride of 4, less than the 12 bytes");
    }
    {
        Gltf g = skinned_bar();  // 0.7 and 1.7 were truncated into other vertices
        g.doc["meshes"][0]["primitives"][0]["indices"] = g.floats({0, 1.7f, 2, 0, 2, 3.2f}, "SCALAR", 1);
        expect_load_error("float-indices.gltf", g.text(), "are not unsigned integers");
    }
    {
        Gltf g = skinned_bar();
        g.doc["accessors"][1]["normalized"] = true;
        expect_load_error("normalized-indices.gltf", g.text(), "are normalized: glTF asks for unsigned");
    }
    {
        Gltf g = skinned_bar();
        g.doc["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] =
            g.floats({0, 0, 0, 0, 0, 0, 0, 0, 0.5f, 0, 0, 0, 1.7f, 0, 0, 0}, "VEC4", 4);
        expect_load_error("float-joints.gltf", g.text(), "are not unsigned integers");
    }
    {
        Gltf g = skinned_bar();  // joints are kept in 16 bits: joint 66,000 became 65,535
        std::vector<int> joints(70000, 1);
        joints[0] = 0;
        g.doc["skins"][0]["joints"] = joints;
        g.doc["skins"][0].erase("inverseBindMatrices");
        const std::vector<uint32_t> far = {0, 0, 0, 0, 0, 0, 0, 0, 66000, 0, 0, 0, 1, 0, 0, 0};
        g.doc["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] =
            g.add(far.data(), far.size() * 4, 4, "VEC4", 5125);
        expect_load_error("many-joints.gltf", g.text(), "names joint 66000; at most 65,536 joints");
    }
}

TEST_F(GltfLoader, HostileNumbersLoadOrFailCleanly) {
    Gltf bar = skinned_bar();
    bar.doc["accessors"][0]["sparse"] = {
        {"count", 1}, {"indices", {{"bufferView", 1}, {"componentType", 5123}}}, {"values", {{"bufferView", 0}}}};
    const json values =
        json::array({-1, 0, 1, 3, 4, 255, 2147483647LL, 4294967296LL, 9223372036854775807LL, 18446744073709551615ULL});
    const std::vector<std::pair<std::string, std::vector<std::string>>> fields = {
        {"accessors",
         {"/bufferView", "/byteOffset", "/count", "/componentType", "/sparse/count", "/sparse/indices/bufferView",
          "/sparse/indices/byteOffset", "/sparse/values/bufferView", "/sparse/values/byteOffset"}},
        {"bufferViews", {"/buffer", "/byteOffset", "/byteLength", "/byteStride"}}};
    size_t loaded = 0, refused = 0;
    for (const auto& [array, keys] : fields)
        for (size_t i = 0; i < bar.doc[array].size(); ++i)
            for (const std::string& key : keys) {
                const json::json_pointer at("/" + array + "/" + std::to_string(i) + key);
                if (!bar.doc.contains(at)) continue;
                for (const json& value : values) {
                    Gltf g = bar;
                    g.doc[at] = value;
                    const std::string path = write("hostile.gltf", g.text());
                    try {
                        load_gltf(path);
                        ++loaded;
                    } catch (const LoadError& e) {
                        EXPECT_EQ(std::string(e.what()).rfind(path, 0), 0u) << e.what();
                        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
                        ++refused;
                    }
                }
            }
    EXPECT_GT(loaded, 0u);
    EXPECT_GT(refused, 100u);
}

// The long clip of the finding (its last key at 3,333 s passes the 100,000-keyframe cap) is
// refused by the loading budget before any keyframe is sampled; one more second is too long.
TEST_F(GltfLoader, LoadingBudgetIsCheckedBeforeSampling) {
    auto clip_until = [](double last) {
        Gltf g = skinned_bar();
        const std::vector<float> times = {0, float(last)};
        g.doc["animations"][0]["samplers"][0]["input"] = g.floats(times, "SCALAR", 1);
        return g.text();
    };
    LoadOptions small;
    small.max_keyframe_bytes = 1 << 20;  // 99,991 keyframes × 4 vertices × 12 bytes = 4.8 MB
    expect_load_error("long.gltf", clip_until(3333), "loading budget", small);
    expect_load_error("longer.gltf", clip_until(3334), "absurdly long");
    // The bar's 1 s clip: 31 keyframes × 4 vertices × 12 bytes = 1,488 bytes, exactly.
    small.max_keyframe_bytes = 1488;
    EXPECT_EQ(load_gltf(write("fits.gltf", clip_until(1)), small).keyframe_count(), 31u);
    small.max_keyframe_bytes = 1487;
    expect_load_error("tight.gltf", clip_until(1), "loading budget", small);
}

// LoadOptions::clips: only the named clips are sampled (a clip too long for the budget is never
// sampled when not asked), each exactly as among all the clips; a name the file lacks samples
// every clip, so that select_clips reports the file's clip names.
TEST_F(GltfLoader, OnlyTheAskedClipsAreSampled) {
    Gltf g = skinned_bar();
    const double s = std::sqrt(0.5);
    auto add_clip = [&](const char* name, float last, std::vector<float> rotations) {
        const int t = g.floats({0, last}, "SCALAR", 1), r = g.floats(rotations, "VEC4", 4);
        json sampler = {{"input", t}, {"output", r}, {"interpolation", "LINEAR"}};
        json channel = {{"sampler", 0}, {"target", {{"node", 1}, {"path", "rotation"}}}};
        g.doc["animations"].push_back(
            {{"name", name}, {"samplers", json::array({sampler})}, {"channels", json::array({channel})}});
    };
    add_clip("long", 3333, {0, 0, 0, 1, 0, 0, float(s), float(s)});  // 99,991 keyframes: 4.8 MB
    add_clip("back", 0.5f, {0, 0, float(s), float(s), 0, 0, 0, 1});  // 16 keyframes, from 90° to 0
    const std::string path = write("clips.gltf", g.text());

    LoadOptions all;
    const AnimatedMesh full = load_gltf(path, all);
    ASSERT_EQ(full.clips.size(), 3u);
    LoadOptions small;
    small.max_keyframe_bytes = 1 << 20;
    test::expect_one_line_load_error(path, "loading budget", [&] { load_gltf(path, small); });
    small.clips = {"back", "bend"};
    const AnimatedMesh two = load_gltf(path, small);
    ASSERT_EQ(two.clips.size(), 2u);
    EXPECT_EQ(two.clips[0].name, "bend");  // the file's order; select_clips gives the asked one
    EXPECT_EQ(two.keyframe_count(), 31u + 16u);
    for (const auto& names : {std::vector<std::string>{"back", "bend"}, std::vector<std::string>{"bend"}}) {
        const AnimatedMesh a = select_clips(two, names), b = select_clips(full, names);
        EXPECT_EQ(a.keyframe_positions, b.keyframe_positions);
        ASSERT_EQ(a.clips.size(), b.clips.size());
        for (size_t c = 0; c < a.clips.size(); ++c) {
            EXPECT_EQ(a.clips[c].name, b.clips[c].name);
            EXPECT_EQ(a.clips[c].keyframe_count, b.clips[c].keyframe_count);
            EXPECT_EQ(a.clips[c].first_keyframe, b.clips[c].first_keyframe);
            EXPECT_EQ(a.clips[c].start_time_s, b.clips[c].start_time_s);
        }
    }
    // 'back' at t = 0.5 is the bind pose again; at t = 0 the child is turned 90°.
    expect_position(two, 31 + 15, 2, 1, 2, 0);
    expect_position(two, 31, 2, -1, 2, 0);
    // A name the file lacks: every clip is sampled (here over the budget), so nothing is hidden.
    small.clips = {"bend", "walk"};
    test::expect_one_line_load_error(path, "loading budget", [&] { load_gltf(path, small); });
    all.clips = {"walk"};
    try {
        select_clips(load_gltf(path, all), all.clips);
        ADD_FAILURE() << "a missing clip was not reported";
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("clips: bend, long, back"), std::string::npos) << e.what();
    }
}

// The keyframes are sampled in parallel (LoadOptions::threads), each into its own slice: every
// thread count gives the same bits, and each clip's keyframes land where its first_keyframe says
// (the hand-worked poses of SkinnedBarBendsAsWorkedOutByHand and of 'back', at their places).
TEST_F(GltfLoader, KeyframesAreTheSameBitsWhateverTheThreads) {
    Gltf g = skinned_bar();
    const double s = std::sqrt(0.5);
    const int t = g.floats({0, 2}, "SCALAR", 1), r = g.floats({0, 0, float(s), float(s), 0, 0, 0, 1}, "VEC4", 4);
    json sampler = {{"input", t}, {"output", r}, {"interpolation", "LINEAR"}};
    json channel = {{"sampler", 0}, {"target", {{"node", 1}, {"path", "rotation"}}}};
    g.doc["animations"].push_back(
        {{"name", "back"}, {"samplers", json::array({sampler})}, {"channels", json::array({channel})}});
    const std::string path = write("threads.gltf", g.text());
    std::vector<AnimatedMesh> loads;
    for (const unsigned threads : {1u, 2u, 3u, 0u}) {
        LoadOptions options;
        options.threads = threads;
        loads.push_back(load_gltf(path, options));
    }
    const AnimatedMesh& m = loads[0];
    ASSERT_EQ(m.clips.size(), 2u);
    EXPECT_EQ(m.clips[1].first_keyframe, 31u);
    EXPECT_EQ(m.keyframe_count(), 31u + 61u);
    expect_position(m, 15, 2, 0, 1 + std::sqrt(2.0), 0);  // 'bend' at t = 0.5: 45°
    expect_position(m, 30, 2, -1, 2, 0);                  // 'bend' at t = 1: 90°
    expect_position(m, 31, 2, -1, 2, 0);                  // 'back' at t = 0: 90°
    expect_position(m, 31 + 60, 2, 1, 2, 0);              // 'back' at t = 2: the bind pose
    for (size_t i = 1; i < loads.size(); ++i) {
        EXPECT_EQ(loads[i].keyframe_positions, m.keyframe_positions) << "load " << i;
        ASSERT_EQ(loads[i].clips.size(), m.clips.size());
        for (size_t c = 0; c < m.clips.size(); ++c)
            EXPECT_EQ(loads[i].clips[c].first_keyframe, m.clips[c].first_keyframe);
    }
}

// Accessors named many times are read each time: their values together count against the budget.
TEST_F(GltfLoader, AccessorsNamedManyTimesCountAgainstTheBudget) {
    Gltf g = skinned_bar();
    // 1,000 morph targets that are all the positions: 1,000 × 4 × 3 doubles = 96,000 bytes.
    g.doc["meshes"][0]["primitives"][0]["targets"] = json::array();
    for (int t = 0; t < 1000; ++t) g.doc["meshes"][0]["primitives"][0]["targets"].push_back({{"POSITION", 0}});
    LoadOptions small;
    small.max_keyframe_bytes = 64000;
    expect_load_error("targets.gltf", g.text(), "is one accessor named many times?", small);
    small.max_keyframe_bytes = 200000;
    EXPECT_EQ(load_gltf(write("fits.gltf", g.text()), small).morph_target_count, 1000u);
}

namespace {
std::string shared_data(const std::string& relative) {
    return (fs::path(ANIMORDER_SOURCE_DIR) / ".." / "shared" / "data" / relative).string();
}
}  // namespace

TEST(GltfCharacters, EveryGltfInSharedDataLoads) {
    const char* files[] = {"mixamo-ganfaul/Ganfaul.gltf",
                           "glb-xbot/Xbot.glb",
                           "gltf-cesiumman/CesiumMan.glb",
                           "gltf-fox/Fox.glb",
                           "glb-robot-expressive/RobotExpressive.glb",
                           "gltf-morph-stress-test/MorphStressTest.gltf",
                           "gltf-animated-morph-sphere/AnimatedMorphSphere.gltf",
                           "glb-horse-morph/Horse.glb",
                           "glb-flamingo-morph/Flamingo.glb"};
    ANIMORDER_REQUIRE_DATA(shared_data(""));
    test::DataFiles data;  // every file is checked; the missing ones are named at the end
    for (const char* f : files) {
        SCOPED_TRACE(f);
        if (!data.present(shared_data(f))) continue;
        AnimatedMesh m;
        ASSERT_NO_THROW(m = load_gltf(shared_data(f)));
        EXPECT_GT(m.triangle_count(), 100u);
        EXPECT_GE(m.clips.size(), 1u);
        EXPECT_NO_THROW(validate_animated_mesh(m));
        std::printf("%-52s %6zu triangles %6zu vertices %3zu joints %2zu morph targets %2zu clips %5zu keyframes\n", f,
                    m.triangle_count(), m.vertex_count, m.joint_count, m.morph_target_count, m.clips.size(),
                    m.keyframe_count());
    }
    ANIMORDER_REQUIRE_ALL_DATA(data);
}

TEST(GltfCharacters, GanfaulSkinsWithoutStretching) {
    const std::string path = shared_data("mixamo-ganfaul/Ganfaul.gltf");
    ANIMORDER_REQUIRE_DATA(path);
    const AnimatedMesh m = load_gltf(path);
    EXPECT_NEAR(double(m.triangle_count()), 13802.0, 5.0);
    EXPECT_EQ(m.clips.size(), 12u);
    // Edge lengths over a whole clip relative to its first keyframe: median within 1% of 1.
    const Clip& c = m.clips[0];
    std::vector<double> ratios;
    for (size_t f = 1; f < c.keyframe_count; f += 7) {
        const std::vector<double> r = test::edge_stretch(m, c.first_keyframe, c.first_keyframe + f);
        ratios.insert(ratios.end(), r.begin(), r.end());
    }
    EXPECT_NEAR(test::median(ratios), 1.0, 0.01);
}

// Material flags: each primitive carries its material's doubleSided and alphaMode (glTF's
// defaults, single-sided OPAQUE, without a material); an unknown alphaMode is a one-line error.
// glTF 2.0: "the determinant of the node's global transform defines the winding order" (clockwise
// front faces when it is negative), and engines flip their culling for it (three.js: frontFaceCW
// from the mesh object's world matrix, which for a skinned mesh is its node's, though the skin
// ignores it for positions). Worked out by hand for one triangle, counter-clockwise seen from +Z in
// the file: mirrored in x it lies clockwise seen from +Z, and the engine draws it from +Z; the
// loader flips its corners so that, as everywhere, front faces are counter-clockwise.
TEST_F(GltfLoader, AMirroringNodeTransformGivesClockwiseFrontFacesAsEnginesDrawThem) {
    const auto build = [](const json& parent, const json& node, bool skinned) {
        Gltf g;
        const int p = g.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3), i = g.u16({0, 1, 2}, "SCALAR", 1);
        json primitive = {{"attributes", {{"POSITION", p}}}, {"indices", i}};
        json mesh_node = node;
        mesh_node["mesh"] = 0;
        if (skinned) {
            primitive["attributes"]["JOINTS_0"] = g.u16({0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}, "VEC4", 4);
            primitive["attributes"]["WEIGHTS_0"] = g.floats({1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}, "VEC4", 4);
            mesh_node["skin"] = 0;
            g.doc["skins"] = json::array({json{{"joints", {2}}}});
        }
        g.doc["meshes"] = json::array({json{{"primitives", json::array({primitive})}}});
        json holder = parent;
        holder["children"] = {1};
        g.doc["nodes"] = json::array({holder, mesh_node, json{{"name", "joint"}}});
        g.doc["scenes"] = json::array({json{{"nodes", {0, 2}}}});
        return g;
    };
    // The loaded triangle's orientation seen from +Z: + counter-clockwise, − clockwise.
    const auto seen_from_z = [](const AnimatedMesh& m) {
        const float* k = m.keyframe(0);
        const float* a = k + 3 * m.indices[0];
        const float* b = k + 3 * m.indices[1];
        const float* c = k + 3 * m.indices[2];
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    };
    const json mirror_x = {{"scale", {-1, 1, 1}}};
    // Upright: kept as the file has it.
    AnimatedMesh m = load_gltf(write("upright.gltf", build(json::object(), json::object(), false).text()));
    EXPECT_FALSE(m.primitives[0].mirrored);
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2}));
    EXPECT_GT(seen_from_z(m), 0);
    // Mirrored by its parent: vertex 1 at (−1, 0, 0), corners 0, 2, 1, counter-clockwise from +Z.
    m = load_gltf(write("mirrored.gltf", build(mirror_x, json::object(), false).text()));
    EXPECT_TRUE(m.primitives[0].mirrored);
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 2, 1}));
    expect_position(m, 0, 1, -1, 0, 0);
    EXPECT_GT(seen_from_z(m), 0);
    std::vector<uint32_t> as_written = m.indices;
    to_file_winding(m, as_written.data());
    EXPECT_EQ(as_written, (std::vector<uint32_t>{0, 1, 2}));
    // Two mirrors make a rotation: upright. A matrix mirrors as TRS does.
    m = load_gltf(write("twice.gltf", build(mirror_x, json{{"scale", {1, -1, 1}}}, false).text()));
    EXPECT_FALSE(m.primitives[0].mirrored);
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2}));
    m = load_gltf(write(
        "matrix.gltf",
        build(json{{"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -2, 0, 0, 0, 0, 1}}}, json::object(), false).text()));
    EXPECT_TRUE(m.primitives[0].mirrored);
    // Skinned: the skin ignores the node's transform for positions (the triangle stays where it
    // is, clockwise from +Z as loaded), but the node's determinant still sets the file's winding.
    m = load_gltf(write("skinned.gltf", build(mirror_x, json::object(), true).text()));
    EXPECT_TRUE(m.primitives[0].mirrored);
    expect_position(m, 0, 1, 1, 0, 0);
    EXPECT_LT(seen_from_z(m), 0);

    // A scale animated through zero to −1: one index buffer cannot have both windings.
    Gltf g = build(json::object(), json::object(), false);
    const int t = g.floats({0, 1}, "SCALAR", 1), v = g.floats({1, 1, 1, -1, 1, 1}, "VEC3", 3);
    g.doc["animations"] = json::array(
        {json{{"samplers", json::array({json{{"input", t}, {"output", v}}})},
              {"channels", json::array({json{{"sampler", 0}, {"target", {{"node", 0}, {"path", "scale"}}}}})}}});
    expect_load_error("flips.gltf", g.text(), "mirrors its mesh in some keyframes and not in others");
    // Flattened on the way (a scale of 0 says neither) and mirrored after: mirrored.
    g.doc["accessors"][size_t(v)]["count"] = 2;
    const int v0 = g.floats({0, 1, 1, -1, 1, 1}, "VEC3", 3);
    g.doc["animations"][0]["samplers"][0]["output"] = v0;
    m = load_gltf(write("flattened.gltf", g.text()));
    EXPECT_TRUE(m.primitives[0].mirrored);
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 2, 1}));
}

// Channels whose target names no node (glTF 2.0 allows it; tinygltf dropped them, and an animation
// left without any, renumbering the others): a KHR_animation_pointer pointer to a node's
// translation animates that node; a node-less TRS channel is ignored, as the spec says (a
// placeholder had applied it to node 0); a pointer elsewhere (a material) counts for the clip's
// length only. Every animation stays a clip, in the file's numbering.
TEST_F(GltfLoader, ChannelsWithoutANodeFollowTheirPointerOrAreIgnored) {
    Gltf g;
    const int p = g.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3), i = g.u16({0, 1, 2}, "SCALAR", 1);
    const int t = g.floats({0, 1}, "SCALAR", 1), t2 = g.floats({0, 2}, "SCALAR", 1);
    const int moved = g.floats({0, 0, 0, 1, 0, 0}, "VEC3", 3), big = g.floats({3, 3, 3, 3, 3, 3}, "VEC3", 3);
    const int colour = g.floats({1, 1, 1, 1, 0, 0, 0, 1}, "VEC4", 4);
    g.doc["meshes"] =
        json::array({json{{"primitives", json::array({json{{"attributes", {{"POSITION", p}}}, {"indices", i}}})}}});
    g.doc["materials"] = json::array({json{{"name", "m"}}});
    g.doc["nodes"] = json::array({json{{"mesh", 0}}, json{{"name", "other"}}});
    g.doc["scenes"] = json::array({json{{"nodes", json::array({0, 1})}}});
    const auto pointer = [](int sampler, const std::string& to) {
        return json{{"sampler", sampler},
                    {"target", {{"path", "pointer"}, {"extensions", {{"KHR_animation_pointer", {{"pointer", to}}}}}}}};
    };
    const json samplers = json::array({json{{"input", t}, {"output", moved}}, json{{"input", t}, {"output", big}},
                                       json{{"input", t2}, {"output", colour}}});
    g.doc["animations"] =
        json::array({json{{"name", "colour"},
                          {"samplers", samplers},
                          {"channels", json::array({pointer(2, "/materials/0/pbrMetallicRoughness/baseColorFactor")})}},
                     json{{"name", "ignored"},
                          {"samplers", samplers},
                          {"channels", json::array({json{{"sampler", 1}, {"target", {{"path", "scale"}}}}})}},
                     json{{"name", "slide"},
                          {"samplers", samplers},
                          {"channels", json::array({pointer(0, "/nodes/0/translation")})}}});
    const AnimatedMesh m = load_gltf(write("pointers.gltf", g.text()));
    ASSERT_EQ(m.clips.size(), 3u);
    EXPECT_EQ(m.clips[0].name, "colour");
    EXPECT_EQ(m.clips[0].keyframe_count, 61u);  // the colour's 2 s
    EXPECT_EQ(m.clips[2].source_animation, 2);
    for (size_t k = 0; k < m.clips[0].keyframe_count + m.clips[1].keyframe_count; ++k)
        expect_position(m, k, 1, 1, 0, 0);  // still
    const size_t last = m.clips[2].first_keyframe + m.clips[2].keyframe_count - 1;
    expect_position(m, last, 1, 2, 0, 0);  // slid by 1 in x
}

TEST_F(GltfLoader, PrimitivesCarryTheirMaterialFlags) {
    Gltf g;
    const std::vector<float> pos = {0, 0, 0, 1, 0, 0, 1, 1, 0};
    const int p = g.floats(pos, "VEC3", 3);
    json prims = json::array();
    for (int material : {-1, 0, 1, 2, 3}) {
        json prim = {{"attributes", {{"POSITION", p}}}};
        if (material >= 0) prim["material"] = material;
        prims.push_back(prim);
    }
    g.doc["materials"] = json::array({json{{"doubleSided", true}}, json{{"alphaMode", "BLEND"}},
                                      json{{"alphaMode", "MASK"}, {"doubleSided", true}},
                                      json{{"alphaMode", "OPAQUE"}, {"doubleSided", false}}});
    g.doc["meshes"] = json::array({json{{"name", "m"}, {"primitives", prims}}});
    g.doc["nodes"] = json::array({json{{"mesh", 0}}});
    g.doc["scenes"] = json::array({json{{"nodes", {0}}}});
    const AnimatedMesh m = load_gltf(write("materials.gltf", g.text()));
    ASSERT_EQ(m.primitives.size(), 5u);
    const bool sided[] = {false, true, false, true, false};
    const AlphaMode mode[] = {AlphaMode::Opaque, AlphaMode::Opaque, AlphaMode::Blend, AlphaMode::Mask,
                              AlphaMode::Opaque};
    for (size_t i = 0; i < 5; ++i) {
        EXPECT_EQ(m.primitives[i].double_sided, sided[i]) << i;
        EXPECT_EQ(m.primitives[i].alpha_mode, mode[i]) << i;
    }
    EXPECT_EQ(double_sided_triangles(m), (std::vector<uint8_t>{0, 1, 0, 1, 0}));
    EXPECT_TRUE(has_blended_primitives(m));

    g.doc["materials"][1]["alphaMode"] = "ADDITIVE";
    expect_load_error("bad-mode.gltf", g.text(), "alphaMode 'ADDITIVE'");
    g.doc["materials"][1]["alphaMode"] = "BLEND";
    g.doc["meshes"][0]["primitives"][1]["material"] = 9;
    expect_load_error("missing-material.gltf", g.text(), "names a missing material");
}

// The double-sided characters of ../shared/data, as their files say (read with Python's json module
// from the JSON chunk: both of Xbot's materials and both of MorphStressTest's are doubleSided, all OPAQUE).
TEST(GltfCharacters, DoubleSidedMaterialsOfSharedData) {
    ANIMORDER_REQUIRE_DATA(shared_data(""));
    test::DataFiles data;
    for (const char* f : {"glb-xbot/Xbot.glb", "gltf-morph-stress-test/MorphStressTest.gltf"}) {
        SCOPED_TRACE(f);
        if (!data.present(shared_data(f))) continue;
        const AnimatedMesh m = load_gltf(shared_data(f));
        ASSERT_GE(m.primitives.size(), 1u);
        for (const Primitive& p : m.primitives) {
            EXPECT_TRUE(p.double_sided) << p.name;
            EXPECT_EQ(p.alpha_mode, AlphaMode::Opaque) << p.name;
        }
    }
    for (const char* f : {"mixamo-ganfaul/Ganfaul.gltf", "gltf-fox/Fox.glb", "gltf-cesiumman/CesiumMan.glb"}) {
        SCOPED_TRACE(f);
        if (!data.present(shared_data(f))) continue;
        for (const Primitive& p : load_gltf(shared_data(f)).primitives) {
            EXPECT_FALSE(p.double_sided) << p.name;
            EXPECT_EQ(p.alpha_mode, AlphaMode::Opaque) << p.name;
        }
    }
    ANIMORDER_REQUIRE_ALL_DATA(data);
}

// The current folder moved to `folder` while it lives (tinygltf also looks for files there).
struct InFolder {
    explicit InFolder(const fs::path& folder) : before(fs::current_path()) { fs::current_path(folder); }
    ~InFolder() { fs::current_path(before); }
    fs::path before;
};

// files_load_reads lists what the loader will read, resolved as tinygltf resolves it: the files
// here are read by loading the same glTF (every listed buffer is one the load needs), and the
// spellings are worked out by hand from the URIs ('+' a space, %XY a byte, data: URIs inside).
TEST_F(GltfLoader, TheFilesALoadReadsAreListedAsTheLoaderResolvesThem) {
    Gltf g = skinned_bar();
    fs::create_directories(dir_ / "sub");
    write("sub/a b.bin", g.bin);
    g.doc["buffers"] = json::array({{{"byteLength", g.bin.size()}, {"uri", "sub/a%20b.bin"}}});
    g.doc["images"] =
        json::array({{{"uri", "tex+1.png"}}, {{"uri", "data:image/png;base64,AAAA"}}, {{"uri", "c%2Bd.png"}}});
    const std::string gltf = write("x.gltf", g.doc.dump());
    const std::string folder = dir_.string();
    const std::vector<std::string> expected = {gltf, folder + "/sub/a b.bin", folder + "/tex 1.png",
                                               folder + "/c+d.png"};
    EXPECT_EQ(files_load_reads(gltf), expected);
    std::vector<std::string> read;
    LoadOptions options;
    options.files_read = &read;
    EXPECT_EQ(load_character(gltf, {}, options).triangle_count(), 2u);  // the decoded buffer is the one it read
    EXPECT_EQ(read, expected);

    // A GLB's JSON chunk is read the same way; a chunk length past the end lists no external file.
    const std::string text = g.doc.dump();
    auto glb = [&](uint32_t chunk_length) {
        std::string bytes = "glTF";
        const uint32_t header[4] = {2, uint32_t(20 + text.size()), chunk_length, 0x4E4F534Au};  // "JSON"
        bytes.append(reinterpret_cast<const char*>(header), sizeof header);
        return bytes + text;
    };
    const std::string good = write("y.glb", glb(uint32_t(text.size())));
    EXPECT_EQ(files_load_reads(good),
              (std::vector<std::string>{good, folder + "/sub/a b.bin", folder + "/tex 1.png", folder + "/c+d.png"}));
    const std::string lying = write("z.glb", glb(uint32_t(text.size() + 1)));
    EXPECT_EQ(files_load_reads(lying), std::vector<std::string>{lying});
    EXPECT_EQ(files_load_reads(write("junk.gltf", "{not json")),
              std::vector<std::string>{(dir_ / "junk.gltf").string()});
}

// A file that never ends (a FIFO, a device) is refused at once, not read: as the character, as a
// glTF buffer URI (relative or absolute), and by the writers' read_model path (check, reapply).
TEST_F(GltfLoader, FilesThatAreNotRegularAreRefusedWithoutReadingThem) {
    const std::string fifo = (dir_ / "pipe.bin").string();
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    Gltf g = skinned_bar();
    g.doc["buffers"] = json::array({{{"byteLength", 12}, {"uri", "pipe.bin"}}});
    const std::string path = write("fifo.gltf", g.doc.dump());
    test::expect_one_line_load_error(path, "reads " + fifo + ", which is not a regular file",
                                     [&] { load_character(path); });
    EXPECT_THROW(require_regular_files(path), LoadError);
    // An absolute URI from a glTF named without a folder is taken as it is (tinygltf joins it to
    // an empty folder): /dev/zero.
    g.doc["buffers"] = json::array({{{"byteLength", 12}, {"uri", "/dev/zero"}}});
    write("zero.gltf", g.doc.dump());
    const InFolder here(dir_);
    test::expect_one_line_load_error("zero.gltf", "reads /dev/zero, which is not a regular file",
                                     [&] { load_character("zero.gltf"); });
    const std::string glb = (dir_ / "pipe.glb").string();
    ASSERT_EQ(::mkfifo(glb.c_str(), 0600), 0);
    test::expect_one_line_load_error(glb, "is not a regular file", [&] { load_character(glb); });
    test::expect_one_line_load_error(fifo, "is not a regular file", [&] { load_character(fifo); });
}

// tinygltf's other rules, each worked out from its source (tiny_gltf.h 2.7: FindFile tries the
// glTF's folder, then the current one; IsDataURI knows seven media types; an empty image URI is
// skipped): a buffer found only in the current folder is the one listed and read, a "data:" URI
// of another type is a file name, an empty image URI names nothing.
TEST_F(GltfLoader, UrisResolveAsTinygltfResolvesThem) {
    Gltf g = skinned_bar();
    fs::create_directories(dir_ / "a");
    write("x.bin", g.bin);  // beside the current folder only
    g.doc["buffers"] = json::array({{{"byteLength", g.bin.size()}, {"uri", "x.bin"}}});
    g.doc["images"] = json::array({{{"uri", ""}}, {{"uri", "data:x"}}});
    write("a/a.gltf", g.doc.dump());
    const InFolder here(dir_);
    const std::vector<std::string> expected = {"a/a.gltf", "./x.bin", "a/data:x"};
    EXPECT_EQ(files_load_reads("a/a.gltf"), expected);
    std::vector<std::string> read;
    LoadOptions options;
    options.files_read = &read;
    EXPECT_EQ(load_character("a/a.gltf", {}, options).triangle_count(), 2u);
    EXPECT_EQ(read, expected);
    ASSERT_EQ(::mkfifo("a/data:x", 0600), 0);  // a file, so a FIFO there is refused, not read
    test::expect_one_line_load_error("a/a.gltf", "reads a/data:x, which is not a regular file",
                                     [&] { load_character("a/a.gltf"); });
}

// No file is read whole beyond the loading budget (or its default, when that is more): a buffer
// of 5 GiB (sparse: nothing is written) is refused at once, not read into memory.
TEST_F(GltfLoader, AFileLargerThanTheBudgetIsNotRead) {
    Gltf g = skinned_bar();
    write("huge.bin", g.bin);
    fs::resize_file(dir_ / "huge.bin", uintmax_t(5) << 30);
    g.doc["buffers"] = json::array({{{"byteLength", g.bin.size()}, {"uri", "huge.bin"}}});
    const std::string path = write("huge.gltf", g.doc.dump());
    test::expect_one_line_load_error(path, "is larger than the loading budget of 4294967296 bytes",
                                     [&] { load_character(path); });
    LoadOptions small;
    small.max_keyframe_bytes = 1 << 20;  // a small keyframe budget still reads files up to the default
    EXPECT_EQ(small.file_budget(), LoadOptions{}.max_keyframe_bytes);
}
