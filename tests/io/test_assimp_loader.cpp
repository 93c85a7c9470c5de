// The assimp loader on every non-glTF character of ../shared/data (skipped with a message when
// the folder is absent): triangle counts of shared/data/README.md, Mixamo clip folders matched by
// joint name, skin that stretches without tearing, and one-line errors.
#include "animorder/animated_mesh.h"
#include "animorder/assimp_loader.h"
#include "animorder/load.h"

#include "support/files.h"
#include "support/gltf_builder.h"
#include "support/load_error.h"
#include "support/meshes.h"
#include "support/require.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <tuple>

using namespace animorder;
namespace fs = std::filesystem;

namespace {
const std::string kData = std::string(ANIMORDER_SOURCE_DIR) + "/../shared/data/";

// Median over a clip's keyframes of edge length / edge length at its first keyframe.
double median_stretch(const AnimatedMesh& m, const Clip& c) {
    std::vector<double> ratios;
    const size_t step = std::max<size_t>(1, c.keyframe_count / 6);
    for (size_t f = step; f < c.keyframe_count; f += step) {
        const std::vector<double> r = test::edge_stretch(m, c.first_keyframe, c.first_keyframe + f);
        ratios.insert(ratios.end(), r.begin(), r.end());
    }
    return ratios.empty() ? 1.0 : test::median(ratios);
}
}  // namespace

TEST(AssimpCharacters, EveryCharacterInSharedDataLoadsWithItsClips) {
    ANIMORDER_REQUIRE_DATA(kData);
    struct Case {
        const char* file;
        const char* clips;  // folder of Mixamo-style clip files, or ""
        size_t triangles;
        size_t min_clips;
    };
    const Case cases[] = {{"pg-barbarian/model.fbx", "pg-barbarian/anims", 6520, 11},
                          {"pg-goblin/model.fbx", "pg-goblin/anims", 7820, 5},
                          {"pg-witch/model.fbx", "pg-witch/anims", 7592, 7},
                          {"x-wuson/Testwuson.X", "", 3732, 3},
                          {"x-dwarf/dwarf.x", "", 1896, 1},
                          {"b3d-dwarf2/dwarf2.b3d", "", 1896, 1},
                          {"md5-bob/Bob.md5mesh", "", 1027, 1},
                          {"x-bcn-epileptic/BCN_Epileptic.X", "", 5126, 1},
                          {"iqm-mrfixit/mrfixit.iqm", "", 2988, 1},  // own reader: skeletal idle of 101 frames
                          {"md2-dolphin/dolphin.md2", "", 500, 1},
                          {"md2-sydney/sydney.md2", "", 679, 16},
                          {"md2-faerie/faerie.md2", "", 654, 16}};
    animorder::test::DataFiles data;  // every character is checked; the missing ones are named at the end
    for (const Case& c : cases) {
        SCOPED_TRACE(c.file);
        bool present = data.present(kData + c.file);
        if (*c.clips) present = data.present(kData + c.clips) && present;
        if (!present) continue;
        std::vector<std::string> clips;
        if (*c.clips) clips.push_back(kData + c.clips);
        AnimatedMesh m;
        ASSERT_NO_THROW(m = load_character(kData + c.file, clips));
        EXPECT_EQ(m.triangle_count(), c.triangles);
        EXPECT_GE(m.clips.size(), c.min_clips);
        EXPECT_NO_THROW(validate_animated_mesh(m));
        for (const Clip& clip : m.clips)
            if ((m.joint_count > 0 || m.vertex_count == 324 /* dolphin */) && clip.keyframe_count > 2) {
                EXPECT_NEAR(median_stretch(m, clip), 1.0, 0.03) << clip.name;
            }
        std::printf("%-34s %5zu triangles %3zu joints %2zu clips %4zu keyframes\n", c.file, m.triangle_count(),
                    m.joint_count, m.clips.size(), m.keyframe_count());
    }
    ANIMORDER_REQUIRE_ALL_DATA(data);
}

TEST(Md2, EveryFrameIsAKeyframeAndFrontsFaceOut) {
    const std::string path = kData + "md2-sydney/sydney.md2";
    ANIMORDER_REQUIRE_DATA(path);
    const AnimatedMesh m = load_character(path);
    // 198 frames in 16 groups at 10 frames per second, resampled at 30: 3·(n − 1) + 1 per group.
    size_t frames = 0;
    for (const Clip& c : m.clips) frames += (c.keyframe_count - 1) / 3 + 1;
    EXPECT_EQ(frames, 198u);
    EXPECT_EQ(m.clips[0].name, "stand");
    // Counter-clockwise fronts: a closed-ish body has positive signed volume at every keyframe.
    for (size_t k = 0; k < m.keyframe_count(); k += 17) {
        double volume = 0;
        const float* p = m.keyframe(k);
        for (size_t t = 0; t < m.indices.size(); t += 3) {
            const float *a = p + 3 * m.indices[t], *b = p + 3 * m.indices[t + 1], *c = p + 3 * m.indices[t + 2];
            volume += (double(a[0]) * (double(b[1]) * c[2] - double(b[2]) * c[1]) -
                       double(a[1]) * (double(b[0]) * c[2] - double(b[2]) * c[0]) +
                       double(a[2]) * (double(b[0]) * c[1] - double(b[1]) * c[0])) /
                      6.0;
        }
        EXPECT_GT(volume, 0.0) << "keyframe " << k;
    }
    // Truncated copies are refused with the file's name.
    const fs::path cut = fs::temp_directory_path() / ("animorder-md2-" + std::to_string(::getpid()) + ".md2");
    std::ifstream in(path, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
    EXPECT_THROW(load_character(cut.string()), LoadError);
    fs::remove(cut);
}

TEST(Iqm, SkeletalAnimationMovesAndFrontsFaceOut) {
    const std::string path = kData + "iqm-mrfixit/mrfixit.iqm";
    ANIMORDER_REQUIRE_DATA(path);
    const AnimatedMesh m = load_character(path);
    ASSERT_EQ(m.clips.size(), 1u);
    EXPECT_EQ(m.joint_count, 75u);
    EXPECT_GT(m.keyframe_count(), 50u);
    // Real motion, no tearing.
    const Clip& c = m.clips[0];
    const std::vector<double> r = test::edge_stretch(m, c.first_keyframe, c.first_keyframe + c.keyframe_count / 2);
    EXPECT_NEAR(test::median(r), 1.0, 0.03);
    double moved = 0;
    for (size_t i = 0; i < m.vertex_count * 3; ++i)
        moved = std::max(moved, double(std::fabs(m.keyframe(c.keyframe_count / 2)[i] - m.keyframe(0)[i])));
    EXPECT_GT(moved, 0.01);
    double volume = 0;
    const float* p = m.keyframe(0);
    for (size_t t = 0; t < m.indices.size(); t += 3) {
        const float *a = p + 3 * m.indices[t], *b = p + 3 * m.indices[t + 1], *d = p + 3 * m.indices[t + 2];
        volume += (double(a[0]) * (double(b[1]) * d[2] - double(b[2]) * d[1]) -
                   double(a[1]) * (double(b[0]) * d[2] - double(b[2]) * d[0]) +
                   double(a[2]) * (double(b[0]) * d[1] - double(b[1]) * d[0])) /
                  6.0;
    }
    EXPECT_GT(volume, 0.0);
}

TEST(AssimpCharacters, ClipFilesOfAnotherSkeletonAreRefused) {
    ANIMORDER_REQUIRE_DATA(kData);
    try {
        load_character(kData + "pg-barbarian/model.fbx", {kData + "x-dwarf/dwarf.x"});
        FAIL() << "no error";
    } catch (const LoadError& e) {
        EXPECT_NE(std::string(e.what()).find("is a joint of"), std::string::npos) << e.what();
    }
}

TEST(AssimpLoader, BrokenFilesGiveOneLineErrors) {
    const fs::path dir = fs::temp_directory_path() / ("animorder-assimp-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path junk = dir / "junk.fbx";
    std::ofstream(junk) << "Kaydara FBX Binary  \x00\x1a\x00 truncated";
    for (const fs::path& p : {junk, dir / "missing.x"}) {
        try {
            load_character(p.string());
            ADD_FAILURE() << p << ": no error";
        } catch (const LoadError& e) {
            const std::string what = e.what();
            EXPECT_EQ(what.rfind(p.string(), 0), 0u) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        }
    }
    fs::remove_all(dir);
}

// --- Hostile files: crafted reproducers of crashes inside Debian's libassimp 5.2.5 ---------------

namespace {

class AssimpHostile : public test::ScratchFolderTest {
protected:
    AssimpHostile() : ScratchFolderTest("animorder-assimp-hostile") {}
    std::string write(const std::string& name, const std::string& text) const {
        std::ofstream(path(name), std::ios::binary) << text;
        return path(name).string();
    }
};

const char* const kIdentity = "1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0;;";

// A text .X mesh of one triangle (0,0,0) (1,0,0) (0,1,0); `faces` and `extra` replace its face
// list and add templates inside the mesh.
std::string x_mesh(const std::string& faces = "3;0,1,2;;", const std::string& extra = "") {
    return "Mesh m {\n 3;\n 0.0;0.0;0.0;,\n 1.0;0.0;0.0;,\n 0.0;1.0;0.0;;\n 1;\n " + faces + "\n" + extra + "}\n";
}
std::string x_file(const std::string& body) {
    return std::string("xof 0303txt 0032\nFrame Root {\nFrameTransformMatrix { ") + kIdentity + " }\n" + body + "}\n";
}
std::string x_normals(const std::string& index) {
    return "MeshNormals {\n 3;\n 0.0;0.0;1.0;,\n 0.0;0.0;1.0;,\n 0.0;0.0;1.0;;\n 1;\n 3;0,1," + index + ";;\n}\n";
}

// An MD5 mesh of one triangle over one joint; `tri` is its face, `extra_tris` lines after it.
std::string md5_mesh(const std::string& tri, const std::string& extra_tris = "") {
    return "MD5Version 10\ncommandline \"\"\n\nnumJoints 1\nnumMeshes 1\n\njoints {\n\t\"root\"\t-1 ( 0 0 0 ) ( 0 0 0 "
           ")\n}\n\n"
           "mesh {\n\tshader \"x\"\n\tnumverts 3\n\tvert 0 ( 0 0 ) 0 1\n\tvert 1 ( 1 0 ) 1 1\n\tvert 2 ( 0 1 ) 2 1\n"
           "\tnumtris 1\n\ttri 0 " +
           tri + "\n" + extra_tris +
           "\tnumweights 3\n\tweight 0 0 1.0 ( 0 0 0 )\n\tweight 1 0 1.0 ( 1 0 0 )\n\tweight 2 0 1.0 ( 0 1 0 )\n}\n";
}

// A skinned .X character: Root > Bone1 (at y = 1) > Bone2 (at y = 1 + bone2), a triangle
// skinned to both, and a clip "walk" holding Bone2 in place from tick 0 to last_tick at 25
// ticks per second.
std::string x_skinned(const std::string& bone2, long last_tick = 40) {
    auto frame = [](const std::string& ty) {
        return std::string("FrameTransformMatrix { 1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,") + ty +
               ",0.0,1.0;; }\n";
    };
    std::ostringstream s;
    s << "xof 0303txt 0032\nAnimTicksPerSecond { 25; }\nFrame Root {\n"
      << frame("0.0") << "Frame Bone1 {\n"
      << frame("1.0") << "Frame Bone2 {\n"
      << frame(bone2) << "}\n}\n"
      << x_mesh("3;0,1,2;;", std::string(" SkinWeights {\n \"Bone1\";\n 1;\n 0;\n 1.0;\n ") + kIdentity + "\n }\n" +
                                 " SkinWeights {\n \"Bone2\";\n 2;\n 1,2;\n 1.0,1.0;\n " + kIdentity + "\n }\n")
      << "}\nAnimationSet walk {\n Animation {\n  { Bone2 }\n  AnimationKey {\n   2;\n   2;\n   0;3;0.0," << bone2
      << ",0.0;;,\n   " << last_tick << ";3;0.0," << bone2 << ",0.0;;;\n  }\n }\n}\n";
    return s.str();
}

// The LoadError of loading `file` (with `clips`), or "" with a test failure when none.
std::string load_error(const std::string& file, const std::vector<std::string>& clips = {},
                       const LoadOptions& options = {}) {
    try {
        load_character(file, clips, options);
    } catch (const LoadError& e) {
        return e.what();
    }
    ADD_FAILURE() << file << ": loaded without error";
    return "";
}

}  // namespace

TEST_F(AssimpHostile, CraftedFilesThatCrashAssimpGiveOneLineErrors) {
    std::string nested;
    for (int i = 0; i < 60000; ++i) nested += "Frame f {\n";
    nested += x_mesh();
    for (int i = 0; i < 60000; ++i) nested += "}\n";
    const std::string skin_weight =
        std::string(" SkinWeights {\n \"Root\";\n 1;\n -2147483648;\n 1.0;\n ") + kIdentity + "\n }\n";
    // Each of these killed the process inside libassimp 5.2.5 (SIGSEGV) before loads were isolated.
    const std::vector<std::string> crashers = {
        write("normal-index-2e31.x", x_file(x_mesh("3;0,1,2;;", x_normals("2147483647")))),
        write("skin-weight-vertex-minus-2e31.x", x_file(x_mesh("3;0,1,2;;", skin_weight))),
        write("nested-60000.x", "xof 0303txt 0032\n" + nested),
        write("tri-index-2e9.md5mesh", md5_mesh("0 1 2000000000")),
    };
    // Refused by assimp itself or by our checks (no crash in 5.2.5, kept as regressions).
    const std::vector<std::string> refused = {
        write("face-index-2e31.x", x_file(x_mesh("3;0,1,2147483647;;"))),
        write("face-index-65536.x", x_file(x_mesh("3;0,1,65536;;"))),
        write("tri-index-65536.md5mesh", md5_mesh("0 1 65536")),
        write("tri-number-2e9.md5mesh", md5_mesh("0 1 2", "\ttri 2000000000 0 1 2\n")),
    };
    // A heap overflow read in assimp that crashes or not with the heap's layout (it crashed the
    // command-line tool, not always this test): loading it must simply never kill us.
    try {
        load_character(write("normal-index-65536.x", x_file(x_mesh("3;0,1,2;;", x_normals("65536")))));
    } catch (const LoadError& e) {
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
    for (const auto* list : {&crashers, &refused})
        for (const std::string& file : *list) {
            SCOPED_TRACE(file);
            const std::string what = load_error(file);
            EXPECT_EQ(what.rfind(file + ": ", 0), 0u) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
            if (list == &crashers) {
                EXPECT_NE(what.find(": assimp crashed reading it ("), std::string::npos) << what;
            }
            std::printf("%s\n", what.c_str());
        }
}

// A cut .md5mesh: assimp 5.2 loads what came before the cut without a word (Bob cut at 30% gave
// one mesh of its six). Its header's mesh count and each mesh's vert, tri and weight counts say
// what it should hold; a file that holds less is refused, naming what is missing.
TEST_F(AssimpHostile, ACutMd5MeshIsRefused) {
    const std::string whole = md5_mesh("0 1 2");
    EXPECT_NO_THROW(load_character(write("whole.md5mesh", whole)));
    std::string two = whole;
    two.replace(two.find("numMeshes 1"), 11, "numMeshes 2");
    EXPECT_NE(load_error(write("two.md5mesh", two)).find("its header says 2 meshes, it holds 1"), std::string::npos);
    const std::string cut = whole.substr(0, whole.rfind("\tweight 2"));
    EXPECT_NE(load_error(write("cut.md5mesh", cut)).find("mesh 1 says 3 weights, it holds 2"), std::string::npos);
}

// A PLY whose header never ends: assimp 5.2 reads it for ever. The isolated reader is stopped
// after its processor time (LoadOptions::parse_seconds, 1 s here) and the file named.
TEST_F(AssimpHostile, AFileAssimpLoopsOnIsStoppedInItsTime) {
    LoadOptions options;
    options.parse_seconds = 1;
    const std::string ply = write("cut-header.ply", "ply\nformat ascii 1.0\ncomment Created ");
    // The second time from a process that ignores SIGXCPU (a setting the reader inherits).
    for (const bool ignored : {false, true}) {
        SCOPED_TRACE(ignored ? "SIGXCPU ignored" : "SIGXCPU as by default");
        const auto previous = std::signal(SIGXCPU, ignored ? SIG_IGN : SIG_DFL);
        const auto start = std::chrono::steady_clock::now();
        const std::string what = load_error(ply, {}, options);
        std::signal(SIGXCPU, previous);
        EXPECT_EQ(what,
                  ply + ": assimp did not finish reading it in 1 s of processor time (a damaged file it loops on?)");
        EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 30.0);
    }
}

// A cut text STL: assimp 5.2 keeps the facets before the cut without a word (Bob's STL cut in
// half gave 512 of 1,027 triangles); a text STL ends with "endsolid". A binary STL whose header
// starts with "solid" is no text STL.
TEST_F(AssimpHostile, ACutTextStlIsRefused) {
    const std::string facet =
        "facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n "
        "endloop\nendfacet\n";
    const std::string whole = "solid tri\n" + facet + facet + "endsolid tri\n";
    EXPECT_EQ(load_character(write("whole.stl", whole)).triangle_count(), 2u);
    const std::string cut = whole.substr(0, whole.rfind("endloop"));
    EXPECT_NE(load_error(write("cut.stl", cut)).find("cut short or damaged: a text STL ends with 'endsolid'"),
              std::string::npos);
    // Ends that are whole: CR lines, one line, a NUL or a ^Z after the name.
    std::string cr = whole, one_line = whole;
    std::replace(cr.begin(), cr.end(), '\n', '\r');
    std::replace(one_line.begin(), one_line.end(), '\n', ' ');
    for (const std::string& text : {cr, one_line, whole + std::string(1, '\0'), whole + "\x1a"})
        EXPECT_EQ(load_character(write("whole-end.stl", text)).triangle_count(), 2u) << text;
    std::string binary(84 + 50, '\0');  // one facet, its header starting "solid"
    binary.replace(0, 5, "solid");
    binary[80] = 1;
    const float corners[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::memcpy(&binary[84], corners, sizeof corners);
    EXPECT_EQ(load_character(write("binary.stl", binary)).triangle_count(), 1u);
}

// A file of points and lines only: what the loader says of glTF, not assimp's "No meshes remaining".
TEST_F(AssimpHostile, PointsAndLinesOnlyAreNamed) {
    const std::string obj = write("lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\np 3\n");
    EXPECT_EQ(load_error(obj),
              obj + ": no triangle mesh in the file (points and lines cannot be reordered for overdraw)");
}

TEST_F(AssimpHostile, ACrashInAClipFileNamesTheClipFile) {
    const std::string character = write("character.x", x_skinned("1.0"));
    const std::string skin_weight =
        std::string(" SkinWeights {\n \"Root\";\n 1;\n -2147483648;\n 1.0;\n ") + kIdentity + "\n }\n";
    const std::string clip = write("clip.x", x_file(x_mesh("3;0,1,2;;", skin_weight)));
    const std::string what = load_error(character, {clip});
    EXPECT_EQ(what.rfind(clip + ": assimp crashed reading it (", 0), 0u) << what;
}

TEST_F(AssimpHostile, AGoodFileComesBackFromTheChildWhole) {
    const AnimatedMesh m = load_character(write("triangle.x", x_file(x_mesh())));
    ASSERT_EQ(m.vertex_count, 3u);
    ASSERT_EQ(m.indices.size(), 3u);
    ASSERT_EQ(m.clips.size(), 1u);
    EXPECT_EQ(m.clips[0].name, "static");
    EXPECT_EQ(m.keyframe_count(), 1u);
    // The triangle's corners, whatever order assimp keeps them in, with z up to a sign (.X is
    // left-handed).
    std::set<std::array<float, 3>> corners;
    for (size_t v = 0; v < 3; ++v)
        corners.insert({m.keyframe(0)[3 * v], m.keyframe(0)[3 * v + 1], std::fabs(m.keyframe(0)[3 * v + 2])});
    EXPECT_EQ(corners, (std::set<std::array<float, 3>>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
    // The skinned one: Bone2 held at rest, so every keyframe is the bind pose.
    const AnimatedMesh s = load_character(write("skinned.x", x_skinned("1.0")));
    EXPECT_EQ(s.joint_count, 2u);
    ASSERT_EQ(s.clips.size(), 1u);
    EXPECT_EQ(s.clips[0].keyframe_count, 49u);  // 40 ticks at 25/s = 1.6 s at 30/s, + 1
    for (size_t k = 0; k < s.keyframe_count(); k += 12)
        for (size_t i = 0; i < 9; ++i) EXPECT_NEAR(s.keyframe(k)[i], s.keyframe(0)[i], 1e-6);
}

// As in glTF (test_gltf_loader): a node transform that mirrors (here the root frame's x → −x) makes
// the file's front faces clockwise, as engines cull them; the loader flips the corners back to
// counter-clockwise, and the flag crosses from the importer's child process.
TEST_F(AssimpHostile, AMirroringFrameFlipsTheWindingAcrossTheIsolatedReader) {
    const AnimatedMesh upright = load_character(write("triangle.x", x_file(x_mesh())));
    ASSERT_EQ(upright.indices.size(), 3u);
    EXPECT_FALSE(upright.primitives[0].mirrored);
    std::string mirrored_file = x_file(x_mesh());
    const std::string identity = kIdentity;
    mirrored_file.replace(mirrored_file.find(identity), 3, "-1.");
    const AnimatedMesh m = load_character(write("mirrored.x", mirrored_file));
    ASSERT_EQ(m.primitives.size(), 1u);
    EXPECT_TRUE(m.primitives[0].mirrored);
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{upright.indices[0], upright.indices[2], upright.indices[1]}));
    for (size_t v = 0; v < 3; ++v) EXPECT_EQ(m.keyframe(0)[3 * v], -upright.keyframe(0)[3 * v]) << v;
}

// A clip that only scales (the .X AnimationKey of type 1) lasts to its last scaling key: 50 ticks at
// 25 per second are 2 s, 61 keyframes at 30/s, the last one at twice the size (it had been cut to
// the position and rotation keys: none, so "animates nothing", or shorter).
TEST_F(AssimpHostile, AClipOfScalingKeysLastsToItsLastKey) {
    std::string file = x_file(x_mesh()) +
                       "AnimationSet grow {\n Animation {\n  { Root }\n  AnimationKey {\n   1;\n   2;\n"
                       "   0;3;1.0,1.0,1.0;;,\n   50;3;2.0,2.0,2.0;;;\n  }\n }\n}\n";
    file.insert(file.find('\n') + 1, "AnimTicksPerSecond { 25; }\n");
    const AnimatedMesh m = load_character(write("grow.x", file));
    ASSERT_EQ(m.clips.size(), 1u);
    EXPECT_NEAR(m.clips[0].duration_s, 2.0, 1e-9);
    EXPECT_EQ(m.clips[0].keyframe_count, 61u);
    float x_max = 0;
    for (size_t v = 0; v < 3; ++v) x_max = std::max(x_max, std::fabs(m.keyframe(60)[3 * v]));
    EXPECT_NEAR(x_max, 2.0f, 1e-5);
}

// A skinned mesh's vertex that no bone weighs stays with the mesh's node: here the root frame sits
// at x = 10 and only vertex 0 is weighed (to Bone1, offset identity, so it too sits 10 along x), and
// all three corners are moved by 10 (vertices 1 and 2 had stayed at their mesh-space coordinates,
// tearing the triangle 10 units long).
TEST_F(AssimpHostile, AVertexNoBoneWeighsStaysWithItsMeshsNode) {
    const std::string translated = "1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0,0.0,10.0,0.0,0.0,1.0;;";
    const std::string file =
        std::string("xof 0303txt 0032\nFrame Root {\nFrameTransformMatrix { ") + translated +
        " }\nFrame Bone1 {\nFrameTransformMatrix { " + kIdentity + " }\n}\n" +
        x_mesh("3;0,1,2;;", std::string(" SkinWeights {\n \"Bone1\";\n 1;\n 0;\n 1.0;\n ") + kIdentity + "\n }\n") +
        "}\n";
    const AnimatedMesh m = load_character(write("partial.x", file));
    ASSERT_EQ(m.vertex_count, 3u);
    EXPECT_EQ(m.joint_count, 1u);
    std::set<std::array<float, 2>> corners;
    for (size_t v = 0; v < 3; ++v) corners.insert({m.keyframe(0)[3 * v], m.keyframe(0)[3 * v + 1]});
    EXPECT_EQ(corners, (std::set<std::array<float, 2>>{{10, 0}, {11, 0}, {10, 1}}));
}

// A clip folder's hidden files (macOS leaves .DS_Store in every folder it shows) are no clips: the
// folder loads (it failed on assimp's "No suitable reader"); another stray file still fails.
TEST_F(AssimpHostile, AClipFoldersHiddenFilesAreNoClips) {
    const std::string character = write("character.x", x_skinned("1.0"));
    fs::create_directories(path("clips"));
    write("clips/run.x", x_skinned("1.0", 20));
    write("clips/.DS_Store", std::string("\0\0\0\1Bud1", 8));
    const AnimatedMesh m = load_character(character, {path("clips").string()});
    ASSERT_EQ(m.clips.size(), 2u);
    EXPECT_EQ(m.clips[1].name, "run");
    write("clips/notes.txt", "not a clip");
    EXPECT_NE(load_error(character, {path("clips").string()}).find("notes.txt"), std::string::npos);
}

TEST_F(AssimpHostile, LongClipsAreCheckedAgainstTheBudgetBeforeSampling) {
    // Two keys 83,000 ticks apart at 25 ticks per second: 3,320 s, 99,601 keyframes at 30/s —
    // under the 100,000 cap, so only the budget stops a big character's 2.5 GB.
    const std::string file = write("long.x", x_skinned("1.0", 83000));
    const size_t need = size_t(99601) * 3 * 12;
    LoadOptions tight;
    tight.max_keyframe_bytes = need - 1;
    const std::string what = load_error(file, {}, tight);
    EXPECT_EQ(what.rfind(file + ": the animation needs 99601 keyframes x 3 vertices", 0), 0u) << what;
    EXPECT_NE(what.find("loading budget of " + std::to_string(need - 1) + " bytes"), std::string::npos) << what;
    LoadOptions exact;
    exact.max_keyframe_bytes = need;
    EXPECT_EQ(load_character(file, {}, exact).keyframe_count(), 99601u);
}

// A clip file for a skeleton of other proportions is retargeted with a note naming the largest
// difference; one for the character's own skeleton (to exporters' rounding) is applied as it is.
TEST_F(AssimpHostile, ClipFilesOfAnotherSkeletonAreRetargetedNamingTheJoint) {
    const std::string character = write("character.x", x_skinned("1.0"));
    const AnimatedMesh m = load_character(
        character, {write("same.x", x_skinned("1.0005")), write("close.x", x_skinned("1.01")),
                    write("other.x", x_skinned("1.5"))});
    ASSERT_EQ(m.clips.size(), 4u);
    EXPECT_EQ(m.clips[0].retargeted, "");
    EXPECT_EQ(m.clips[1].retargeted, "") << "a difference exporters' rounding makes";
    EXPECT_NE(m.clips[2].retargeted, "") << "Bone2 1% longer";
    // 50 % longer (the character is 1 unit from Bone1 to Bone2).
    EXPECT_EQ(m.clips[3].retargeted.rfind("retargeted onto the character's bone offsets (largest difference: joint "
                                          "'Bone2' at (0, 1.5, 0) in the clip and (0, 1, 0) in the character: 50.0% "
                                          "of its size 1)",
                                          0),
              0u)
        << m.clips[3].retargeted;
    // Its keyframes are those of the character's own clip: Bone2 keeps the character's offset.
    ASSERT_EQ(m.clips[3].keyframe_count, m.clips[0].keyframe_count);
    for (size_t i = 0; i < m.vertex_count * 3; ++i)
        EXPECT_EQ(m.keyframe(m.clips[3].first_keyframe)[i], m.keyframe(m.clips[0].first_keyframe)[i]) << i;
}

namespace {
// A skinned .X rig: Root > Bone1 (the hips, `hip` above the root) > Bone2 (`bone` above Bone1),
// the triangle's corner 0 on Bone1 and corners 1 and 2 on Bone2, with a clip "move" made for
// this rig: over 40 ticks Bone1 walks forward half its height and turns a quarter about z, Bone2
// bends an eighth about x. `skeleton` replaces the frames (a rig without Bone2). Numbers are
// written with a decimal point (assimp's .X reader refuses "1" where it expects a float).
std::string x_rig(double hip, double bone, const std::string& skeleton = "") {
    auto frame = [](double ty) {
        return "FrameTransformMatrix { 1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0," + std::to_string(ty) +
               ",0.0,1.0;; }\n";
    };
    std::ostringstream s;
    s << "xof 0303txt 0032\nAnimTicksPerSecond { 25; }\nFrame Root {\n" << frame(0);
    if (skeleton.empty())
        s << "Frame Bone1 {\n" << frame(hip) << "Frame Bone2 {\n" << frame(bone) << "}\n}\n";
    else
        s << skeleton;
    s << x_mesh("3;0,1,2;;", std::string(" SkinWeights {\n \"Bone1\";\n 1;\n 0;\n 1.0;\n ") + kIdentity + "\n }\n" +
                                 " SkinWeights {\n \"Bone2\";\n 2;\n 1,2;\n 1.0,1.0;\n " + kIdentity + "\n }\n")
      << "}\nAnimationSet move {\n"
      << " Animation {\n  { Bone1 }\n  AnimationKey {\n   0;\n   2;\n   0;4;1.0,0.0,0.0,0.0;;,\n"
      << "   40;4;0.7071068,0.0,0.0,0.7071068;;;\n  }\n  AnimationKey {\n   2;\n   2;\n   0;3;0.0," << std::to_string(hip)
      << ",0.0;;,\n   40;3;" << std::to_string(hip / 2) << "," << std::to_string(hip) << ",0.0;;;\n  }\n }\n"
      << " Animation {\n  { Bone2 }\n  AnimationKey {\n   0;\n   2;\n   0;4;1.0,0.0,0.0,0.0;;,\n"
      << "   40;4;0.9238795,0.3826834,0.0,0.0;;;\n  }\n  AnimationKey {\n   2;\n   2;\n   0;3;0.0," << std::to_string(bone)
      << ",0.0;;,\n   40;3;0.0," << std::to_string(bone) << ",0.0;;;\n  }\n }\n}\n";
    return s.str();
}
}  // namespace

// Retargeted as engines play a clip made for another rig: the clip's rotations on the character's
// own bone offsets, the hips' translation scaled by the hip heights. The same motion made for a
// rig with hips 1.5 times as high and a bone twice as long then moves the character exactly as
// the motion made for its own rig does (without retargeting, its triangle would stretch to the
// other rig's bone and walk the other rig's stride). A clip whose skeleton lacks one of the
// character's skinned joints cannot drive it: refused, naming the joint.
TEST_F(AssimpHostile, AClipForAnotherRigMovesTheCharacterAsItsOwnClipDoes) {
    const std::string character = write("character.x", x_rig(1, 1));
    const AnimatedMesh m =
        load_character(character, {write("own.x", x_rig(1, 1)), write("taller.x", x_rig(1.5, 2))});
    ASSERT_EQ(m.clips.size(), 3u);
    const Clip &own = m.clips[1], &taller = m.clips[2];
    EXPECT_EQ(own.retargeted, "");
    EXPECT_NE(taller.retargeted.find("joint 'Bone2' at (0, 2, 0) in the clip and (0, 1, 0) in the character"),
              std::string::npos)
        << taller.retargeted;
    EXPECT_NE(taller.retargeted.find("root translation of 'Bone1' scaled by 0.6667"), std::string::npos)
        << taller.retargeted;
    ASSERT_EQ(taller.keyframe_count, own.keyframe_count);
    float moved = 0;
    for (size_t k = 0; k < own.keyframe_count; ++k)
        for (size_t i = 0; i < m.vertex_count * 3; ++i) {
            const float expected = m.keyframe(own.first_keyframe + k)[i];
            EXPECT_NEAR(m.keyframe(taller.first_keyframe + k)[i], expected, 1e-5f) << "keyframe " << k << ", " << i;
            moved = std::max(moved, std::fabs(expected - m.keyframe(own.first_keyframe)[i]));
        }
    EXPECT_GT(moved, 0.4f) << "the motion moves the triangle";
    // Its hips named otherwise: Bone2 is 2 from them, not 1, and Bone1 is not there.
    const std::string lacking = write(
        "lacking.x", x_rig(1.5, 2, "Frame Hips {\nFrameTransformMatrix { 1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0,"
                                   "0.0,0.0,1.5,0.0,1.0;; }\nFrame Bone2 {\nFrameTransformMatrix { 1.0,0.0,0.0,0.0,0.0,"
                                   "1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,2.0,0.0,1.0;; }\n}\n}\n"));
    // One made for the character's own rig that lacks a joint loads: the joint stays at rest.
    const AnimatedMesh own_lacking = load_character(
        character, {write("own-lacking.x", x_rig(1, 1, "Frame Bone1 {\nFrameTransformMatrix { 1.0,0.0,0.0,0.0,0.0,1.0,"
                                                      "0.0,0.0,0.0,0.0,1.0,0.0,0.0,1.0,0.0,1.0;; }\n}\n"))});
    ASSERT_EQ(own_lacking.clips.size(), 2u);
    EXPECT_EQ(own_lacking.clips[1].retargeted, "");
    const std::string what = load_error(character, {lacking});
    EXPECT_EQ(what, lacking + ": made for another skeleton than " + character +
                        "'s: it has no joint 'Bone1' (1 of the character's 2 skinned joints missing), so it cannot "
                        "drive the character");
}

// The joint count is the skeleton's (every node a bone of some mesh names, once), not the largest
// mesh's bone count: BCN_Epileptic's three meshes have 24, 20 and 10 bones of its 54 joints
// (../shared/data/README.md), and it reported 24.
TEST(AssimpCharacters, TheJointCountIsTheSkeletonsAcrossMeshes) {
    const std::string file = kData + "x-bcn-epileptic/BCN_Epileptic.X";
    ANIMORDER_REQUIRE_DATA(file);
    const AnimatedMesh m = load_character(file);
    EXPECT_EQ(m.primitives.size(), 3u);
    EXPECT_EQ(m.joint_count, 54u);
}

// Two readers of one file: glTF characters read by assimp (its glTF importer, this loader's
// hierarchy, skinning and morph targets) and by the glTF loader (tinygltf, its own evaluation)
// give the same keyframes, corner by corner (assimp joins identical vertices, so vertices are
// compared through the triangles), within float rounding. Skins (CesiumMan, Fox), skin and
// morph targets on 19 meshes (RobotExpressive), and keyed morph weights alone: a whole mesh per
// key (Horse), two targets (AnimatedMorphSphere), eight targets on a mesh of two primitives
// (MorphStressTest). Before assimp's morph channels were read, the morph files were refused
// ("animates nothing").
TEST(AssimpCharacters, GltfReadByAssimpMatchesTheGltfLoader) {
    animorder::test::DataFiles data;
    for (const char* file :
         {"gltf-cesiumman/CesiumMan.glb", "gltf-fox/Fox.glb", "glb-robot-expressive/RobotExpressive.glb",
          "glb-horse-morph/Horse.glb", "gltf-animated-morph-sphere/AnimatedMorphSphere.gltf",
          "gltf-morph-stress-test/MorphStressTest.gltf"}) {
        SCOPED_TRACE(file);
        if (!data.present(kData + file)) continue;  // named at the end; the other files still run
        const AnimatedMesh gltf = load_character(kData + file);
        AnimatedMesh assimp;
        ASSERT_NO_THROW(assimp = load_assimp(kData + file));
        ASSERT_EQ(assimp.clips.size(), gltf.clips.size());
        for (size_t c = 0; c < gltf.clips.size(); ++c) {
            EXPECT_EQ(assimp.clips[c].name, gltf.clips[c].name);
            EXPECT_EQ(assimp.clips[c].keyframe_count, gltf.clips[c].keyframe_count);
        }
        EXPECT_EQ(assimp.morph_target_count, gltf.morph_target_count);
        ASSERT_EQ(assimp.indices.size(), gltf.indices.size());
        ASSERT_EQ(assimp.keyframe_count(), gltf.keyframe_count());
        double size = 0, worst = 0;
        for (size_t k = 0; k < gltf.keyframe_count(); ++k)
            for (size_t i = 0; i < gltf.indices.size(); ++i)
                for (size_t d = 0; d < 3; ++d) {
                    const double mine = assimp.keyframe(k)[3 * assimp.indices[i] + d];
                    const double theirs = gltf.keyframe(k)[3 * gltf.indices[i] + d];
                    size = std::max(size, std::fabs(theirs));
                    worst = std::max(worst, std::fabs(mine - theirs));
                }
        EXPECT_GT(size, 0.0);
        EXPECT_LE(worst, 1e-5 * size) << "largest difference " << worst << " in a character of size " << size;
    }
    ANIMORDER_REQUIRE_ALL_DATA(data);
}

// The same on a file of one triangle (no data needed): a morph target moving vertex 2 by (0, 0, 2),
// its weight keyed 0 → 1 over 2 s under a node moved by (0, 0, 5); and morph weights assimp passes
// on unchecked, refused by name: one that is not finite, one absurd.
TEST_F(AssimpHostile, AMorphTargetThroughAssimpMovesAsTheGltfLoaderSays) {
    const auto morphing = [](float weight, float time) {
        test::Gltf g;
        using nlohmann::json;
        const int p = g.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3), i = g.u16({0, 1, 2}, "SCALAR", 1);
        const int target = g.floats({0, 0, 0, 0, 0, 0, 0, 0, 2}, "VEC3", 3);
        const int t = g.floats({0, time}, "SCALAR", 1), w = g.floats({0, weight}, "SCALAR", 1);
        json primitive = {
            {"attributes", {{"POSITION", p}}}, {"indices", i}, {"targets", json::array({json{{"POSITION", target}}})}};
        g.doc["meshes"] = json::array({json{{"primitives", json::array({primitive})}, {"weights", {0.0}}}});
        g.doc["nodes"] = json::array({json{{"name", "blob"}, {"mesh", 0}, {"translation", {0, 0, 5}}}});
        g.doc["scenes"] = json::array({json{{"nodes", json::array({0})}}});
        json sampler = {{"input", t}, {"output", w}};
        json channel = {{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}};
        g.doc["animations"] = json::array(
            {json{{"name", "swell"}, {"samplers", json::array({sampler})}, {"channels", json::array({channel})}}});
        return g.text();
    };
    const std::string file = write("swell.gltf", morphing(1, 2));
    const AnimatedMesh gltf = load_character(file), assimp = load_assimp(file);
    ASSERT_EQ(assimp.keyframe_count(), 61u);
    ASSERT_EQ(gltf.keyframe_count(), 61u);
    for (size_t k = 0; k < 61; ++k)
        for (size_t i = 0; i < 3; ++i)
            for (size_t d = 0; d < 3; ++d)
                EXPECT_NEAR(assimp.keyframe(k)[3 * assimp.indices[i] + d], gltf.keyframe(k)[3 * gltf.indices[i] + d],
                            1e-6);
    EXPECT_FLOAT_EQ(assimp.keyframe(30)[3 * assimp.indices[2] + 2], 6.0f);  // weight 0.5: 5 + 1
    for (const auto& [weight, time, message] :
         {std::tuple{NAN, 2.0f, "morph channel 'blob' keys a weight of nan"},
          std::tuple{1e30f, 2.0f,
                     "morph channel 'blob' keys a weight of 1000000015047466219876688855040.000000, "
                     "absurd for a morph target"}}) {
        const std::string bad = write("bad.gltf", morphing(weight, time));
        test::expect_one_line_load_error(bad, message, [&] { load_assimp(bad); });
    }
}

// A Mixamo clip moves the character's parts as a skeleton does: in every keyframe of the witch's
// own run, 99% of her triangles' edges keep their length in her file's own pose to within a factor
// of two (a correct run: under 1.8; the skin stretches at her joints). Her joints' pivots and
// pre-rotations were applied twice (kept as assimp's helper nodes while her joints' keys held them
// too): she was a tangle, her foot above her hips, and that 99th percentile above 2.5.
TEST(AssimpCharacters, AMixamoClipMovesThePartsRigidly) {
    const std::string witch = kData + "pg-witch/model.fbx", run = kData + "pg-witch/anims/Run.fbx";
    ANIMORDER_REQUIRE_DATA(witch);
    ANIMORDER_REQUIRE_DATA(run);
    const AnimatedMesh m = load_character(witch, {run});
    ASSERT_EQ(m.clips.size(), 2u);
    auto edge = [&](size_t k, uint32_t a, uint32_t b) {
        const float *p = m.keyframe(k) + 3 * size_t(a), *q = m.keyframe(k) + 3 * size_t(b);
        return std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
    };
    const size_t pose = m.clips[0].first_keyframe;
    for (size_t k = m.clips[1].first_keyframe; k < m.clips[1].first_keyframe + m.clips[1].keyframe_count; ++k) {
        std::vector<double> stretch;
        for (size_t i = 0; i < m.indices.size(); i += 3)
            for (int e = 0; e < 3; ++e) {
                const uint32_t a = m.indices[i + size_t(e)], b = m.indices[i + size_t(e + 1) % 3];
                const double rest = edge(pose, a, b);
                if (rest > 0) stretch.push_back(std::max(edge(k, a, b) / rest, rest / edge(k, a, b)));
            }
        ASSERT_FALSE(stretch.empty());
        std::nth_element(stretch.begin(), stretch.begin() + ptrdiff_t(stretch.size() * 99 / 100), stretch.end());
        EXPECT_LE(stretch[stretch.size() * 99 / 100], 2.0) << "keyframe " << k;
    }
}

// Another Mixamo character's clip (the barbarian's walk, on the witch) is retargeted, the note
// naming the joint that differs most; her own clips are applied as they are.
TEST(AssimpCharacters, AnotherCharactersMixamoClipIsRetargeted) {
    const std::string witch = kData + "pg-witch/model.fbx", walk = kData + "pg-barbarian/anims/Dwarf Walk.fbx";
    ANIMORDER_REQUIRE_DATA(witch);
    ANIMORDER_REQUIRE_DATA(walk);
    const AnimatedMesh all = load_character(witch, {walk, kData + "pg-witch/anims/Run.fbx"});
    ASSERT_EQ(all.clips.size(), 3u);  // her file's own pose, then the clip files
    const AnimatedMesh m = select_clips(all, {"Dwarf Walk", "Run"});
    // The barbarian's forearm is 27.36 cm, the witch's 38.89 cm, her size 236 cm.
    EXPECT_EQ(m.clips[0].retargeted.rfind(
                  "retargeted onto the character's bone offsets (largest difference: joint 'mixamorig:LeftForeArm'", 0),
              0u)
        << m.clips[0].retargeted;
    EXPECT_EQ(m.clips[0].retargeted.find('\n'), std::string::npos);
    EXPECT_EQ(m.clips[1].retargeted, "");
    // Walking, she stands her own height (the walk's bones on hers, her hips at her height): within
    // a tenth of it in her file's own pose (a T-pose), keyframe by keyframe.
    auto height = [](const AnimatedMesh& mesh, size_t k) {
        float low = INFINITY, high = -INFINITY;
        for (size_t v = 0; v < mesh.vertex_count; ++v)
            low = std::min(low, mesh.keyframe(k)[3 * v + 1]), high = std::max(high, mesh.keyframe(k)[3 * v + 1]);
        return high - low;
    };
    const double standing = height(all, all.clips[0].first_keyframe);
    for (size_t k = 0; k < m.clips[0].keyframe_count; ++k)
        EXPECT_NEAR(height(m, m.clips[0].first_keyframe + k), standing, 0.1 * standing) << "keyframe " << k;
}

// A Doom 3 character's own .md5anim under another name, given as a clip file, loads as the same
// clip as when it sits beside the mesh under the mesh's name: the skeleton rule does not apply to
// an .md5anim (its baseframe is no bind pose; it refused Bob's own walk for its 'lamp' joint).
TEST_F(AssimpHostile, AnMd5CharactersOwnAnimationLoadsAsAClipFile) {
    const std::string mesh = kData + "md5-bob/Bob.md5mesh", anim = kData + "md5-bob/Bob.md5anim";
    ANIMORDER_REQUIRE_DATA(mesh);
    ANIMORDER_REQUIRE_DATA(anim);
    fs::copy_file(mesh, path("Bob.md5mesh"));
    fs::copy_file(anim, path("walk.md5anim"));
    const AnimatedMesh own = load_character(mesh);
    const AnimatedMesh m = load_character(path("Bob.md5mesh").string(), {path("walk.md5anim").string()});
    ASSERT_EQ(m.clips.size(), 1u);
    EXPECT_EQ(m.clips[0].name, "walk");
    EXPECT_EQ(m.keyframe_count(), own.keyframe_count());
    ASSERT_EQ(m.keyframe_positions.size(), own.keyframe_positions.size());
    float worst = 0;  // the clip file's importer rounds the joints' transforms its own way
    for (size_t i = 0; i < m.keyframe_positions.size(); ++i)
        worst = std::max(worst, std::fabs(m.keyframe_positions[i] - own.keyframe_positions[i]));
    EXPECT_LT(worst, 1e-3f);  // Bob is about 100 units tall
}

// Material flags through assimp and the isolated reader's serialisation: OBJ's `d` (dissolve)
// below 1 is BLEND; a material without it OPAQUE; OBJ has no two-sided flag.
TEST_F(AssimpHostile, MaterialFlagsTravelThroughTheIsolatedReader) {
    write("veil.mtl", "newmtl solid\nKd 1 1 1\nnewmtl veil\nKd 1 1 1\nd 0.5\n");
    const std::string obj = write("veil.obj",
                                  "mtllib veil.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\n"
                                  "o solid\nusemtl solid\nf 1 2 3\no veil\nusemtl veil\nf 4 5 6\n");
    const AnimatedMesh m = load_character(obj);
    ASSERT_EQ(m.primitives.size(), 2u);
    EXPECT_EQ(m.primitives[0].alpha_mode, AlphaMode::Opaque);
    EXPECT_EQ(m.primitives[1].alpha_mode, AlphaMode::Blend);
    EXPECT_FALSE(m.primitives[0].double_sided);
    EXPECT_FALSE(m.primitives[1].double_sided);
}

// A file of bones and motion alone (a .bvh here, like an .md5anim): assimp adds a mesh drawing the
// bones ("SkeletonMaterial"), which is not a character. Loaded as one, it gave 16 triangles of
// bones and every method "optimised" them; now it is a one-line error pointing at --clip.
TEST_F(AssimpHostile, ASkeletonWithoutAMeshIsNotACharacter) {
    const std::string bvh = write("walk.bvh",
                                  "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n"
                                  "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
                                  "  JOINT Chest\n  {\n    OFFSET 0 5 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n"
                                  "    End Site\n    {\n      OFFSET 0 5 0\n    }\n  }\n}\n"
                                  "MOTION\nFrames: 2\nFrame Time: 0.033333\n0 0 0 0 0 0 0 0 0\n0 0 0 0 0 0 10 0 0\n");
    const std::string what = load_error(bvh);
    EXPECT_EQ(what.rfind(bvh, 0), 0u) << what;
    EXPECT_NE(what.find("only a skeleton"), std::string::npos) << what;
    EXPECT_NE(what.find("--clip"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
}
