// The prerequisite switch of support/require.h: which ANIMORDER_REQUIRE values require which
// component, and that a required, missing prerequisite is a fatal failure carrying the reason.
#include "support/require.h"

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace test = animorder::test;

TEST(Require, UnsetOrEmptyRequiresNothing) {
    EXPECT_FALSE(test::requires_component(nullptr, "gl"));
    EXPECT_FALSE(test::requires_component("", "data"));
    EXPECT_FALSE(test::requires_component(",,", "validator"));
}

TEST(Require, CommaListNamesExactlyItsComponents) {
    EXPECT_TRUE(test::requires_component("gl,validator,data", "gl"));
    EXPECT_TRUE(test::requires_component("gl,validator,data", "validator"));
    EXPECT_TRUE(test::requires_component("gl,validator,data", "data"));
    EXPECT_TRUE(test::requires_component("gl", "gl"));
    EXPECT_FALSE(test::requires_component("gl", "data"));
    EXPECT_FALSE(test::requires_component("validator,data", "gl"));
    EXPECT_TRUE(test::requires_component(" gl , data ", "data"));  // spaces around names are ignored
}

TEST(Require, AllRequiresEveryComponent) {
    for (const char* c : {"gl", "validator", "data"}) EXPECT_TRUE(test::requires_component("all", c)) << c;
    EXPECT_TRUE(test::requires_component("data,all", "gl"));
}

// The prerequisites of the signal tests (strace to slow a commit down, a PID namespace for a
// container's first process) and of the /proc and root tests are components CI can require: they
// called GTEST_SKIP themselves, and CI passed without running them.
TEST(Require, TheSignalAndSystemPrerequisitesAreComponents) {
    for (const char* c : {"strace", "namespaces", "root", "proc"}) {
        EXPECT_TRUE(test::known_component(c)) << c;
        EXPECT_TRUE(test::requires_component("all", c)) << c;
        EXPECT_FALSE(test::requires_component("gl,data", c)) << c;
    }
    EXPECT_TRUE(test::requires_component("gl,strace,namespaces", "strace"));
    EXPECT_TRUE(test::requires_component("gl,strace,namespaces", "namespaces"));
    EXPECT_FALSE(test::requires_component("gl,strace", "namespaces"));
}

TEST(Require, UnknownNamesAreFailuresNotSilentlyIgnored) {
    EXPECT_NONFATAL_FAILURE(test::requires_component("gl,opengl", "gl"), "unknown component 'opengl'");
    EXPECT_NONFATAL_FAILURE(test::requires_component("gl", "gpu"), "unknown prerequisite 'gpu'");
}

namespace {
void missing_gl() { ANIMORDER_REQUIRE_OR_SKIP("gl", 1 + 1 == 3, "no display for " << 42); }
void present_gl() { ANIMORDER_REQUIRE_OR_SKIP("gl", 1 + 1 == 2, "never printed"); }
}  // namespace

TEST(Require, RequiredAndMissingFailsWithTheReason) {
    const char* before = std::getenv("ANIMORDER_REQUIRE");
    const std::string saved = before ? before : "";
    ::setenv("ANIMORDER_REQUIRE", "validator,gl", 1);
    EXPECT_FATAL_FAILURE(missing_gl(), "no display for 42");
    ::setenv("ANIMORDER_REQUIRE", "all", 1);
    EXPECT_FATAL_FAILURE(missing_gl(), "required gl (ANIMORDER_REQUIRE) is missing");
    EXPECT_NO_FATAL_FAILURE(present_gl());  // present: neither a failure nor a skip
    if (before)
        ::setenv("ANIMORDER_REQUIRE", saved.c_str(), 1);
    else
        ::unsetenv("ANIMORDER_REQUIRE");
    EXPECT_FALSE(::testing::Test::IsSkipped());
}

// A loop over characters records every missing file and goes on; at the end the skip (or, when
// data is required, the failure) names all of them, not the first alone.
namespace {
// Globals: EXPECT_FATAL_FAILURE's statement cannot name the test's locals.
test::DataFiles g_data;
int g_ran = 0;
void loop_over_files() {
    for (const char* f : {"no-such-a.glb", "CMakeLists.txt", "no-such-b.glb", "README.md"}) {
        if (!g_data.present(std::filesystem::path(ANIMORDER_SOURCE_DIR) / f)) continue;
        ++g_ran;
    }
    ANIMORDER_REQUIRE_ALL_DATA(g_data);
}
}  // namespace

TEST(Require, DataFilesNameEveryMissingFileAfterTheLoop) {
    const char* before = std::getenv("ANIMORDER_REQUIRE");
    const std::string saved = before ? before : "";
    ::setenv("ANIMORDER_REQUIRE", "data", 1);
    EXPECT_FATAL_FAILURE(loop_over_files(), "2 of 4 files are absent (../shared/data): ");
    EXPECT_EQ(g_ran, 2) << "the files after a missing one still run";
    ASSERT_EQ(g_data.missing().size(), 2u);
    EXPECT_NE(g_data.reason().find("no-such-a.glb, "), std::string::npos) << g_data.reason();
    EXPECT_NE(g_data.reason().find("no-such-b.glb"), std::string::npos) << g_data.reason();
    EXPECT_FALSE(g_data.complete());

    test::DataFiles all_there;
    EXPECT_TRUE(all_there.present(std::filesystem::path(ANIMORDER_SOURCE_DIR) / "CMakeLists.txt"));
    EXPECT_TRUE(all_there.complete());
    if (before)
        ::setenv("ANIMORDER_REQUIRE", saved.c_str(), 1);
    else
        ::unsetenv("ANIMORDER_REQUIRE");
}
