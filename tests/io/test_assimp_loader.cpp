// The assimp loader on every non-glTF character of ../shared/data (skipped with a message when
// the folder is absent): triangle counts of shared/data/README.md, Mixamo clip folders matched by
// joint name, skin that stretches without tearing, and one-line errors.
#include "animorder/animated_mesh.h"
#include "animorder/load.h"
#include "support/meshes.h"
#include "support/require.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

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
    for (const Case& c : cases) {
        SCOPED_TRACE(c.file);
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
                       double(a[2]) * (double(b[0]) * c[1] - double(b[1]) * c[0])) / 6.0;
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
                   double(a[2]) * (double(b[0]) * d[1] - double(b[1]) * d[0])) / 6.0;
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
