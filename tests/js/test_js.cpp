// The JavaScript side, run from CTest: the JS runtime against the C runtime on one optimised file
// (js/test/equivalence.mjs), and the viewer in headless Chromium (viewer/test/browser.mjs).
// Prerequisites through the requirement switch: "node" (node on the PATH) and "browser" (Debian's
// chromium and viewer/node_modules from scripts/install-deps.sh).
#include "support/files.h"
#include "support/require.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
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
    run_browser_test(*this, dir_, "", shot, 10);
    const char* keep = std::getenv("ANIMORDER_VIEWER_SCREENSHOT");
    if (keep && *keep && fs::exists(shot)) {
        fs::copy_file(shot, keep, fs::copy_options::overwrite_existing);
        std::cout << "screenshot copied to " << keep << "\n";
    }
}

// A skinned character (CesiumMan: SkinnedMesh, node transforms, a texture) of ../shared/data.
TEST_F(JsTest, SkinnedViewerInHeadlessChromium) {
    std::string why;
    ANIMORDER_REQUIRE_OR_SKIP("browser", have_browser(why), why);
    const fs::path cesium = test::shared_data_path("gltf-cesiumman/CesiumMan.glb");
    ANIMORDER_REQUIRE_DATA(cesium);
    const test::Outcome o = run(std::string(ANIMORDER_EXE) + " optimize -q " + sh(cesium) +
                                " --method single -k 3 --views 42 --resolution 64 -o " + sh(path("cesium.glb")));
    ASSERT_EQ(o.exit_code, 0) << o.err;
    run_browser_test(*this, dir_,
                     " --model cesium.glb --sidecar cesium.animorder.bin --input " + sh(cesium) + " --expect-skinned 1",
                     path("cesium.png"), 11);
}

// `animorder view`: the viewer's files and the model only, GET/HEAD only, nothing above its folders.
TEST_F(JsTest, ViewServesOnlyTheViewer) {
    std::string why;
    ANIMORDER_REQUIRE_OR_SKIP("node", have_node(why), why);
    const fs::path three = fs::path(source_dir) / "viewer" / "node_modules" / "three";
    ANIMORDER_REQUIRE_OR_SKIP("browser", fs::exists(three),
                              three.string() + " is absent (run scripts/install-deps.sh)");
    const test::Outcome a = run(std::string(ANIMORDER_EXE) + " subdivide -q --levels 0 -o " + sh(path("char.glb")));
    ASSERT_EQ(a.exit_code, 0) << a.err;
    const test::Outcome o = run("node " + sh(source_dir + "/viewer/test/server.mjs") + " " + sh(ANIMORDER_EXE) + " " +
                                sh(path("char.glb")));
    EXPECT_EQ(o.exit_code, 0) << o.out << o.err;
    EXPECT_EQ(test::line_count(o.out), 20u) << o.out;
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
