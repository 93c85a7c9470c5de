// `animorder subdivide` end to end: exit codes, the counts it prints and writes, one-line errors
// for a bad level count or output, and never overwriting the input.
#include "animorder/animated_mesh.h"
#include "animorder/gltf_loader.h"
#include "animorder/procedural_character.h"

#include <gtest/gtest.h>

#include "support/files.h"

#include <sys/wait.h>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
namespace test = animorder::test;

namespace {

class SubdivideCli : public test::ScratchFolderTest {
protected:
    SubdivideCli() : ScratchFolderTest("animorder-subdivide-cli") {}
    test::Outcome run(const std::string& args) {
        return test::run_captured(std::string(ANIMORDER_EXE) + " " + args, dir_);
    }
};

}  // namespace

TEST_F(SubdivideCli, BundledCharacterOneLevelWritesTheCounts) {
    const test::Outcome o = run("subdivide --levels 1 --clip wave -o " + path("c1.glb").string());
    ASSERT_EQ(o.exit_code, 0) << o.err;
    EXPECT_NE(o.err.find("bundled procedural character"), std::string::npos) << o.err;
    EXPECT_NE(o.out.find("triangles 11760 -> 47040"), std::string::npos) << o.out;
    EXPECT_NE(o.out.find("MB"), std::string::npos) << o.out;
    // The file holds what was printed: 4x the triangles, only the kept clip.
    const animorder::AnimatedMesh back = animorder::load_gltf(path("c1.glb").string());
    EXPECT_EQ(back.triangle_count(), 47040u);
    ASSERT_EQ(back.clips.size(), 1u);
    EXPECT_EQ(back.clips[0].name, "wave");
    const animorder::AnimatedMesh original = animorder::make_procedural_character();
    for (const animorder::Clip& c : original.clips) {
        if (c.name == "wave") {
            EXPECT_EQ(back.keyframe_count(), c.keyframe_count);
        }
    }
}

TEST_F(SubdivideCli, TwoLevelsOfAGltfInputAndQuiet) {
    // A subdivided file is itself an input: subdivide it once more.
    ASSERT_EQ(run("subdivide -q --levels 1 --clip wave -o " + path("c1.gltf").string()).exit_code, 0);
    const test::Outcome o =
        run("subdivide --quiet " + path("c1.gltf").string() + " --levels 1 -o " + path("c2.glb").string());
    ASSERT_EQ(o.exit_code, 0) << o.err;
    EXPECT_EQ(o.err, "");
    EXPECT_NE(o.out.find("triangles 47040 -> 188160"), std::string::npos) << o.out;
}

TEST_F(SubdivideCli, TooManyLevelsIsAClearError) {
    const test::Outcome o = run("subdivide --levels 9 -o " + path("x.glb").string());
    EXPECT_NE(o.exit_code, 0);
    EXPECT_EQ(test::line_count(o.err), 1u) << o.err;
    EXPECT_NE(o.err.find("--levels 9"), std::string::npos) << o.err;
    EXPECT_NE(o.err.find("at most 4"), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(path("x.glb")));
}

TEST_F(SubdivideCli, RefusesToOverwriteTheInputAndOtherExtensions) {
    ASSERT_EQ(run("subdivide -q --levels 1 --clip wave -o " + path("in.glb").string()).exit_code, 0);
    const std::string before = test::slurp_existing(path("in.glb"));
    const test::Outcome same =
        run("subdivide -q " + path("in.glb").string() + " --levels 1 -o " + path("in.glb").string());
    EXPECT_NE(same.exit_code, 0);
    EXPECT_NE(same.err.find("refusing to overwrite the input"), std::string::npos) << same.err;
    EXPECT_EQ(test::slurp_existing(path("in.glb")), before);
    const test::Outcome obj = run("subdivide -q --levels 1 -o " + path("x.obj").string());
    EXPECT_NE(obj.exit_code, 0);
    EXPECT_NE(obj.err.find(".glb or .gltf"), std::string::npos) << obj.err;
    const test::Outcome missing = run("subdivide -q --levels 1");
    EXPECT_NE(missing.exit_code, 0);
}
