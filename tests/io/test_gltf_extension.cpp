// The ANIMORDER_animated_triangle_orders reader and checker on the hand-written example of
// docs/extension (a quad: order 0 = 0 1 2 0 2 3, order 1 = 0 2 3 0 1 2, a 2 x 2 table 0 1 1 0,
// centre (0.5, 0.5, 0)), and on corrupted copies of it: each must be reported with its own
// one-line message, and read_orders_extension (the loader path of reapply and evaluate --stored)
// must refuse it with a LoadError.
#include "animorder/gltf_extension.h"
#include "animorder/load.h"

#include "support/files.h"
#include "support/require.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <functional>

using namespace animorder;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const char* const kExt = "ANIMORDER_animated_triangle_orders";

// The example's buffer, built here from the values the README states (not read from the file),
// with `edit` applied to the 12 order indices.
std::string buffer_bytes(const std::function<void(std::vector<uint16_t>&)>& edit = nullptr) {
    std::string b;
    auto put = [&b](const void* p, size_t n) { b.append(static_cast<const char*>(p), n); };
    const float positions[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    put(positions, sizeof positions);
    const uint16_t indices[] = {0, 1, 2, 0, 2, 3};
    put(indices, sizeof indices);
    std::vector<uint16_t> orders = {0, 1, 2, 0, 2, 3, 0, 2, 3, 0, 1, 2};
    if (edit) edit(orders);
    put(orders.data(), 24);
    const uint8_t table[] = {0, 1, 1, 0};
    put(table, 4);
    const float tail[] = {0.5f, 0.5f, 0, 0, 0, 0, 0};  // centre, key time, translation
    put(tail, sizeof tail);
    return b;
}

class GltfExtension : public test::ScratchFolderTest {
protected:
    GltfExtension() : ScratchFolderTest("animorder-gltf-extension") {}
    // The example with its buffer in example.bin, `edit` applied to its JSON; returns the path.
    std::string variant(const std::function<void(json&)>& edit, const std::string& bytes = buffer_bytes()) {
        json g = json::parse(test::slurp(fs::path(ANIMORDER_SOURCE_DIR) / "docs" / "extension" / "example.gltf"));
        g["buffers"][0]["uri"] = "example.bin";
        if (edit) edit(g);
        std::ofstream(path("example.bin"), std::ios::binary) << bytes;
        std::ofstream(path("example.gltf")) << g.dump(1);
        return path("example.gltf").string();
    }
};

}  // namespace

TEST_F(GltfExtension, TheExampleReadsAsTheReadmeDescribesIt) {
    // The shipped example itself (embedded buffer) and the rebuilt one agree.
    for (const std::string& file :
         {(fs::path(ANIMORDER_SOURCE_DIR) / "docs" / "extension" / "example.gltf").string(), variant(nullptr)}) {
        const OrdersExtensionCheck r = check_orders_extension(file);
        ASSERT_TRUE(r.errors.empty()) << r.errors.front();
        EXPECT_TRUE(r.present);
        EXPECT_EQ(r.method, "single");
        EXPECT_EQ(r.buffer_count, 2u);
        EXPECT_EQ(r.fallback, 0u);
        ASSERT_EQ(r.clips.size(), 1u);
        const ExtensionClip& c = r.clips[0];
        EXPECT_EQ(c.name, "still");
        EXPECT_EQ(c.animation, 0);
        EXPECT_EQ(c.sample_rate, 30);
        EXPECT_EQ(c.keyframes, 1u);
        EXPECT_EQ(c.theta_steps, 2u);
        EXPECT_EQ(c.phi_steps, 2u);
        EXPECT_EQ(c.cells, (std::vector<uint8_t>{0, 1, 1, 0}));
        EXPECT_EQ(c.centers, (std::vector<float>{0.5f, 0.5f, 0.f}));
        ASSERT_EQ(r.primitives.size(), 1u);
        const ExtensionPrimitive& p = r.primitives[0];
        EXPECT_EQ(p.component_type, 5123);
        EXPECT_EQ(p.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
        EXPECT_EQ(p.orders, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 2, 3, 0, 1, 2}));
        EXPECT_TRUE(p.indices_equal_fallback);
        EXPECT_EQ(p.order_is_permutation, (std::vector<bool>{true, true}));
        EXPECT_NO_THROW(read_orders_extension(file));
    }
}

TEST_F(GltfExtension, EveryCorruptionIsReportedOnOneLine) {
    const auto root = [](json& g) -> json& { return g["extensions"][kExt]; };
    const auto prim = [](json& g) -> json& { return g["meshes"][0]["primitives"][0]["extensions"][kExt]; };
    struct Case {
        const char* what;
        std::function<void(json&)> edit;
        std::string bytes;
        const char* expected;
    };
    const std::vector<Case> cases = {
        {"no extension",
         [](json& g) {
             g.erase("extensions");
             g.erase("extensionsUsed");
         },
         buffer_bytes(), "no ANIMORDER_animated_triangle_orders extension"},
        {"required", [](json& g) { g["extensionsRequired"] = {kExt}; }, buffer_bytes(),
         "must not be listed in extensionsRequired"},
        {"not used", [](json& g) { g["extensionsUsed"] = json::array(); }, buffer_bytes(),
         "not listed in extensionsUsed"},
        {"orders out of range", [&](json& g) { prim(g)["orders"] = 99; }, buffer_bytes(), "accessor 99 does not exist"},
        {"orders negative", [&](json& g) { prim(g)["orders"] = -1; }, buffer_bytes(), "orders = -1 is out of range"},
        {"orders of the wrong type", [&](json& g) { prim(g)["orders"] = 0; }, buffer_bytes(), "has the wrong type"},
        {"orders of bytes", [&](json& g) { prim(g)["orders"] = 3; }, buffer_bytes(), "UNSIGNED_BYTE"},
        {"orders past their view", [](json& g) { g["accessors"][2]["count"] = 14; }, buffer_bytes(),
         "more than its buffer view holds"},
        {"orderCount", [&](json& g) { prim(g)["orderCount"] = 3; }, buffer_bytes(),
         "orderCount 3 differs from bufferCount 2"},
        {"bufferCount",
         [&](json& g) {
             root(g)["bufferCount"] = 3;
             prim(g)["orderCount"] = 3;
         },
         buffer_bytes(), "orders has 12 elements; orderCount x indices = 18"},
        {"fallback out of range", [&](json& g) { root(g)["fallback"] = 2; }, buffer_bytes(),
         "fallback = 2 is out of range"},
        {"indices not the fallback", [&](json& g) { root(g)["fallback"] = 1; }, buffer_bytes(),
         "indices differs from order 1"},
        {"flipped winding", nullptr, buffer_bytes([](std::vector<uint16_t>& o) { std::swap(o[7], o[8]); }),
         "order 1 is not a permutation"},
        {"other triangle", nullptr, buffer_bytes([](std::vector<uint16_t>& o) { o[11] = 3; }),
         "order 1 is not a permutation"},
        {"table of the wrong size", [&](json& g) { root(g)["clips"][0]["thetaSteps"] = 3; }, buffer_bytes(),
         "table has 4 cells; keyframes x thetaSteps x phiSteps = 6"},
        {"table accessor out of range", [&](json& g) { root(g)["clips"][0]["table"] = 1000; }, buffer_bytes(),
         "accessor 1000 does not exist"},
        {"table of shorts", [&](json& g) { root(g)["clips"][0]["table"] = 1; }, buffer_bytes(), "component type 5123"},
        {"cell past bufferCount", [&](json& g) { root(g)["clips"][0]["bufferBase"] = 1; }, buffer_bytes(),
         "names order 2, not below bufferCount 2"},
        {"thetaSteps 1", [&](json& g) { root(g)["clips"][0]["thetaSteps"] = 1; }, buffer_bytes(),
         "thetaSteps = 1 is out of range"},
        {"sampleRate", [&](json& g) { root(g)["clips"][0]["sampleRate"] = 0; }, buffer_bytes(),
         "sampleRate is missing or not a positive"},
        {"centers of the wrong type", [&](json& g) { root(g)["clips"][0]["centers"] = 3; }, buffer_bytes(),
         "centers (accessor 3) has the wrong type"},
        {"animation out of range", [&](json& g) { root(g)["clips"][0]["animation"] = 5; }, buffer_bytes(),
         "animation = 5 is out of range"},
        // A null clip, which tinygltf drops (the clips after it were renumbered), an offset tinygltf
        // wraps, a sample rate that is 0 as the runtimes' float.
        {"null clip", [&](json& g) { root(g)["clips"].push_back(nullptr); }, buffer_bytes(),
         "clips[1] is not an object"},
        {"negative byteOffset", [](json& g) { g["accessors"][2]["byteOffset"] = -4; }, buffer_bytes(),
         "accessors[2].byteOffset -4 is not a non-negative integer"},
        {"sampleRate 0 as a float", [&](json& g) { root(g)["clips"][0]["sampleRate"] = 1e-300; }, buffer_bytes(),
         "sampleRate is missing or not a positive number a 32-bit float holds"},
        {"method not a string", [&](json& g) { root(g)["method"] = 5; }, buffer_bytes(), "root.method is not a string"},
        // A clip named after another animation: reapply put its table on that one.
        {"name of another animation", [&](json& g) { root(g)["clips"][0]["name"] = "walk"; }, buffer_bytes(),
         "clips[0].name 'walk' is not the name of animation 0 ('still')"},
        {"no clips", [&](json& g) { root(g)["clips"] = json::array(); }, buffer_bytes(), "clips is missing or empty"},
        {"sparse orders",
         [](json& g) {
             g["accessors"][2]["sparse"] = {{"count", 1},
                                            {"indices", {{"bufferView", 3}, {"componentType", 5121}}},
                                            {"values", {{"bufferView", 1}}}};
         },
         buffer_bytes(), "is sparse"},
        {"view outside the buffer", [](json& g) { g["bufferViews"][2]["byteOffset"] = 1000; }, buffer_bytes(),
         "lies outside its buffer"},
        // Integers past 32 bits, which tinygltf wraps (2^32 + 0 read as 0 passed): quoted as written.
        {"bufferBase past 2^32", [&](json& g) { root(g)["clips"][0]["bufferBase"] = 4294967296ULL; }, buffer_bytes(),
         "bufferBase = 4294967296 is out of range"},
        {"orders past 2^32", [&](json& g) { prim(g)["orders"] = 4294967298ULL; }, buffer_bytes(),
         "orders = 4294967298 is out of range"},
        {"fallback below -2^31", [&](json& g) { root(g)["fallback"] = -4294967296LL; }, buffer_bytes(),
         "fallback = -4294967296 is out of range"},
        {"bufferCount 2^62", [&](json& g) { root(g)["bufferCount"] = 4611686018427387904ULL; }, buffer_bytes(),
         "bufferCount = 4611686018427387904 is out of range"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        std::string file;
        try {
            file = variant(c.edit, c.bytes);
            const OrdersExtensionCheck r = check_orders_extension(file);
            ASSERT_FALSE(r.errors.empty());
            bool found = false;
            for (const std::string& e : r.errors) {
                EXPECT_EQ(e.find('\n'), std::string::npos) << e;
                found = found || e.find(c.expected) != std::string::npos;
            }
            EXPECT_TRUE(found) << r.errors.front();
        } catch (const LoadError& e) {  // tinygltf itself refused the file: also one line
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
            EXPECT_STREQ(c.what, "view outside the buffer") << e.what();
        }
        try {
            read_orders_extension(file);
            ADD_FAILURE() << "read_orders_extension accepted it";
        } catch (const LoadError& e) {
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        }
    }
}

// A clip's time range is the key times' data, as the loader (which wrote startTime) and the engines
// read them: an input accessor's declared min and max may disagree with it (a validator error that
// engines never see). Before, check took min and refused optimize's own output of such a file.
TEST_F(GltfExtension, KeyTimesAreTheDataNotTheDeclaredBounds) {
    const std::string stale = variant([](json& g) {
        g["accessors"][5]["min"] = json::array({0.25});  // the key is at 0
        g["accessors"][5]["max"] = json::array({0.25});
    });
    const OrdersExtensionCheck r = check_orders_extension(stale);
    EXPECT_TRUE(r.errors.empty()) << r.errors.front();
    const std::string shifted = variant([](json& g) { g["extensions"][kExt]["clips"][0]["startTime"] = 0.25; });
    const OrdersExtensionCheck wrong = check_orders_extension(shifted);
    ASSERT_EQ(wrong.errors.size(), 1u);
    EXPECT_NE(wrong.errors[0].find("startTime 0.250000 is not animation 0's first key time 0.000000"),
              std::string::npos)
        << wrong.errors[0];
}

TEST_F(GltfExtension, WritingIntoAnotherFileReadsBackTheSame) {
    const std::string input = variant([](json& g) {
        g.erase("extensions");
        g.erase("extensionsUsed");
        g["meshes"][0]["primitives"][0].erase("extensions");
    });
    OrdersExtensionCheck root =
        read_orders_extension((fs::path(ANIMORDER_SOURCE_DIR) / "docs" / "extension" / "example.gltf").string());
    root.fallback = 1;
    PrimitiveOrders po;
    po.mesh = 0, po.primitive = 0;
    po.orders = {1, 2, 0, 2, 3, 0, 3, 0, 2, 0, 1, 2};  // both orders, rotated corners
    for (const bool binary : {true, false}) {
        const fs::path out = path(binary ? "out.glb" : "out.gltf");
        std::ofstream(out, std::ios::binary) << gltf_with_extension_orders(input, out.string(), root, {po}, binary);
        const OrdersExtensionCheck r = check_orders_extension(out.string());
        ASSERT_TRUE(r.errors.empty()) << r.errors.front();
        EXPECT_EQ(r.fallback, 1u);
        EXPECT_EQ(r.primitives[0].orders, po.orders);
        EXPECT_EQ(r.primitives[0].indices, (std::vector<uint32_t>{3, 0, 2, 0, 1, 2}));
        EXPECT_EQ(r.clips[0].cells, (std::vector<uint8_t>{0, 1, 1, 0}));
        EXPECT_EQ(r.clips[0].animation, 0);
    }
}

TEST_F(GltfExtension, TheExamplePassesTheKhronosValidator) {
    std::string why, report;
    ANIMORDER_REQUIRE_OR_SKIP("validator", test::validator_available(why), why);
    const fs::path example = fs::path(ANIMORDER_SOURCE_DIR) / "docs" / "extension" / "example.gltf";
    ASSERT_TRUE(test::validate_gltf(example, report, dir_)) << report;
    EXPECT_EQ(nlohmann::json::parse(report)["errors"], 0) << report;
}

// The shared corpus of hostile files (tests/extension-corpus/, made by make.mjs): every reader
// gives each file its manifest's verdict (the JS runtime and the glTF-Transform extension in their
// own tests). Invalid: some error holds the manifest's phrase; every error is one line of
// printable text (a clip name's newline or ESC escaped).
TEST_F(GltfExtension, EveryCorpusFileGetsItsManifestVerdict) {
    const fs::path corpus = fs::path(ANIMORDER_SOURCE_DIR) / "tests" / "extension-corpus";
    const json manifest = json::parse(test::slurp(corpus / "manifest.json"));
    ASSERT_GE(manifest.size(), 40u);
    for (const json& entry : manifest) {
        const std::string file = entry["file"].get<std::string>();
        SCOPED_TRACE(file);
        std::vector<std::string> errors;
        try {
            errors = check_orders_extension((corpus / file).string()).errors;
        } catch (const LoadError& e) {  // tinygltf itself refused the file
            errors = {e.what()};
        }
        for (const std::string& e : errors)
            for (const char c : e) EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20 || c == 0x7f) << e;
        if (entry["valid"].get<bool>()) {
            EXPECT_TRUE(errors.empty()) << errors.front();
            continue;
        }
        ASSERT_FALSE(errors.empty());
        const std::string phrase = entry["phrase"].get<std::string>();
        EXPECT_TRUE(std::any_of(errors.begin(), errors.end(),
                                [&](const std::string& e) { return e.find(phrase) != std::string::npos; }))
            << "'" << phrase << "' not in: " << errors.front();
    }
}

namespace {

// A strip of `triangles` triangles (t, t+1, t+2, windings alternating) with `orders` orders, order
// b the triangles rotated b places, in `bin` (appended); as tests/extension-corpus/amplify.mjs.
// Returns the byte offsets of positions, indices, orders and the end.
std::array<size_t, 4> put_strip(std::string& bin, size_t triangles, size_t orders) {
    const auto put = [&bin](const void* p, size_t n) {
        bin.append(static_cast<const char*>(p), n);
        bin.append((4 - n % 4) % 4, '\0');
    };
    std::array<size_t, 4> at{};
    std::vector<float> positions;
    for (size_t v = 0; v < triangles + 2; ++v) positions.insert(positions.end(), {float(v / 2), float(v % 2), 0.f});
    const auto triangle = [](size_t t) {
        return t % 2 == 0 ? std::vector<uint16_t>{uint16_t(t), uint16_t(t + 1), uint16_t(t + 2)}
                          : std::vector<uint16_t>{uint16_t(t + 1), uint16_t(t), uint16_t(t + 2)};
    };
    std::vector<uint16_t> indices, all;
    for (size_t t = 0; t < triangles; ++t) {
        const auto c = triangle(t);
        indices.insert(indices.end(), c.begin(), c.end());
    }
    for (size_t b = 0; b < orders; ++b)
        for (size_t t = 0; t < triangles; ++t) {
            const auto c = triangle((t + b) % triangles);
            all.insert(all.end(), c.begin(), c.end());
        }
    at[0] = bin.size();
    put(positions.data(), positions.size() * 4);
    at[1] = bin.size();
    put(indices.data(), indices.size() * 2);
    at[2] = bin.size();
    put(all.data(), all.size() * 2);
    at[3] = bin.size();
    return at;
}

// `primitives` primitives sharing one POSITION, one orders and (unless `distinct_indices`) one
// indices accessor, and `clips` clips sharing one table of `cells` cells and one centres
// accessor: a small file that names its accessors thousands of times.
json shared_file(size_t primitives, size_t clips, size_t cells, bool distinct_indices, std::string& bin) {
    const size_t triangles = 500, orders = 8;
    const std::array<size_t, 4> at = put_strip(bin, triangles, orders);
    const size_t table = bin.size();
    for (size_t i = 0; i < cells; ++i) bin.push_back(char(i % orders));
    bin.append((4 - cells % 4) % 4, '\0');
    const size_t centre = bin.size();
    const float c[3] = {0.5f, 0.5f, 0};
    bin.append(reinterpret_cast<const char*>(c), 12);
    const auto view = [](size_t offset, size_t length) {
        return json{{"buffer", 0}, {"byteOffset", offset}, {"byteLength", length}};
    };
    json g = {{"asset", {{"version", "2.0"}}},
              {"extensionsUsed", {kExt}},
              {"scene", 0},
              {"scenes", {{{"nodes", {0}}}}},
              {"nodes", {{{"mesh", 0}}}},
              {"buffers", {{{"uri", "shared.bin"}, {"byteLength", bin.size()}}}},
              {"bufferViews",
               {view(at[0], at[1] - at[0]), view(at[1], at[2] - at[1]), view(at[2], at[3] - at[2]), view(table, cells),
                view(centre, 12)}},
              {"accessors",
               {{{"bufferView", 0}, {"componentType", 5126}, {"count", triangles + 2}, {"type", "VEC3"}},
                {{"bufferView", 1}, {"componentType", 5123}, {"count", 3 * triangles}, {"type", "SCALAR"}},
                {{"bufferView", 2}, {"componentType", 5123}, {"count", 3 * triangles * orders}, {"type", "SCALAR"}},
                {{"bufferView", 3}, {"componentType", 5121}, {"count", cells}, {"type", "SCALAR"}},
                {{"bufferView", 4}, {"componentType", 5126}, {"count", 1}, {"type", "VEC3"}}}}};
    json prims = json::array();
    for (size_t p = 0; p < primitives; ++p) {
        size_t indices = 1;
        if (distinct_indices && p > 0) {
            indices = g["accessors"].size();
            g["accessors"].push_back(g["accessors"][1]);
        }
        prims.push_back({{"attributes", {{"POSITION", 0}}},
                         {"indices", indices},
                         {"extensions", {{kExt, {{"orders", 2}, {"orderCount", orders}}}}}});
    }
    g["meshes"] = {{{"primitives", prims}}};
    const json clip = {{"name", "posed"}, {"sampleRate", 30},      {"keyframes", 1}, {"bufferBase", 0},
                       {"thetaSteps", 2}, {"phiSteps", cells / 2}, {"table", 3},     {"centers", 4}};
    g["extensions"][kExt] = {{"bufferCount", orders}, {"fallback", 0}, {"clips", json::array()}};
    for (size_t k = 0; k < clips; ++k) g["extensions"][kExt]["clips"].push_back(clip);
    return g;
}

}  // namespace

// Accessors that many clips and primitives share are read once and held once (each clip's cells
// and each primitive's orders the same storage); distinct (orders, indices) pairs over the same
// bytes, which would compare the orders once per primitive, are refused past the work cap.
TEST_F(GltfExtension, SharedAccessorsAreReadOnceAndTheWorkIsCapped) {
    std::string bin;
    const json shared = shared_file(2000, 1000, 200000, false, bin);
    std::ofstream(path("shared.bin"), std::ios::binary) << bin;
    std::ofstream(path("shared.gltf")) << shared.dump();
    const OrdersExtensionCheck r = check_orders_extension(path("shared.gltf").string());
    ASSERT_TRUE(r.errors.empty()) << r.errors.front();
    ASSERT_EQ(r.clips.size(), 1000u);
    ASSERT_EQ(r.primitives.size(), 2000u);
    EXPECT_EQ(r.clips[0].cells.data(), r.clips[999].cells.data());
    EXPECT_EQ(r.primitives[0].orders.data(), r.primitives[1999].orders.data());
    EXPECT_EQ(r.primitives[0].indices.data(), r.primitives[1999].indices.data());
    EXPECT_EQ(r.primitives[1999].order_is_permutation, std::vector<bool>(8, true));
    // Posing 2000 copies of the strip costs more than the file holds: check leaves it unposed.
    EXPECT_GT(r.posed_elements, r.work_budget);

    bin.clear();
    const json distinct = shared_file(2000, 1, 200, true, bin);
    std::ofstream(path("shared.bin"), std::ios::binary) << bin;
    std::ofstream(path("shared.gltf")) << distinct.dump();
    const OrdersExtensionCheck d = check_orders_extension(path("shared.gltf").string());
    ASSERT_EQ(d.errors.size(), 1u);
    EXPECT_NE(d.errors[0].find("more work than its file's size allows"), std::string::npos) << d.errors[0];
}
