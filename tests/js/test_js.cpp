// The JavaScript side, run from CTest: the JS runtime against the C runtime on one optimised file
// (js/test/equivalence.mjs), and the viewer in headless Chromium (viewer/test/browser.mjs).
// Prerequisites through the requirement switch: "node" (node on the PATH) and "browser" (Debian's
// chromium and viewer/node_modules from scripts/install-deps.sh).
#include "support/files.h"
#include "support/require.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

namespace fs = std::filesystem;
using namespace animorder;

namespace {

const std::string source_dir = ANIMORDER_SOURCE_DIR;

std::string sh(const fs::path& p) { return "'" + p.string() + "'"; }

bool have_node(std::string& why) {
    if (std::system("node --version >/dev/null 2>&1") == 0) return true;
    why = "node is not on the PATH (scripts/install-deps.sh installs it)";
    return false;
}

class JsTest : public test::ScratchFolderTest {
protected:
    JsTest() : ScratchFolderTest("animorder-js") {}
    test::Outcome run(const std::string& command) { return test::run_captured(command, dir_); }

    // Runs a node script of the repository that checks on its own and expects its closing line.
    void expect_script_passes(const std::string& script, const std::string& closing_line) {
        const test::Outcome o = run("node " + sh(source_dir + "/" + script));
        EXPECT_EQ(o.exit_code, 0) << o.out << o.err;
        EXPECT_NE(o.out.find(closing_line), std::string::npos) << o.out << o.err;
    }

    // The bundled character as a glTF (its clips as morph-weight animations), optimised with small
    // clustering settings (k = 3, 42 views at 64²: seconds, not the 25 s of the defaults).
    void optimise_character() {
        const test::Outcome a = run(std::string(ANIMORDER_EXE) + " subdivide -q --levels 0 -o " + sh(path("char.glb")));
        ASSERT_EQ(a.exit_code, 0) << a.err;
        const test::Outcome b = run(std::string(ANIMORDER_EXE) + " optimize -q " + sh(path("char.glb")) +
                                    " --method single -k 3 --views 42 --resolution 64 -o " + sh(path("out.glb")));
        ASSERT_EQ(b.exit_code, 0) << b.err;
    }
};

TEST_F(JsTest, RuntimeAnswersExactlyAsTheCRuntime) {
    std::string why;
    ANIMORDER_REQUIRE_OR_SKIP("node", have_node(why), why);
    optimise_character();
    if (HasFatalFailure()) return;
    // The same tables read from the sidecar and from the glb's ANIMORDER_animated_triangle_orders.
    const test::Outcome o = run("node " + sh(source_dir + "/js/test/equivalence.mjs") + " " + sh(RUNTIME_ANSWERS_EXE) +
                                " " + sh(path("out.animorder.bin")) + " " + sh(dir_) + " " + sh(path("out.glb")));
    EXPECT_EQ(o.exit_code, 0) << o.out << o.err;
    // Every answer identical (the script prints one line per source).
    EXPECT_NE(o.out.find("sidecar: 120000 of 120000 answers identical"), std::string::npos) << o.out << o.err;
    EXPECT_NE(o.out.find("glb extension: 120000 of 120000 answers identical"), std::string::npos) << o.out << o.err;
}

// Whether the browser test can run here; `why` says what is missing.
bool have_browser(std::string& why) {
    const fs::path modules = fs::path(source_dir) / "viewer" / "node_modules";
    if (!have_node(why)) return false;
    if (!fs::exists("/usr/bin/chromium")) {
        why = "/usr/bin/chromium is absent (Debian package chromium; scripts/install-deps.sh installs it)";
        return false;
    }
    if (!fs::exists(modules / "puppeteer-core") || !fs::exists(modules / "three")) {
        why = "three / puppeteer-core are not installed in " + modules.string() + " (run scripts/install-deps.sh)";
        return false;
    }
    return true;
}

// Runs viewer/test/browser.mjs with `files` (--model/--input/--sidecar...) and expects `checks`
// lines starting "ok" and none "FAIL".
void run_browser_test(JsTest& t, const fs::path& dir, const std::string& files, const fs::path& shot, size_t checks) {
    fs::create_directories(shot.parent_path());
    const test::Outcome o =
        test::run_captured("node " + sh(source_dir + "/viewer/test/browser.mjs") + " --animorder " + sh(ANIMORDER_EXE) +
                               " --answers " + sh(RUNTIME_ANSWERS_EXE) + " --node-counts " + sh(NODE_COUNTS_EXE) +
                               " --scratch " + sh(dir) + " --screenshot " + sh(shot) + files,
                           dir);
    (void)t;
    std::cout << o.out;
    EXPECT_EQ(o.exit_code, 0) << o.out << o.err;
    size_t ok = 0;
    for (size_t at = o.out.find("ok   "); at != std::string::npos; at = o.out.find("ok   ", at + 1)) ++ok;
    EXPECT_EQ(ok, checks) << o.out << o.err;
    EXPECT_EQ(o.out.find("FAIL"), std::string::npos) << o.out;
    EXPECT_GT(fs::exists(shot) ? fs::file_size(shot) : 0u, 10000u);
}

// The bundled character (morph-target animation, two primitives, two clips). The screenshot stays
// in the scratch folder like everything else the test writes (it went to build/viewer/); docs/
// viewer.png is a committed copy of it, taken anew where ANIMORDER_VIEWER_SCREENSHOT names a file
// to copy it to (docs/viewer.md): only then does the test write outside its folder.
TEST_F(JsTest, ViewerInHeadlessChromium) {
    std::string why;
    ANIMORDER_REQUIRE_OR_SKIP("browser", have_browser(why), why);
    optimise_character();
    if (HasFatalFailure()) return;
    const fs::path shot = path("screenshot.png");
    run_browser_test(*this, dir_, "", shot, 11);
    const char* keep = std::getenv("ANIMORDER_VIEWER_SCREENSHOT");
    if (keep && *keep && fs::exists(shot)) {
        fs::copy_file(shot, keep, fs::copy_options::overwrite_existing);
        std::cout << "screenshot copied to " << keep << "\n";
    }
}

// `glb` as a .gltf with its binary chunk in an external .bin and each embedded image in a file of
// its own under a subfolder, URIs percent-encoded (the way characters are often shared):
// NAME.gltf, NAME.bin and textures/image N.EXT in `folder`.
void write_external_gltf(const fs::path& glb, const fs::path& folder, const std::string& name) {
    const std::string bytes = test::slurp(glb);
    ASSERT_GT(bytes.size(), 28u);
    const auto u32 = [&](size_t at) {
        uint32_t v = 0;
        for (int i = 3; i >= 0; --i) v = v << 8 | uint8_t(bytes[at + size_t(i)]);
        return size_t(v);
    };
    const size_t json_length = u32(12);
    nlohmann::json j = nlohmann::json::parse(bytes.substr(20, json_length));
    const std::string bin = bytes.substr(20 + json_length + 8, u32(20 + json_length));
    fs::create_directories(folder / "textures");
    j["buffers"][0]["uri"] = name + ".bin";
    std::ofstream(folder / (name + ".bin"), std::ios::binary) << bin;
    for (size_t i = 0; i < j["images"].size(); ++i) {
        nlohmann::json& image = j["images"][i];
        const nlohmann::json& view = j["bufferViews"][image["bufferView"].get<size_t>()];
        const std::string file = "image " + std::to_string(i) + (image["mimeType"] == "image/png" ? ".png" : ".jpg");
        std::ofstream(folder / "textures" / file, std::ios::binary)
            << bin.substr(view.value("byteOffset", size_t(0)), view["byteLength"].get<size_t>());
        image.erase("bufferView");
        image["uri"] = "textures/image%20" + std::to_string(i) + file.substr(file.find('.'));
    }
    std::ofstream(folder / (name + ".gltf")) << j.dump();
}

// A skinned character (CesiumMan: SkinnedMesh, node transforms, a texture) of ../shared/data, as
// a .gltf with an external .bin and texture (written by write_external_gltf, under names with a
// space), optimised into another folder: its .glb names the texture at "../ext/textures/…". The
// page loads both files with their buffers and textures through `animorder view`.
TEST_F(JsTest, SkinnedViewerInHeadlessChromium) {
    std::string why;
    ANIMORDER_REQUIRE_OR_SKIP("browser", have_browser(why), why);
    const fs::path cesium = test::shared_data_path("gltf-cesiumman/CesiumMan.glb");
    ANIMORDER_REQUIRE_DATA(cesium);
    write_external_gltf(cesium, path("ext"), "Cesium Man");
    if (HasFatalFailure()) return;
    fs::create_directories(path("out"));
    const test::Outcome o = run(std::string(ANIMORDER_EXE) + " optimize -q " + sh(path("ext/Cesium Man.gltf")) +
                                " --method single -k 3 --views 42 --resolution 64 -o " + sh(path("out/cesium.glb")));
    ASSERT_EQ(o.exit_code, 0) << o.err;
    EXPECT_NE(test::slurp(path("out/cesium.glb")).find("../ext/textures/image%200.jpg"), std::string::npos);
    run_browser_test(*this, dir_,
                     " --model out/cesium.glb --sidecar out/cesium.animorder.bin --input " +
                         sh(path("ext/Cesium Man.gltf")) + " --expect-skinned 1 --expect-textured 1",
                     path("cesium.png"), 13);
}

// `animorder view`: the viewer's files, the model and the files it names from below its folder only,
// GET/HEAD only, nothing above its folders.
TEST_F(JsTest, ViewServesOnlyTheViewer) {
    std::string why;
    ANIMORDER_REQUIRE_OR_SKIP("node", have_node(why), why);
    const fs::path three = fs::path(source_dir) / "viewer" / "node_modules" / "three";
    ANIMORDER_REQUIRE_OR_SKIP("browser", fs::exists(three),
                              three.string() + " is absent (run scripts/install-deps.sh)");
    const test::Outcome a = run(std::string(ANIMORDER_EXE) + " subdivide -q --levels 0 -o " + sh(path("char.glb")));
    ASSERT_EQ(a.exit_code, 0) << a.err;
    const test::Outcome o = run("node " + sh(source_dir + "/viewer/test/server.mjs") + " " + sh(ANIMORDER_EXE) + " " +
                                sh(path("char.glb")) + " " + sh(dir_));
    EXPECT_EQ(o.exit_code, 0) << o.out << o.err;
    EXPECT_EQ(test::line_count(o.out), 33u) << o.out;
    EXPECT_EQ(o.out.find("FAIL"), std::string::npos) << o.out;
}

// The JS runtime on the extension's example file, against answers worked out by hand (and its
// refusals of broken tables): js/test/hand-worked.mjs.
TEST_F(JsTest, RuntimeHandWorkedOnTheSpecExample) {
    std::string why;
    ANIMORDER_REQUIRE_OR_SKIP("node", have_node(why), why);
    expect_script_passes("js/test/hand-worked.mjs", "hand-worked: all checks passed");
}

// The JS runtime on the shared corpus of hostile files (tests/extension-corpus/): the verdict of
// each as its manifest and `animorder check` give it, and the amplification files of amplify.mjs
// read once or refused by the work cap (js/test/corpus.mjs).
TEST_F(JsTest, RuntimeGivesTheCorpusVerdictsOfCheck) {
    std::string why;
    ANIMORDER_REQUIRE_OR_SKIP("node", have_node(why), why);
    expect_script_passes("js/test/corpus.mjs", "corpus: all checks passed");
}

// The three.js plugin in node with three.js's GLTFLoader on the extension's example, broken as a
// hostile file is (js/test/three-plugin.mjs): it refuses what the runtime refuses, with one clear
// line, and never draws a primitive without orders from another's.
bool have_three(std::string& why) {
    const fs::path three = fs::path(source_dir) / "viewer" / "node_modules" / "three";
    if (!have_node(why)) return false;
    if (fs::exists(three)) return true;
    why = "three is not installed in " + three.string() + " (run scripts/install-deps.sh)";
    return false;
}

TEST_F(JsTest, ThreePluginRefusesWhatTheRuntimeRefuses) {
    std::string why;
    ANIMORDER_REQUIRE_OR_SKIP("node", have_three(why), why);
    expect_script_passes("js/test/three-plugin.mjs", "three plugin: all checks passed");
}

}  // namespace
