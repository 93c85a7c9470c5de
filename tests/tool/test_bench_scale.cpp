// bench_scale --baseline end to end, on its smoke settings (--quick): a build compared with itself
// writes the same buffers (the single-sided Xbot copy included) and leaves nothing in the temporary
// folder; a baseline that fails, and bad options, give exit code 1 and a line saying why.
#include <gtest/gtest.h>

#include "support/files.h"
#include "support/require.h"

#include <filesystem>
#include <string>

namespace fs = std::filesystem;
namespace test = animorder::test;

namespace {

const fs::path kData = fs::path(ANIMORDER_SOURCE_DIR).parent_path() / "shared" / "data";

class BenchScale : public test::ScratchFolderTest {
protected:
    BenchScale() : ScratchFolderTest("animorder-bench-scale") {}
    // bench_scale with the test's folder as its temporary folder and ../shared/data as its data.
    test::Outcome run(const std::string& args) {
        fs::create_directories(path("tmp"));
        return test::run_captured(
            "TMPDIR=" + path("tmp").string() + " ANIMORDER_DATA=" + kData.string() + " " + BENCH_SCALE_EXE + " " + args,
            dir_);
    }
    size_t count(const std::string& text, const std::string& what) {
        size_t n = 0;
        for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
        return n;
    }
};

}  // namespace

TEST_F(BenchScale, ABuildAgainstItselfWritesTheSameBuffers) {
    ANIMORDER_REQUIRE_OR_SKIP("data", fs::exists(kData / "glb-xbot" / "Xbot.glb"),
                              (kData / "glb-xbot" / "Xbot.glb").string() + " is absent");
    const test::Outcome o =
        run(std::string("--quick --baseline ") + ANIMORDER_EXE + " --rounds 2 xbot-single-sided clip60-single");
    ASSERT_EQ(o.exit_code, 0) << o.out << o.err;
    EXPECT_EQ(count(o.out, "this build  wall"), 2u) << o.out;
    EXPECT_EQ(count(o.out, "baseline    wall"), 2u) << o.out;
    EXPECT_EQ(count(o.out, "(fastest of 2; "), 4u) << o.out;
    EXPECT_EQ(count(o.out, "buffers identical"), 2u) << o.out;
    EXPECT_NE(o.out.find("xbot-single-sided speed-up "), std::string::npos) << o.out;
    EXPECT_NE(o.out.find("(the goal asks 2.75x: 33 s -> 12.0 s)"), std::string::npos) << o.out;
    EXPECT_TRUE(fs::is_empty(path("tmp"))) << "bench_scale left its scratch folders behind";
}

TEST_F(BenchScale, TheSingleSidedCopyLoadsAsTheSameCharacter) {
    // The rewritten GLB (only its materials' doubleSided changed) is a valid file of the same
    // character: the same triangles, clips, keyframes and nodes as the file it came from. That it
    // is the workload shows in bench-baseline.txt: the same buffers as the engine.
    ANIMORDER_REQUIRE_OR_SKIP("data", fs::exists(kData / "glb-xbot" / "Xbot.glb"),
                              (kData / "glb-xbot" / "Xbot.glb").string() + " is absent");
    const test::Outcome o = run("--quick xbot-single xbot-single-sided");
    ASSERT_EQ(o.exit_code, 0) << o.out << o.err;
    const size_t original = o.out.find("xbot-single        "), copy = o.out.find("xbot-single-sided  ");
    ASSERT_NE(original, std::string::npos) << o.out;
    ASSERT_NE(copy, std::string::npos) << o.out;
    const auto counts = [&o](size_t at) {  // "N triangles N clips N keyframes N nodes"
        const size_t from = o.out.find_first_of("0123456789", at);
        return o.out.substr(from, o.out.find("nodes", from) - from);
    };
    EXPECT_EQ(counts(original), counts(copy)) << o.out;
    EXPECT_NE(counts(copy).find("49112 triangles"), std::string::npos) << o.out;
    EXPECT_EQ(o.out.find("failed"), std::string::npos) << o.out;
    EXPECT_TRUE(fs::is_empty(path("tmp")));
}

TEST_F(BenchScale, AFailingBaselineIsReported) {
    ANIMORDER_REQUIRE_OR_SKIP("data", fs::exists(kData / "mixamo-ganfaul" / "Ganfaul.gltf"),
                              (kData / "mixamo-ganfaul" / "Ganfaul.gltf").string() + " is absent");
    const test::Outcome o = run("--quick --baseline /bin/false clip60-single");
    EXPECT_EQ(o.exit_code, 1) << o.out;
    EXPECT_NE(o.out.find("clip60-single     baseline    failed"), std::string::npos) << o.out;
    EXPECT_EQ(o.out.find("speed-up"), std::string::npos) << o.out;
    EXPECT_TRUE(fs::is_empty(path("tmp")));
}

TEST_F(BenchScale, BadOptionsAreRefused) {
    const test::Outcome missing = run("--baseline " + path("no-such-animorder").string() + " clip60-single");
    EXPECT_EQ(missing.exit_code, 1);
    EXPECT_NE(missing.err.find("--baseline needs another build's animorder executable"), std::string::npos)
        << missing.err;
    for (const std::string rounds : {"0", "101", "2x", ""}) {
        const test::Outcome o = run(std::string("--baseline ") + ANIMORDER_EXE + " clip60-single --rounds " + rounds);
        EXPECT_EQ(o.exit_code, 1) << rounds;
        EXPECT_NE(o.err.find("--rounds needs a count from 1 to 100"), std::string::npos) << rounds << ": " << o.err;
    }
    const test::Outcome unknown = run("no-such-case");
    EXPECT_EQ(unknown.exit_code, 1);
    EXPECT_NE(unknown.err.find("unknown case 'no-such-case'"), std::string::npos) << unknown.err;
}
