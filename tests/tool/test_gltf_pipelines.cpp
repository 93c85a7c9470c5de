// The orders through real glTF pipelines, on the bundled character (exported with `subdivide
// --levels 0`) and two characters of ../shared/data: glTF-Transform (prune, dedup, resample,
// reorder, weld, optimize without compression or simplification) with js/gltf-transform-animorder
// registered keeps (or re-derives) orders that `check` accepts; gltf-pipeline and gltfpack outputs are rejected
// by `check` (their orders are gone or dangle), and `reapply` turns them into files that `check`
// accepts and whose stored-order OVR (`evaluate --stored`) equals the optimised file's within
// 0.001. Every output passes the Khronos glTF Validator without errors. A simplified file is
// refused by `reapply` with one line and nothing written, and taken with --nearest: its orders
// then beat its own order's overdraw. glTF-Transform's `optimize` with its default simplification
// (compression off) keeps orders the extension places by the nearest original triangles.
#include "support/files.h"
#include "support/gltf_builder.h"
#include "support/require.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;
namespace test = animorder::test;
using nlohmann::json;

namespace {

const fs::path kSource = ANIMORDER_SOURCE_DIR;
const fs::path kTools = kSource / ".tools" / "node_modules" / ".bin";
const fs::path kConfig = kSource / "js" / "gltf-transform-animorder" / "gltf-transform.config.js";

bool on_path(const std::string& program) {
    return std::system(("command -v " + program + " >/dev/null 2>&1").c_str()) == 0;
}

class GltfPipelines : public test::ScratchFolderTest {
protected:
    GltfPipelines() : ScratchFolderTest("animorder-gltf-pipelines") {}
    test::Outcome run(const std::string& command) { return test::run_captured(command, dir_); }
    std::string exe() const { return ANIMORDER_EXE; }
    std::string q(const fs::path& p) const { return "'" + p.string() + "'"; }

    bool tools_present(std::string& why) const {
        for (const char* t : {"gltf-transform", "gltf-pipeline"})
            if (!fs::exists(kTools / t)) {
                why = (kTools / t).string() + " is absent (run scripts/install-deps.sh)";
                return false;
            }
        if (!fs::exists(kSource / "js" / "gltf-transform-animorder" / "node_modules" / "@gltf-transform" / "core")) {
            why = "js/gltf-transform-animorder/node_modules is absent (run scripts/install-deps.sh)";
            return false;
        }
        if (!on_path("gltfpack") || !on_path("node")) {
            why = "gltfpack or node is not on PATH (Debian packages gltfpack, nodejs)";
            return false;
        }
        return true;
    }

    void expect_valid(const fs::path& file) {
        std::string report;
        const bool valid = test::validate_gltf(file, report, dir_);
        EXPECT_TRUE(valid) << file << ": " << report;
        if (valid) {
            EXPECT_EQ(json::parse(report)["errors"], 0) << file << ": " << report;
        }
    }

    int check(const fs::path& file) {
        const test::Outcome o = run(exe() + " check " + q(file));
        EXPECT_EQ(o.exit_code == 0, json::parse(o.out)["ok"].get<bool>()) << o.out;
        if (o.exit_code != 0) {
            EXPECT_EQ(test::line_count(o.err), 1u) << o.err;
        }
        return o.exit_code;
    }

    double stored_ovr(const fs::path& file) {
        const fs::path report = path(file.stem().string() + ".evaluate.json");
        const test::Outcome o =
            run(exe() + " evaluate -q --methods original --stored --eval-views 12 --eval-resolution 64 " + q(file) +
                " --report " + q(report));
        EXPECT_EQ(o.exit_code, 0) << o.err;
        if (o.exit_code != 0) return -1;
        const json j = json::parse(test::slurp(report));
        EXPECT_EQ(j["methods"].back()["name"], "stored");
        return j["methods"].back()["ovr_mean"].get<double>();
    }

    // The OVR of the file's own triangle order (evaluate's `original`).
    double file_order_ovr(const fs::path& file) {
        const fs::path report = path(file.stem().string() + ".original.json");
        const test::Outcome o = run(exe() + " evaluate -q --methods original --eval-views 12 --eval-resolution 64 " +
                                    q(file) + " --report " + q(report));
        EXPECT_EQ(o.exit_code, 0) << o.err;
        if (o.exit_code != 0) return -1;
        return json::parse(test::slurp(report))["methods"][0]["ovr_mean"].get<double>();
    }

    // The bundled character as glTF JSON (subdivide --levels 0), to edit into a test's input.
    json bundled_character() {
        const test::Outcome o = run(exe() + " subdivide -q --levels 0 -o " + q(path("character.gltf")));
        EXPECT_EQ(o.exit_code, 0) << o.err;
        return json::parse(test::slurp(path("character.gltf")));
    }

    // `g` written as NAME.gltf, optimised cheaply into NAME-optimised.glb, through gltfpack, then
    // reapplied: both the optimised and the reapplied file pass `check`.
    void optimise_pack_reapply(const json& g, const std::string& name) {
        SCOPED_TRACE(name);
        std::ofstream(path(name + ".gltf")) << g.dump();
        const fs::path optimised = path(name + "-optimised.glb"), pack = path(name + "-gltfpack.glb");
        test::Outcome o =
            run(exe() + " optimize -q --method single -k 2 --views 12 --resolution 64 --max-iterations 2 " +
                q(path(name + ".gltf")) + " -o " + q(optimised));
        ASSERT_EQ(o.exit_code, 0) << o.err;
        EXPECT_EQ(check(optimised), 0);
        o = run("gltfpack -i " + q(optimised) + " -o " + q(pack));
        ASSERT_EQ(o.exit_code, 0) << o.out << o.err;
        o = run(exe() + " reapply " + q(optimised) + " " + q(pack) + " -o " + q(path(name + "-reapplied.glb")));
        ASSERT_EQ(o.exit_code, 0) << o.err;
        EXPECT_EQ(check(path(name + "-reapplied.glb")), 0);
    }

    void round_trip(const fs::path& input, const std::string& name) {
        SCOPED_TRACE(name);
        const fs::path optimised = path(name + ".glb");
        test::Outcome o =
            run(exe() + " optimize -q --method single -k 3 --views 12 --resolution 64 --max-iterations 3 " + q(input) +
                " -o " + q(optimised));
        ASSERT_EQ(o.exit_code, 0) << o.err;
        ASSERT_EQ(check(optimised), 0);
        expect_valid(optimised);
        const double ovr = stored_ovr(optimised);
        ASSERT_GT(ovr, 1.0);

        // glTF-Transform with the extension registered: the orders stay valid.
        const std::string gt = q(kTools / "gltf-transform");
        for (const std::string& step :
             {std::string("prune"), std::string("dedup"), std::string("resample"), std::string("reorder"),
              std::string("weld"),
              std::string("optimize --compress false --texture-compress false --simplify false")}) {
            SCOPED_TRACE(step);
            const fs::path out = path(name + "-gt-" + step.substr(0, step.find(' ')) + ".glb");
            const std::string verb = step.substr(0, step.find(' '));
            const std::string rest = step.find(' ') == std::string::npos ? "" : step.substr(step.find(' '));
            o = run(gt + " " + verb + " " + q(optimised) + " " + q(out) + rest + " --config " + q(kConfig));
            ASSERT_EQ(o.exit_code, 0) << o.out << o.err;
            EXPECT_EQ(check(out), 0);
            expect_valid(out);
            EXPECT_NEAR(stored_ovr(out), ovr, 1e-3);
        }

        // `optimize` with its default simplification (compression off): the extension places the
        // simplified triangles by the nearest original ones. The orders pass `check` and the
        // validator, and draw with less overdraw than the same pipeline's own order (run without
        // the extension).
        {
            const fs::path placed = path(name + "-gt-optimize-simplified.glb"), plain = path(name + "-gt-plain.glb");
            const std::string settings = " --compress false --texture-compress false";
            o = run(gt + " optimize " + q(optimised) + " " + q(placed) + settings + " --config " + q(kConfig));
            ASSERT_EQ(o.exit_code, 0) << o.out << o.err;
            EXPECT_NE((o.out + o.err).find("placed the triangles"), std::string::npos) << o.out << o.err;
            EXPECT_EQ(check(placed), 0);
            expect_valid(placed);
            o = run(gt + " optimize " + q(optimised) + " " + q(plain) + settings);
            ASSERT_EQ(o.exit_code, 0) << o.out << o.err;
            const double with = stored_ovr(placed), without = file_order_ovr(plain);
            EXPECT_LT(with, without);
            EXPECT_LT(with, ovr + 0.05);  // measured: within 0.03 on these three characters
            std::printf("%s through gltf-transform optimize --compress false: OVR %.4f in its own order, %.4f with "
                        "the placed orders (the optimised file's: %.4f)\n",
                        name.c_str(), without, with, ovr);
        }

        // The file's other extensions stay: the config's extension list replaces the CLI's own,
        // and once held only ours, so quantize wrote KHR_mesh_quantization's accessors without
        // the extension (invalid) and prune dropped every KHR_* one.
        const fs::path quantized = path(name + "-gt-quantize.glb");
        o = run(gt + " quantize " + q(optimised) + " " + q(quantized) + " --config " + q(kConfig));
        ASSERT_EQ(o.exit_code, 0) << o.out << o.err;
        EXPECT_NE(test::slurp(quantized).find("KHR_mesh_quantization"), std::string::npos);
        expect_valid(quantized);
        EXPECT_EQ(check(quantized), 0);

        // gltf-pipeline (dangling accessor references) and gltfpack (extension dropped, triangles
        // reordered, positions quantised): check rejects, reapply repairs.
        const fs::path pipeline = path(name + "-pipeline.glb"), pack = path(name + "-gltfpack.glb");
        o = run(q(kTools / "gltf-pipeline") + " -i " + q(optimised) + " -o " + q(pipeline));
        ASSERT_EQ(o.exit_code, 0) << o.out << o.err;
        o = run("gltfpack -i " + q(optimised) + " -o " + q(pack));
        ASSERT_EQ(o.exit_code, 0) << o.out << o.err;
        for (const fs::path& processed : {pipeline, pack}) {
            SCOPED_TRACE(processed.filename().string());
            EXPECT_EQ(check(processed), 1);
            const fs::path repaired = path(processed.stem().string() + "-reapplied.glb");
            o = run(exe() + " reapply " + q(optimised) + " " + q(processed) + " -o " + q(repaired));
            ASSERT_EQ(o.exit_code, 0) << o.err;
            EXPECT_NE(o.err.find("matched"), std::string::npos) << o.err;
            EXPECT_EQ(check(repaired), 0);
            expect_valid(repaired);
            EXPECT_NEAR(stored_ovr(repaired), ovr, 1e-3);
            // Every triangle found: --nearest changes nothing.
            const fs::path nearest = path(processed.stem().string() + "-reapplied-nearest.glb");
            o = run(exe() + " reapply -q --nearest 0.1 " + q(optimised) + " " + q(processed) + " -o " + q(nearest));
            ASSERT_EQ(o.exit_code, 0) << o.err;
            EXPECT_EQ(test::slurp(nearest), test::slurp(repaired));
        }

        // A simplified file: refused in one line, nothing written, unless --nearest places its
        // triangles by the optimised ones they stand for. Its orders then pass `check` and the
        // validator, and draw it with less overdraw than its own order (gltfpack's).
        const fs::path simplified = path(name + "-simplified.glb"), refused = path(name + "-refused.glb");
        o = run("gltfpack -si 0.3 -sa -i " + q(optimised) + " -o " + q(simplified));
        ASSERT_EQ(o.exit_code, 0) << o.err;
        o = run(exe() + " reapply -q " + q(optimised) + " " + q(simplified) + " -o " + q(refused));
        EXPECT_EQ(o.exit_code, 1);
        EXPECT_EQ(test::line_count(o.err), 1u) << o.err;
        EXPECT_NE(o.err.find("nothing written"), std::string::npos) << o.err;
        EXPECT_NE(o.err.find("--nearest"), std::string::npos) << o.err;
        EXPECT_FALSE(fs::exists(refused));
        const fs::path placed = path(name + "-simplified-reapplied.glb");
        o = run(exe() + " reapply --nearest 0.1 " + q(optimised) + " " + q(simplified) + " -o " + q(placed));
        ASSERT_EQ(o.exit_code, 0) << o.err;
        EXPECT_NE(o.out.find("placed by the nearest optimised one"), std::string::npos) << o.out;
        EXPECT_EQ(check(placed), 0);
        expect_valid(placed);
        const double own = file_order_ovr(simplified), reapplied = stored_ovr(placed);
        EXPECT_LT(reapplied, own) << "the simplified file's own order: " << own;
        // Close to the full mesh's orders (measured: within 0.035 on these three characters).
        EXPECT_LT(reapplied, ovr + 0.05);
        std::printf("%s simplified to 30%%: OVR %.4f in its own order, %.4f with the reapplied orders "
                    "(the optimised file's: %.4f)\n",
                    name.c_str(), own, reapplied, ovr);
        // The same mesh with no triangle near enough: refused, nothing written.
        o = run(exe() + " reapply -q --nearest 1e-9 " + q(optimised) + " " + q(simplified) + " -o " + q(refused));
        EXPECT_EQ(o.exit_code, 1);
        EXPECT_EQ(test::line_count(o.err), 1u) << o.err;
        EXPECT_NE(o.err.find("--nearest"), std::string::npos) << o.err;
        EXPECT_FALSE(fs::exists(refused));
    }
};

}  // namespace

TEST_F(GltfPipelines, BundledCharacter) {
    std::string why;
    ANIMORDER_REQUIRE_OR_SKIP("gltf-tools", tools_present(why), why);
    ANIMORDER_REQUIRE_OR_SKIP("validator", test::validator_available(why), why);
    const test::Outcome o = run(exe() + " subdivide -q --levels 0 -o " + q(path("character.glb")));
    ASSERT_EQ(o.exit_code, 0) << o.err;
    round_trip(path("character.glb"), "character-optimised");
}

TEST_F(GltfPipelines, CesiumMan) {
    std::string why;
    const fs::path input = test::shared_data_path("gltf-cesiumman/CesiumMan.glb");
    ANIMORDER_REQUIRE_DATA(input);
    ANIMORDER_REQUIRE_OR_SKIP("gltf-tools", tools_present(why), why);
    ANIMORDER_REQUIRE_OR_SKIP("validator", test::validator_available(why), why);
    round_trip(input, "cesiumman");
}

TEST_F(GltfPipelines, Fox) {
    std::string why;
    const fs::path input = test::shared_data_path("gltf-fox/Fox.glb");
    ANIMORDER_REQUIRE_DATA(input);
    ANIMORDER_REQUIRE_OR_SKIP("gltf-tools", tools_present(why), why);
    ANIMORDER_REQUIRE_OR_SKIP("validator", test::validator_available(why), why);
    round_trip(input, "fox");
}

TEST_F(GltfPipelines, CheckAndReapplyRefuseBadInputInOneLine) {
    // A file without the extension, and one with it corrupted (tables of the wrong size).
    const fs::path example = kSource / "docs" / "extension" / "example.gltf";
    json g = json::parse(test::slurp(example));
    g["extensions"]["ANIMORDER_animated_triangle_orders"]["clips"][0]["phiSteps"] = 7;
    std::ofstream(path("corrupt.gltf")) << g.dump();
    g.erase("extensions");
    g.erase("extensionsUsed");
    std::ofstream(path("plain.gltf")) << g.dump();
    test::Outcome o = run(exe() + " check " + q(path("plain.gltf")));
    EXPECT_EQ(o.exit_code, 1);
    EXPECT_EQ(test::line_count(o.err), 1u) << o.err;
    EXPECT_NE(o.err.find("no ANIMORDER_animated_triangle_orders extension"), std::string::npos) << o.err;
    EXPECT_FALSE(json::parse(o.out)["present"].get<bool>());
    o = run(exe() + " check " + q(path("corrupt.gltf")));
    EXPECT_EQ(o.exit_code, 1);
    EXPECT_NE(o.err.find("table has 4 cells"), std::string::npos) << o.err;
    // No glTF at all: the same one line, and still a report on stdout (it printed none).
    std::ofstream(path("junk.glb")) << "glTF but not really";
    for (const char* file : {"missing.glb", "junk.glb"}) {
        o = run(exe() + " check " + q(path(file)));
        EXPECT_EQ(o.exit_code, 1) << file;
        EXPECT_EQ(test::line_count(o.err), 1u) << o.err;
        const json report = json::parse(o.out, nullptr, false);
        ASSERT_TRUE(report.is_object()) << file << ": " << o.out;
        EXPECT_FALSE(report["readable"].get<bool>()) << file;
        EXPECT_FALSE(report["ok"].get<bool>()) << file;
        EXPECT_EQ(report["errors"].size(), 1u) << file;
    }
    for (const char* optimised : {"plain.gltf", "corrupt.gltf"}) {
        o = run(exe() + " reapply " + q(path(optimised)) + " " + q(example) + " -o " + q(path("out.glb")));
        EXPECT_EQ(o.exit_code, 1);
        EXPECT_EQ(test::line_count(o.err), 1u) << o.err;
        EXPECT_FALSE(fs::exists(path("out.glb")));
    }
    o = run(exe() + " evaluate -q --methods original --stored " + q(path("corrupt.gltf")));
    EXPECT_EQ(o.exit_code, 1);
    EXPECT_EQ(test::line_count(o.err), 1u) << o.err;
    // Mismatched meshes: the example's quad is not the bundled character.
    ASSERT_EQ(run(exe() + " subdivide -q --levels 0 -o " + q(path("character.glb"))).exit_code, 0);
    o = run(exe() + " reapply " + q(example) + " " + q(path("character.glb")) + " -o " + q(path("out.glb")));
    EXPECT_EQ(o.exit_code, 1);
    EXPECT_NE(o.err.find("nothing written"), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(path("out.glb")));
    // The same quad posed 0.6% larger, as a resampled or quantised animation leaves a mesh: its
    // corners move 0.3% to 0.6% of the diagonal, the default tolerance (0.1%) finds none of its
    // triangles, and the error says which tolerance finds them all.
    json moved = json::parse(test::slurp(example));
    moved["nodes"][0]["scale"] = {1.006, 1.006, 1.006};
    std::ofstream(path("moved.gltf")) << moved.dump();
    o = run(exe() + " reapply -q " + q(example) + " " + q(path("moved.gltf")) + " -o " + q(path("out.glb")));
    EXPECT_EQ(o.exit_code, 1);
    EXPECT_NE(o.err.find("only 0 of 2 optimised triangles found within --tolerance 0.001"), std::string::npos) << o.err;
    EXPECT_NE(o.err.find("all are found at --tolerance 0.01 (the posed corners moved"), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(path("out.glb")));
    o = run(exe() + " reapply -q --tolerance 0.01 " + q(example) + " " + q(path("moved.gltf")) + " -o " +
            q(path("out.glb")));
    EXPECT_EQ(o.exit_code, 0) << o.err;
}

// A pipeline may drop, reorder or rename animations: reapply finds each clip's animation by name in
// the processed file (it copied the optimised file's index, which then named another animation, or
// none), and refuses a file that lost a clip's animation.
// The triangles of every primitive of a .gltf (buffers in files or data URIs), each rotated to start at
// its smallest index (its winding kept), sorted: equal for two files that draw the same triangles
// with the same winding, whatever their order.
std::vector<std::array<uint32_t, 4>> triangles_as_written(const fs::path& gltf) {
    const json g = json::parse(test::slurp(gltf));
    std::vector<std::array<uint32_t, 4>> out;
    for (size_t m = 0; m < g["meshes"].size(); ++m)
        for (const json& prim : g["meshes"][m]["primitives"]) {
            const json& a = g["accessors"][prim["indices"].get<size_t>()];
            const json& view = g["bufferViews"][a["bufferView"].get<size_t>()];
            const std::string uri = g["buffers"][view["buffer"].get<size_t>()]["uri"].get<std::string>();
            const std::string bytes = uri.rfind("data:", 0) == 0 ? test::base64_decode(uri.substr(uri.find(',') + 1))
                                                                 : test::slurp(gltf.parent_path() / uri);
            const size_t size = a["componentType"] == 5125 ? 4 : 2;
            const size_t at = view.value("byteOffset", size_t(0)) + a.value("byteOffset", size_t(0));
            std::vector<uint32_t> v(a["count"].get<size_t>());
            if (at + v.size() * size > bytes.size()) {
                ADD_FAILURE() << gltf << ": an index accessor runs past its buffer";
                return {};
            }
            for (size_t i = 0; i < v.size(); ++i) {
                uint32_t x = 0;
                std::memcpy(&x, bytes.data() + at + i * size, size);
                v[i] = x;
            }
            for (size_t t = 0; t + 2 < v.size(); t += 3) {
                const size_t r = v[t] <= std::min(v[t + 1], v[t + 2]) ? 0 : v[t + 1] <= v[t + 2] ? 1 : 2;
                out.push_back({uint32_t(m), v[t + r], v[t + (r + 1) % 3], v[t + (r + 2) % 3]});
            }
        }
    std::sort(out.begin(), out.end());
    return out;
}

// A character under a mirroring node (scale −1 in x: its file's front faces are clockwise, and the
// loader flips them for the rasteriser) comes out with its triangles as the file has them: the
// fallback's triangles are the input's, each with its winding; `check` and the validator pass it;
// after gltfpack (which bakes the mirror into the positions and flips the indices) `reapply` writes
// orders `check` accepts, with the optimised file's stored OVR.
TEST_F(GltfPipelines, AMirroredCharacterKeepsItsFilesWindingThroughOptimizeAndReapply) {
    std::string why;
    ANIMORDER_REQUIRE_OR_SKIP("gltf-tools", tools_present(why), why);
    ANIMORDER_REQUIRE_OR_SKIP("validator", test::validator_available(why), why);
    test::Outcome o = run(exe() + " subdivide -q --levels 0 -o " + q(path("character.gltf")));
    ASSERT_EQ(o.exit_code, 0) << o.err;
    json g = json::parse(test::slurp(path("character.gltf")));
    const size_t scene = g.value("scene", 0);
    g["nodes"].push_back({{"name", "mirror"}, {"scale", {-1, 1, 1}}, {"children", g["scenes"][scene]["nodes"]}});
    g["scenes"][scene]["nodes"] = json::array({g["nodes"].size() - 1});
    std::ofstream(path("mirrored.gltf")) << g.dump();
    o = run(exe() + " inspect --json " + q(path("mirrored.gltf")));
    ASSERT_EQ(o.exit_code, 0) << o.err;
    for (const json& p : json::parse(o.out)["primitives"]) EXPECT_TRUE(p["mirrored"].get<bool>()) << p;

    const fs::path optimised = path("mirrored-optimised.gltf");
    o = run(exe() + " optimize -q --method single -k 3 --views 12 --resolution 64 --max-iterations 3 " +
            q(path("mirrored.gltf")) + " -o " + q(optimised));
    ASSERT_EQ(o.exit_code, 0) << o.err;
    const auto input_triangles = triangles_as_written(path("mirrored.gltf"));
    EXPECT_EQ(input_triangles.size(), 11760u);
    EXPECT_TRUE(triangles_as_written(optimised) == input_triangles);
    EXPECT_EQ(check(optimised), 0);
    expect_valid(optimised);
    const fs::path pack = path("mirrored-gltfpack.glb"), repaired = path("mirrored-reapplied.glb");
    o = run("gltfpack -i " + q(optimised) + " -o " + q(pack));
    ASSERT_EQ(o.exit_code, 0) << o.out << o.err;
    o = run(exe() + " reapply " + q(optimised) + " " + q(pack) + " -o " + q(repaired));
    ASSERT_EQ(o.exit_code, 0) << o.err;
    EXPECT_EQ(check(repaired), 0);
    EXPECT_NEAR(stored_ovr(repaired), stored_ovr(optimised), 1e-3);
}

// Animations that share a name (Mixamo exports name every one "mixamo.com") are compared clip by
// clip, each with the animation of its own index: reapply matched every clip against every other of
// that name and found no triangle ("only 0 of ... found").
TEST_F(GltfPipelines, ReapplyPairsClipsOfOneNameByTheirAnimation) {
    std::string why;
    ANIMORDER_REQUIRE_OR_SKIP("gltf-tools", tools_present(why), why);
    json g = bundled_character();
    ASSERT_GE(g["animations"].size(), 2u);
    for (json& a : g["animations"]) a["name"] = "mixamo.com";
    optimise_pack_reapply(g, "same-names");
}

// A character drawn twice (a second node with its mesh: instances) keeps one order per buffer
// through gltfpack, which keeps the instancing: reapply writes the shared primitive once (it was
// refused: "reapply needs one node per mesh"), and `check` passes it.
TEST_F(GltfPipelines, ReapplyWritesAnInstancedMeshOnce) {
    std::string why;
    ANIMORDER_REQUIRE_OR_SKIP("gltf-tools", tools_present(why), why);
    json g = bundled_character();
    const size_t scene = g.value("scene", 0);
    size_t mesh_node = 0;
    while (!g["nodes"][mesh_node].contains("mesh")) ++mesh_node;
    json twin = g["nodes"][mesh_node];
    twin["translation"] = {2, 0, 0};
    g["nodes"].push_back(twin);
    g["scenes"][scene]["nodes"].push_back(g["nodes"].size() - 1);
    optimise_pack_reapply(g, "twins");
}

// A processed copy that dropped one of two animations of a shared name: which lookup table follows
// which animation cannot be told, and reapply says so in one line and writes nothing (it attached
// the first clip's table to the other animation, which `check` then refused).
TEST_F(GltfPipelines, ReapplyRefusesCopiesThatDroppedAnAnimationOfASharedName) {
    json g = bundled_character();
    ASSERT_GE(g["animations"].size(), 2u);
    for (json& a : g["animations"]) a["name"] = "mixamo.com";
    std::ofstream(path("same-names.gltf")) << g.dump();
    test::Outcome o = run(exe() + " optimize -q --method single -k 2 --views 12 --resolution 64 --max-iterations 2 " +
                          q(path("same-names.gltf")) + " -o " + q(path("optimised.gltf")));
    ASSERT_EQ(o.exit_code, 0) << o.err;
    json processed = json::parse(test::slurp(path("same-names.gltf")));
    processed["animations"].erase(0);
    std::ofstream(path("dropped.gltf")) << processed.dump();
    o = run(exe() + " reapply -q " + q(path("optimised.gltf")) + " " + q(path("dropped.gltf")) + " -o " +
            q(path("dropped-reapplied.gltf")));
    EXPECT_EQ(o.exit_code, 1);
    EXPECT_EQ(test::line_count(o.err), 1u) << o.err;
    EXPECT_NE(o.err.find("cannot be told"), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(path("dropped-reapplied.gltf")));
}

TEST_F(GltfPipelines, ReapplyFollowsEachClipsAnimationByName) {
    const fs::path example = kSource / "docs" / "extension" / "example.gltf";
    json g = json::parse(test::slurp(example));
    ASSERT_EQ(g["extensions"]["ANIMORDER_animated_triangle_orders"]["clips"][0]["animation"], 0);
    g.erase("extensions");
    g.erase("extensionsUsed");
    json other = g["animations"][0];
    other["name"] = "other";
    json shifted = g;
    shifted["animations"] = json::array({other, g["animations"][0]});  // "still" is now animation 1
    std::ofstream(path("shifted.gltf")) << shifted.dump();
    test::Outcome o =
        run(exe() + " reapply -q " + q(example) + " " + q(path("shifted.gltf")) + " -o " + q(path("shifted-out.gltf")));
    ASSERT_EQ(o.exit_code, 0) << o.err;
    const json out = json::parse(test::slurp(path("shifted-out.gltf")));
    EXPECT_EQ(out["extensions"]["ANIMORDER_animated_triangle_orders"]["clips"][0]["animation"], 1);
    EXPECT_EQ(run(exe() + " check " + q(path("shifted-out.gltf"))).exit_code, 0);

    json renamed = g;
    renamed["animations"][0]["name"] = "renamed";
    std::ofstream(path("renamed.gltf")) << renamed.dump();
    o = run(exe() + " reapply -q " + q(example) + " " + q(path("renamed.gltf")) + " -o " + q(path("renamed-out.gltf")));
    EXPECT_EQ(o.exit_code, 1);
    EXPECT_EQ(test::line_count(o.err), 1u) << o.err;
    EXPECT_NE(o.err.find("no animation 'still'"), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(path("renamed-out.gltf")));
}

// A processed primitive that matches no optimised triangle (here a copy of the example's primitive:
// the first copy matched every triangle) is written in its own order; reapply says so on stdout
// and stderr instead of leaving it unordered in silence.
TEST_F(GltfPipelines, ReapplySaysWhichPrimitivesItLeftWithoutOrders) {
    const fs::path example = kSource / "docs" / "extension" / "example.gltf";
    json g = json::parse(test::slurp(example));
    g.erase("extensions");
    g.erase("extensionsUsed");
    json& primitives = g["meshes"][0]["primitives"];
    ASSERT_EQ(primitives.size(), 1u);
    primitives[0].erase("extensions");
    primitives.push_back(primitives[0]);
    std::ofstream(path("twice.gltf")) << g.dump();
    test::Outcome o =
        run(exe() + " reapply " + q(example) + " " + q(path("twice.gltf")) + " -o " + q(path("twice-out.gltf")));
    ASSERT_EQ(o.exit_code, 0) << o.err;
    EXPECT_NE(o.out.find("1 primitive(s), 1 without orders"), std::string::npos) << o.out;
    EXPECT_NE(o.err.find("written without orders"), std::string::npos) << o.err;
    const json out = json::parse(test::slurp(path("twice-out.gltf")));
    EXPECT_TRUE(out["meshes"][0]["primitives"][0].contains("extensions"));
    EXPECT_FALSE(out["meshes"][0]["primitives"][1].contains("extensions"));
    // check says so too (it listed only the primitives with orders): usable, and which draw as stored.
    const test::Outcome checked = run(exe() + " check " + q(path("twice-out.gltf")));
    EXPECT_EQ(checked.exit_code, 0);
    const json report = json::parse(checked.out);
    ASSERT_EQ(report["primitives_without_orders"].size(), 1u) << report;
    EXPECT_EQ(report["primitives_without_orders"][0]["primitive"], 1);
    EXPECT_EQ(report["primitives_without_orders"][0]["triangles"], report["primitives"][0]["triangles"]);
    EXPECT_NE(checked.err.find("1 triangle primitive(s)"), std::string::npos) << checked.err;
    o = run(exe() + " reapply -q " + q(example) + " " + q(path("twice.gltf")) + " -o " + q(path("quiet.gltf")));
    EXPECT_EQ(o.err, "");
    EXPECT_NE(o.out.find("1 without orders"), std::string::npos) << o.out;
}

// reapply onto its own output replaces the orders it wrote (and the processed file's indices the
// first time): the same file, byte for byte, from the second run on, and no bigger than the first.
TEST_F(GltfPipelines, ReapplyingTwiceGivesTheSameFile) {
    const fs::path example = kSource / "docs" / "extension" / "example.gltf";
    json g = json::parse(test::slurp(example));
    g.erase("extensions");
    g.erase("extensionsUsed");
    for (json& prim : g["meshes"][0]["primitives"]) prim.erase("extensions");
    std::ofstream(path("bare.gltf")) << g.dump();
    fs::path processed = path("bare.gltf");
    std::vector<std::string> outputs;
    for (int run_index = 1; run_index <= 3; ++run_index) {
        const fs::path out = path("again" + std::to_string(run_index) + ".glb");
        const test::Outcome o = run(exe() + " reapply -q " + q(example) + " " + q(processed) + " -o " + q(out));
        ASSERT_EQ(o.exit_code, 0) << o.err;
        EXPECT_EQ(run(exe() + " check " + q(out)).exit_code, 0);
        outputs.push_back(test::slurp(out));
        processed = out;
    }
    EXPECT_EQ(outputs[1], outputs[2]);
    EXPECT_EQ(outputs[1].size(), outputs[0].size());
}

// RobotExpressive has three triangles with a repeated vertex (they draw nothing), which gltfpack
// drops: reapply takes the packed file (it refused it, "only 3234 of 3237 optimised triangles
// found"), its orders skip those three, and check accepts the result.
TEST_F(GltfPipelines, ReapplyAcceptsAPipelineThatDroppedDegenerateTriangles) {
    std::string why;
    const fs::path input = test::shared_data_path("glb-robot-expressive/RobotExpressive.glb");
    ANIMORDER_REQUIRE_DATA(input);
    ANIMORDER_REQUIRE_OR_SKIP("gltf-tools", on_path("gltfpack"), "gltfpack is not on PATH (Debian package gltfpack)");
    test::Outcome o = run(exe() + " optimize -q " + q(input) +
                          " --views 12 --resolution 64 -k 2 --max-iterations 2 -o " + q(path("robot.glb")));
    ASSERT_EQ(o.exit_code, 0) << o.err;
    ASSERT_EQ(run("gltfpack -noq -i " + q(path("robot.glb")) + " -o " + q(path("packed.glb"))).exit_code, 0);
    o = run(exe() + " reapply -q " + q(path("robot.glb")) + " " + q(path("packed.glb")) + " -o " +
            q(path("reapplied.glb")));
    ASSERT_EQ(o.exit_code, 0) << o.err;
    EXPECT_NE(o.out.find("3234 of 3237 triangles matched"), std::string::npos) << o.out;
    o = run(exe() + " check " + q(path("reapplied.glb")));
    EXPECT_EQ(o.exit_code, 0) << o.out << o.err;
}
