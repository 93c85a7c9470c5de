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
#include "support/gltf_builder.h"
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
#include <set>
#include <sstream>

using namespace animorder;
namespace fs = std::filesystem;

namespace {

const std::string kData = test::shared_data_path().string();

struct Written {
    AnimatedMesh mesh;
    AnimatedMethodResult method;
    fs::path path;
    uint32_t fallback = 1;  // the buffer drawn: 1, or 0 when the method found one
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
    w.fallback = w.method.buffers.orders.size() > 1 ? 1 : 0;
    std::ofstream(output, std::ios::binary)
        << gltf_with_orders(input, output.string(), w.mesh, w.method.buffers, w.fallback, w.method.framing, "single",
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
    // Every character runs: a missing file is named at the end, and without the validator the
    // read-back checks still run (the test skips or fails for the validator at the end).
    test::DataFiles data;
    std::string why;
    const bool validator = test::validator_available(why);
    for (const char* name : {"gltf-cesiumman/CesiumMan.glb", "glb-robot-expressive/RobotExpressive.glb",
                             "gltf-morph-stress-test/MorphStressTest.gltf"}) {
        SCOPED_TRACE(name);
        if (!data.present(kData + name)) continue;
        const fs::path out = dir_ / (std::string("out") + fs::path(name).extension().string());
        const Written w = optimise_and_write(kData + name, out);

        // The output may not add a single validator error to those of the input (MorphStressTest
        // in ../shared/data lacks its PNG files: the same missing-image errors in both).
        // Both reports go to the scratch folder: ../shared/data is read only.
        std::string report, input_report;
        if (validator) {
            const bool valid = test::validate_gltf(out, report, dir_);
            test::validate_gltf(kData + name, input_report, dir_);
            std::printf("%s output: %sinput: %s", name, report.c_str(), input_report.c_str());
            const nlohmann::json r = nlohmann::json::parse(report), in = nlohmann::json::parse(input_report);
            if (!valid) {
                EXPECT_EQ(r["errors"], in["errors"]) << report;
                for (const auto& m : r["messages"]) EXPECT_EQ(m["code"], "IO_ERROR") << report;
            }
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
    ANIMORDER_REQUIRE_ALL_DATA(data);
    ANIMORDER_REQUIRE_OR_SKIP("validator", validator, why);
}

TEST_F(GltfWriter, DeterministicAndLeavesTheRestAlone) {
    const std::string input = kData + "gltf-cesiumman/CesiumMan.glb";
    ANIMORDER_REQUIRE_DATA(input);
    const Written a = optimise_and_write(input, dir_ / "a.gltf");
    const Written b = optimise_and_write(input, dir_ / "b.gltf");
    const std::string text = test::slurp_existing(a.path);
    EXPECT_EQ(text, test::slurp_existing(b.path));
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

// Writing orders over a file that already holds some (optimising an optimised file, as a pipeline
// run twice does) replaces them: the previous orders, tables, centres and drawn indices leave the
// file with their bytes, so it does not grow run after run; what the writer did not replace stays,
// bytes another view shares included; and a file with an extension whose references are unknown
// keeps every accessor where it was.
namespace {

struct Glb {
    nlohmann::json doc;
    std::string bin;
};

Glb read_glb(const fs::path& path) {
    const std::string bytes = test::slurp(path);
    Glb g;
    uint32_t json_length = 0, bin_length = 0;
    std::memcpy(&json_length, bytes.data() + 12, 4);
    g.doc = nlohmann::json::parse(bytes.substr(20, json_length));
    if (bytes.size() > 28 + json_length) {
        std::memcpy(&bin_length, bytes.data() + 20 + json_length, 4);
        g.bin = bytes.substr(28 + json_length, bin_length);
    }
    return g;
}

// The accessors and views something in the document names (core glTF and the orders extension),
// counted independently of the writer's own bookkeeping.
void expect_every_accessor_named_but(const nlohmann::json& doc, int unnamed) {
    std::set<int> accessors, views;
    for (const auto& mesh : doc["meshes"])
        for (const auto& prim : mesh["primitives"]) {
            for (const auto& a : prim["attributes"]) accessors.insert(a.get<int>());
            if (prim.contains("indices")) accessors.insert(prim["indices"].get<int>());
            if (prim.contains("targets"))
                for (const auto& target : prim["targets"])
                    for (const auto& a : target) accessors.insert(a.get<int>());
            if (prim.contains("extensions"))
                accessors.insert(prim["extensions"]["ANIMORDER_animated_triangle_orders"]["orders"].get<int>());
        }
    for (const auto& animation : doc["animations"])
        for (const auto& sampler : animation["samplers"]) {
            accessors.insert(sampler["input"].get<int>());
            accessors.insert(sampler["output"].get<int>());
        }
    for (const auto& clip : doc["extensions"]["ANIMORDER_animated_triangle_orders"]["clips"]) {
        accessors.insert(clip["table"].get<int>());
        accessors.insert(clip["centers"].get<int>());
    }
    accessors.insert(unnamed);
    for (int a = 0; a < int(doc["accessors"].size()); ++a) {
        EXPECT_EQ(accessors.count(a), 1u) << "accessor " << a << " is named by nothing";
        if (doc["accessors"][size_t(a)].contains("bufferView"))
            views.insert(doc["accessors"][size_t(a)]["bufferView"].get<int>());
    }
    EXPECT_EQ(accessors.size(), doc["accessors"].size());
    EXPECT_EQ(views.size(), doc["bufferViews"].size());  // every view is some accessor's
}

// A 16-triangle sheet bent by one animated morph target, drawn with 16-bit indices; accessor
// `shared` (named by nothing) reads the index bytes through a second view of the same bytes.
struct Sheet {
    test::Gltf g;
    int shared = -1;
    std::string index_bytes;
};

Sheet morph_sheet() {
    Sheet s;
    std::vector<float> pos, offsets;
    for (int y = 0; y <= 4; ++y)
        for (int x = 0; x <= 4; ++x) {
            pos.insert(pos.end(), {float(x), float(y), 0.0f});
            offsets.insert(offsets.end(), {0.0f, 0.0f, float((x - 2) * (x - 2)) * 0.3f});
        }
    std::vector<uint16_t> idx;
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            const uint16_t a = uint16_t(y * 5 + x), b = uint16_t(a + 1), c = uint16_t(a + 5), d = uint16_t(a + 6);
            idx.insert(idx.end(), {a, b, d, a, d, c});
        }
    auto& g = s.g;
    const int p = g.floats(pos, "VEC3", 3), i = g.u16(idx, "SCALAR", 1), m = g.floats(offsets, "VEC3", 3);
    g.doc["accessors"][size_t(p)]["min"] = {0, 0, 0};  // bounds: the validator asks them of positions
    g.doc["accessors"][size_t(p)]["max"] = {4, 4, 0};
    g.doc["accessors"][size_t(m)]["min"] = {0, 0, 0};
    g.doc["accessors"][size_t(m)]["max"] = {0, 0, 1.2};
    const size_t index_view = g.doc["accessors"][size_t(i)]["bufferView"].get<size_t>();
    g.doc["bufferViews"].push_back(g.doc["bufferViews"][index_view]);
    s.shared = int(g.doc["accessors"].size());
    g.doc["accessors"].push_back({{"bufferView", g.doc["bufferViews"].size() - 1},
                                  {"componentType", 5123},
                                  {"count", idx.size()},
                                  {"type", "SCALAR"}});
    s.index_bytes.assign(reinterpret_cast<const char*>(idx.data()), idx.size() * 2);
    const std::vector<float> times = {0, 1, 2}, weights = {0, 1, 0};
    const int t = g.floats(times, "SCALAR", 1), w = g.floats(weights, "SCALAR", 1);
    g.doc["accessors"][size_t(t)]["min"] = {0};
    g.doc["accessors"][size_t(t)]["max"] = {2};
    nlohmann::json primitive = {
        {"attributes", {{"POSITION", p}}}, {"indices", i}, {"targets", nlohmann::json::array({{{"POSITION", m}}})}};
    g.doc["meshes"] = nlohmann::json::array(
        {{{"primitives", nlohmann::json::array({primitive})}, {"weights", nlohmann::json::array({0.0})}}});
    g.doc["nodes"] = nlohmann::json::array({{{"mesh", 0}}});
    g.doc["scenes"] = nlohmann::json::array({{{"nodes", nlohmann::json::array({0})}}});
    g.doc["scene"] = 0;
    g.doc["animations"] = nlohmann::json::array(
        {{{"name", "bend"},
          {"samplers", nlohmann::json::array({{{"input", t}, {"output", w}}})},
          {"channels", nlohmann::json::array({{{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}}})}}});
    return s;
}

std::string accessor_bytes(const Glb& g, int accessor, size_t bytes) {
    const auto& a = g.doc["accessors"][size_t(accessor)];
    const auto& v = g.doc["bufferViews"][a["bufferView"].get<size_t>()];
    return g.bin.substr(v.value("byteOffset", size_t(0)) + a.value("byteOffset", size_t(0)), bytes);
}

}  // namespace

TEST_F(GltfWriter, WritingOverAFileWithOrdersReplacesThem) {
    Sheet sheet = morph_sheet();
    const fs::path input = dir_ / "sheet.gltf";
    std::ofstream(input) << sheet.g.text();
    const Written first = optimise_and_write(input.string(), dir_ / "o1.glb");
    const Written second = optimise_and_write(first.path.string(), dir_ / "o2.glb");
    const Written third = optimise_and_write(second.path.string(), dir_ / "o3.glb");
    const Glb in = read_glb(first.path), again = read_glb(second.path), last = read_glb(third.path);

    // The first run replaced the drawn indices (one accessor out, the orders, the fallback, one
    // table and its centres in); each later run replaced the previous run's: the same counts and
    // bytes run after run.
    const size_t input_accessors = sheet.g.doc["accessors"].size();
    EXPECT_EQ(in.doc["accessors"].size(), input_accessors - 1 + 4);
    EXPECT_EQ(again.doc["accessors"].size(), in.doc["accessors"].size());
    EXPECT_EQ(last.doc["accessors"].size(), in.doc["accessors"].size());
    EXPECT_EQ(again.doc["bufferViews"].size(), in.doc["bufferViews"].size());
    EXPECT_EQ(again.bin.size(), in.bin.size());
    EXPECT_EQ(last.bin.size(), in.bin.size());
    EXPECT_EQ(test::slurp_existing(third.path).size(), test::slurp_existing(second.path).size());
    for (const Glb* g : {&in, &again, &last}) {
        SCOPED_TRACE(g == &in ? "first" : g == &again ? "second" : "third");
        // The only accessor nothing names is the input's own, kept with the bytes it shares.
        expect_every_accessor_named_but(g->doc, sheet.shared);
        EXPECT_EQ(accessor_bytes(*g, sheet.shared, sheet.index_bytes.size()), sheet.index_bytes);
    }

    // The last file still reads as the character, drawing its fallback order, and checks clean.
    const AnimatedMesh back = load_gltf(third.path.string());
    EXPECT_EQ(back.keyframe_positions, first.mesh.keyframe_positions);
    EXPECT_TRUE(test::same_triangles_same_winding(first.mesh.indices, back.indices));
    const OrdersExtensionCheck r = check_orders_extension(third.path.string());
    ASSERT_TRUE(r.errors.empty()) << r.errors.front();
    std::vector<uint32_t> fallback(third.mesh.indices.size());
    apply_triangle_order(fallback.data(), third.mesh.indices.data(), third.method.buffers.orders[third.fallback].data(),
                         third.mesh.triangle_count());
    EXPECT_EQ(back.indices, fallback);
    std::string report, why;
    ANIMORDER_REQUIRE_OR_SKIP("validator", test::validator_available(why), why);
    EXPECT_TRUE(test::validate_gltf(third.path, report, dir_)) << report;
}

TEST_F(GltfWriter, AFileWithAnUnknownExtensionKeepsEveryAccessorWhereItWas) {
    Sheet sheet = morph_sheet();
    // An extension this tool does not know, naming the drawn indices' accessor (1) by number:
    // renumbering the accessors could make it name another one.
    sheet.g.doc["extensionsUsed"] = nlohmann::json::array({"VENDOR_names_an_accessor"});
    sheet.g.doc["nodes"][0]["extensions"] = {{"VENDOR_names_an_accessor", {{"accessor", 1}}}};
    const fs::path input = dir_ / "vendor.gltf";
    std::ofstream(input) << sheet.g.text();
    const Written first = optimise_and_write(input.string(), dir_ / "v1.glb");
    const Written second = optimise_and_write(first.path.string(), dir_ / "v2.glb");
    const Glb in = read_glb(first.path), again = read_glb(second.path);
    EXPECT_EQ(in.doc["accessors"].size(), sheet.g.doc["accessors"].size() + 4);  // nothing left out
    EXPECT_EQ(again.doc["accessors"].size(), in.doc["accessors"].size() + 4);
    EXPECT_GT(again.bin.size(), in.bin.size());
    EXPECT_EQ(again.doc["nodes"][0]["extensions"]["VENDOR_names_an_accessor"]["accessor"], 1);
    EXPECT_EQ(accessor_bytes(again, 1, sheet.index_bytes.size()), sheet.index_bytes);  // still the indices
    // The writer says why the file keeps them; a file it prunes gets no note.
    std::string note = "unset";
    gltf_with_orders(first.path.string(), (dir_ / "v3.glb").string(), second.mesh, second.method.buffers,
                     second.fallback, second.method.framing, "single", true, &note);
    EXPECT_NE(note.find("uses extension VENDOR_names_an_accessor"), std::string::npos) << note;
    const fs::path plain = dir_ / "plain.gltf";  // the same sheet, no unknown extension
    std::ofstream(plain) << morph_sheet().g.text();
    note = "unset";
    gltf_with_orders(plain.string(), (dir_ / "p1.glb").string(), first.mesh, first.method.buffers, first.fallback,
                     first.method.framing, "single", true, &note);
    EXPECT_EQ(note, "unset");
}

// A buffer that held only the replaced indices (a .gltf whose views each have their own .bin, say)
// leaves with them: written with byteLength 0, it made the output invalid glTF that no loader,
// animorder's own included, reads back.
TEST_F(GltfWriter, ABufferThatHeldOnlyTheReplacedIndicesLeavesWithThem) {
    Sheet sheet = morph_sheet();
    nlohmann::json doc = nlohmann::json::parse(sheet.g.text());
    const size_t index_view = doc["accessors"][1]["bufferView"].get<size_t>();
    doc["bufferViews"][index_view]["buffer"] = 1;
    doc["bufferViews"][index_view]["byteOffset"] = 0;
    doc["buffers"].push_back({{"byteLength", sheet.index_bytes.size()},
                              {"uri", "data:application/octet-stream;base64," + test::base64(sheet.index_bytes)}});
    const fs::path input = dir_ / "two-buffers.gltf";
    std::ofstream(input) << doc.dump();
    const Written first = optimise_and_write(input.string(), dir_ / "t1.gltf");
    const nlohmann::json out = nlohmann::json::parse(test::slurp(first.path));
    ASSERT_EQ(out["buffers"].size(), 1u);
    EXPECT_GT(out["buffers"][0]["byteLength"].get<size_t>(), 0u);
    for (const auto& view : out["bufferViews"]) EXPECT_EQ(view["buffer"], 0);
    const AnimatedMesh back = load_gltf(first.path.string());  // reads back
    EXPECT_TRUE(test::same_triangles_same_winding(first.mesh.indices, back.indices));
    const Written second = optimise_and_write(first.path.string(), dir_ / "t2.gltf");
    EXPECT_TRUE(check_orders_extension(second.path.string()).errors.empty());
    std::string report, why;
    ANIMORDER_REQUIRE_OR_SKIP("validator", test::validator_available(why), why);
    EXPECT_TRUE(test::validate_gltf(first.path, report, dir_)) << report;
}

// Orders a previous run left on a primitive that is not rewritten now (its mesh drawn by no node)
// leave with the rest: they named another buffer count than the new root object.
TEST_F(GltfWriter, OrdersOnAPrimitiveNoNodeDrawsLeaveWithTheRest) {
    Sheet sheet = morph_sheet();
    const fs::path input = dir_ / "sheet.gltf";
    std::ofstream(input) << sheet.g.text();
    const Written first = optimise_and_write(input.string(), dir_ / "s1.gltf");
    nlohmann::json doc = nlohmann::json::parse(test::slurp(first.path));
    doc["meshes"].push_back(doc["meshes"][0]);  // drawn by no node: the loader never reads it
    ASSERT_TRUE(doc["meshes"][1]["primitives"][0].contains("extensions"));
    std::ofstream(dir_ / "undrawn.gltf") << doc.dump();
    const Written second = optimise_and_write((dir_ / "undrawn.gltf").string(), dir_ / "s2.gltf");
    const nlohmann::json out = nlohmann::json::parse(test::slurp(second.path));
    EXPECT_FALSE(out["meshes"][1]["primitives"][0].contains("extensions"));
    EXPECT_TRUE(check_orders_extension(second.path.string()).errors.empty());
    // The stale orders accessor left too (the undrawn mesh keeps its indices, the old fallback).
    size_t orders_accessors = 0;
    for (const auto& a : out["accessors"]) orders_accessors += a.value("name", "") == "animorder orders";
    EXPECT_EQ(orders_accessors, 1u);
    const auto& undrawn = out["accessors"][out["meshes"][1]["primitives"][0]["indices"].get<size_t>()];
    EXPECT_EQ(undrawn["name"], "animorder fallback order");
    EXPECT_EQ(undrawn["count"], first.mesh.indices.size());
}

// What tinygltf 2.7 reads but does not write is put back from the input (gltf_buffer.h): an image
// given as a data: URI (its bytes were lost: an invalid image, a file three.js refused), and
// extras (nulls in them too) and extensions on skins, samplers, channel targets, accessors, buffer
// views and buffers. Accessors and views are followed to where the writer moved them: the drawn
// indices' accessor and view leave the file, and a new accessor takes the freed place.
TEST_F(GltfWriter, WhatTinygltfLeavesOutIsPutBack) {
    Sheet sheet = morph_sheet();
    nlohmann::json doc = nlohmann::json::parse(sheet.g.text());
    const std::string png = "data:image/png;base64," + test::base64(std::string("\x89PNG\r\n\x1a\n", 8));
    const nlohmann::json xmp = {{"KHR_xmp_json_ld", {{"packet", 0}}}};
    doc["extensionsUsed"] = {"KHR_xmp_json_ld"};
    doc["extensions"]["KHR_xmp_json_ld"] = {{"packets", {{{"dc:creator", {"animorder test"}}}}}};
    doc["images"] = {{{"uri", png}}};
    doc["samplers"] = {{{"magFilter", 9729}, {"extras", {{"list", {1, nullptr, 2}}}}, {"extensions", xmp}}};
    doc["textures"] = {{{"source", 0}, {"sampler", 0}}};
    for (size_t a = 0; a < doc["accessors"].size(); ++a) {
        doc["accessors"][a]["extras"] = {{"accessor", a}, {"unset", nullptr}};
        doc["accessors"][a]["extensions"] = xmp;
    }
    for (size_t v = 0; v < doc["bufferViews"].size(); ++v) doc["bufferViews"][v]["extras"] = {{"view", v}};
    doc["buffers"][0]["extras"] = {{"buffer", 0}};
    doc["animations"][0]["channels"][0]["target"]["extras"] = {{"target", {nullptr}}};
    doc["animations"][0]["samplers"][0]["extras"] = {{"sampler", 0}};
    doc["extras"] = {{"root", {nullptr, 1}}};
    const fs::path input = dir_ / "extras.gltf";
    std::ofstream(input) << doc.dump();
    const size_t index_accessor = 1, index_view = doc["accessors"][index_accessor]["bufferView"].get<size_t>();

    for (const char* name : {"extras-out.gltf", "extras-out.glb"}) {
        SCOPED_TRACE(name);
        const Written w = optimise_and_write(input.string(), dir_ / name);
        const nlohmann::json out =
            w.path.extension() == ".glb" ? read_glb(w.path).doc : nlohmann::json::parse(test::slurp(w.path));
        EXPECT_EQ(out["images"][0], doc["images"][0]);  // the URI, no bufferView -1
        EXPECT_EQ(out["samplers"][0]["extras"], doc["samplers"][0]["extras"]);
        EXPECT_EQ(out["samplers"][0]["extensions"], xmp);
        EXPECT_EQ(out["buffers"][0]["extras"], doc["buffers"][0]["extras"]);
        EXPECT_EQ(out["animations"][0]["channels"][0]["target"]["extras"],
                  doc["animations"][0]["channels"][0]["target"]["extras"]);
        EXPECT_EQ(out["animations"][0]["samplers"][0]["extras"], doc["animations"][0]["samplers"][0]["extras"]);
        EXPECT_EQ(out["extras"], doc["extras"]);
        // Each input accessor but the drawn indices' is found once, by its extras, with its own
        // type, count and extension; the writer's new ones have none.
        std::set<size_t> accessors, views;
        for (const auto& a : out["accessors"]) {
            if (!a.contains("extras")) {
                EXPECT_FALSE(a.contains("extensions")) << a;
                continue;
            }
            const size_t from = a["extras"]["accessor"].get<size_t>();
            EXPECT_TRUE(accessors.insert(from).second) << from;
            EXPECT_EQ(a["extras"], doc["accessors"][from]["extras"]);
            EXPECT_EQ(a["extensions"], xmp);
            for (const char* key : {"type", "count", "componentType"}) EXPECT_EQ(a[key], doc["accessors"][from][key]);
        }
        for (size_t a = 0; a < doc["accessors"].size(); ++a)
            EXPECT_EQ(accessors.count(a), a == index_accessor ? 0u : 1u);
        for (const auto& v : out["bufferViews"]) {
            if (v.contains("extras")) {
                EXPECT_TRUE(views.insert(v["extras"]["view"].get<size_t>()).second);
            }
        }
        for (size_t v = 0; v < doc["bufferViews"].size(); ++v) EXPECT_EQ(views.count(v), v == index_view ? 0u : 1u);
        EXPECT_TRUE(check_orders_extension(w.path.string()).errors.empty());
        std::string report, input_report, why;
        ANIMORDER_REQUIRE_OR_SKIP("validator", test::validator_available(why), why);
        test::validate_gltf(w.path, report, dir_);
        test::validate_gltf(input, input_report, dir_);
        EXPECT_EQ(nlohmann::json::parse(report)["errors"], nlohmann::json::parse(input_report)["errors"])
            << report << input_report;
    }
}
