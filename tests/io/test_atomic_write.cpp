// OutputSet and check_output_paths (src/io/atomic_write.cpp): a signal leaves no temporary, a
// folder no file can be created in is refused up front (even for root, whom access() lets write
// anywhere), and so is an output a sticky folder does not let this user replace.
#include <gtest/gtest.h>

#include "animorder/atomic_write.h"
#include "support/files.h"
#include "support/require.h"

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <set>
#include <string>

namespace fs = std::filesystem;
namespace test = animorder::test;
using animorder::OutputError;
using animorder::OutputSet;

namespace {

class AtomicWrite : public test::ScratchFolderTest {
protected:
    AtomicWrite() : ScratchFolderTest("animorder-atomic-write") {}
    std::string entries() const {
        std::string names;
        for (const auto& e : fs::directory_iterator(dir_)) names += e.path().filename().string() + " ";
        return names;
    }
};

// The wait status of a child process that runs `body`, then exits with 0 (unless body ends it).
int status_of_child(const std::function<void()>& body) {
    const pid_t child = ::fork();
    if (child < 0) return -1;
    if (child == 0) {
        body();
        ::_exit(0);
    }
    int status = -1;
    return ::waitpid(child, &status, 0) == child ? status : -1;
}

}  // namespace

// A run interrupted (Ctrl-C, a farm's SIGTERM) between writing its temporaries and putting them in
// place leaves nothing behind, and still ends as killed by the signal.
TEST_F(AtomicWrite, ASignalRemovesTheTemporariesAndStillKills) {
    for (const int sig : {SIGTERM, SIGINT, SIGHUP}) {
        const int status = status_of_child([&] {
            ::signal(sig, SIG_DFL);  // as a run gets it (under nohup, SIGHUP comes ignored, and stays so)
            OutputSet files;
            files.add(path("a.bin").string(), std::string(100000, 'a'));
            files.add(path("b.json").string(), "{}");
            ::raise(sig);  // its default action ends the process
        });
        EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << "signal " << sig << ", status " << status;
        EXPECT_EQ(entries(), "") << "signal " << sig << " left files behind";
    }
}

// A process that wrote outputs before forking: the child's own temporaries are still removed on a
// signal (each temporary is the process's that made it), and the parent's outputs stay.
TEST_F(AtomicWrite, AForkedChildRemovesItsOwnTemporaries) {
    animorder::write_file_atomically(path("parent.json").string(), "{}");
    const int status = status_of_child([&] {
        OutputSet files;
        files.add(path("child.bin").string(), "c");
        ::raise(SIGTERM);
    });
    EXPECT_TRUE(WIFSIGNALED(status));
    EXPECT_EQ(entries(), "parent.json ");
}

// What the handler must not do: remove the outputs once they are in place.
TEST_F(AtomicWrite, ASignalAfterTheCommitKeepsTheOutputs) {
    const int status = status_of_child([&] {
        OutputSet files;
        files.add(path("a.bin").string(), "a");
        files.commit();
        ::raise(SIGTERM);
    });
    EXPECT_TRUE(WIFSIGNALED(status));
    EXPECT_EQ(entries(), "a.bin ");
}

// A temporary's name cannot be guessed, and it is created as a new file, never through a link:
// links planted under the names earlier versions used (".NAME.tmpPID", ".NAME.oldPID": a
// container's PID is 1) lead nowhere, the file they point at is untouched, and the output is a
// file of its own. Two runs writing one target in the same process use different temporaries.
TEST_F(AtomicWrite, APlantedLinkCannotRedirectAnOutput) {
    const fs::path victim = path("victim.txt");
    std::ofstream(victim) << "precious";
    std::ofstream(path("out.glb")) << "old output";  // so the commit makes a backup too
    const std::string pid = std::to_string(::getpid());
    for (const std::string kind : {"tmp", "old"}) fs::create_symlink(victim, path(".out.glb." + kind + pid));
    OutputSet first, second;
    first.add(path("out.glb").string(), "new output");
    second.add(path("out.glb").string(), "other output");
    const std::regex temporary("\\.out\\.glb\\.tmp" + pid + "-[0-9a-f]{16}");
    std::set<std::string> temporaries;
    for (const auto& e : fs::directory_iterator(dir_)) {
        const std::string name = e.path().filename().string();
        if (!std::regex_match(name, temporary)) continue;
        temporaries.insert(name);
        EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(e.path()))) << name << " is not a file of its own";
    }
    EXPECT_EQ(temporaries.size(), 2u) << "in the folder: " << entries();
    first.commit();
    EXPECT_EQ(test::slurp(victim), "precious");
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(path("out.glb"))));
    EXPECT_EQ(test::slurp(path("out.glb")), "new output");
    for (const std::string kind : {"tmp", "old"}) EXPECT_TRUE(fs::is_symlink(path(".out.glb." + kind + pid)));
}

// /proc lets no file be created, yet access(W_OK) says yes to root: refused before any work.
TEST_F(AtomicWrite, AFolderNoFileCanBeCreatedInIsRefused) {
    ANIMORDER_REQUIRE_OR_SKIP("proc", fs::is_directory("/proc/self"), "no /proc on this system");
    try {
        animorder::check_output_paths({"/proc/animorder-output.json"}, {});
        FAIL() << "an output in /proc was accepted";
    } catch (const OutputError& e) {
        EXPECT_NE(std::string(e.what()).find("not writable"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW(animorder::check_output_paths({path("fine.json").string()}, {}));
    EXPECT_EQ(entries(), "") << "the check leaves no file";
}

// In a sticky folder (like /tmp) only a file's owner may replace it: known at the check, not at
// the commit after the work. Needs root, to make a file of another user.
TEST_F(AtomicWrite, AnotherUsersFileInAStickyFolderIsRefusedAtTheCheck) {
    ANIMORDER_REQUIRE_OR_SKIP("root", ::geteuid() == 0, "not root: a file of another user cannot be made");
    const fs::path sticky = path("sticky");
    fs::create_directory(sticky);
    ASSERT_EQ(::chmod(sticky.c_str(), 01777), 0);
    std::ofstream(sticky / "theirs.json") << "{}";
    const int status = status_of_child([&] {  // as nobody (65534): the file is root's
        if (::setresgid(65534, 65534, 65534) != 0 || ::setresuid(65534, 65534, 65534) != 0) ::_exit(3);
        try {
            animorder::check_output_paths({(sticky / "mine.json").string()}, {});  // a new file: fine
        } catch (const OutputError&) {
            ::_exit(4);
        }
        try {
            animorder::check_output_paths({(sticky / "theirs.json").string()}, {});
        } catch (const OutputError& e) {
            ::_exit(std::string(e.what()).find("another user") != std::string::npos ? 0 : 2);
        }
        ::_exit(1);
    });
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0) << "1: accepted; 2: refused for another reason; 3: no user switch; 4: a new "
                                         "file refused";
    EXPECT_TRUE(fs::exists(sticky / "theirs.json"));
}

// A commit renames over its target: a device (-r /dev/full), a FIFO or a link would have become a
// plain file, for every other user of it too. Refused at the check, and left as it was.
TEST_F(AtomicWrite, AnOutputThatIsNoRegularFileIsRefused) {
    ASSERT_EQ(::mkfifo(path("fifo").c_str(), 0600), 0);
    std::ofstream(path("target.json")) << "{}";
    fs::create_symlink(path("target.json"), path("link.json"));
    const std::pair<std::string, std::string> cases[] = {
        {path("fifo").string(), "a FIFO"}, {path("link.json").string(), "a symbolic link"}, {"/dev/null", "a device"}};
    for (const auto& [output, what] : cases) {
        try {
            animorder::check_output_paths({output}, {});
            ADD_FAILURE() << output << " was accepted";
        } catch (const OutputError& e) {
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
        }
    }
    EXPECT_TRUE(fs::is_fifo(path("fifo")));
    EXPECT_TRUE(fs::is_symlink(path("link.json")));
    EXPECT_TRUE(fs::is_character_file("/dev/null"));
}

// What killed runs left: a temporary of a process that is gone goes at once; one whose process id
// names a live process (PID 1 always does: a container's killed first process, seen from a
// volume another machine shares) stays while it may be written, and goes once its inode has not
// changed for an hour (a temporary lives seconds). A backup whose target is missing stays.
TEST_F(AtomicWrite, LeftOverTemporariesGoOnceTheirProcessIsGoneOrAnHourHasPassed) {
    const std::string target = path("out.glb").string();
    std::ofstream(target) << "result";
    const pid_t gone = [] {
        const pid_t child = ::fork();
        if (child == 0) ::_exit(0);
        ::waitpid(child, nullptr, 0);
        return child;
    }();
    const std::string random = "-0123456789abcdef";
    for (const std::string& name : {".out.glb.tmp" + std::to_string(gone), ".out.glb.tmp" + std::to_string(gone) + random,
                                    ".out.glb.old" + std::to_string(gone) + random, std::string(".out.glb.tmp1"),
                                    std::string(".out.glb.old1"), std::string(".other.glb.old1"),
                                    ".out.glb.tmp" + std::to_string(gone) + "-not-ours"})
        std::ofstream(path(name)) << "left";
    animorder::remove_stale_temporaries(target);
    EXPECT_FALSE(fs::exists(path(".out.glb.tmp" + std::to_string(gone))));
    EXPECT_FALSE(fs::exists(path(".out.glb.tmp" + std::to_string(gone) + random)));
    EXPECT_FALSE(fs::exists(path(".out.glb.old" + std::to_string(gone) + random)));
    EXPECT_TRUE(fs::exists(path(".out.glb.tmp" + std::to_string(gone) + "-not-ours"))) << "a name not of ours went";
    EXPECT_TRUE(fs::exists(path(".out.glb.tmp1")));  // PID 1 runs: it may be writing it now
    EXPECT_TRUE(fs::exists(path(".out.glb.old1")));
    const std::time_t later = std::time(nullptr) + 3601 + 5;
    animorder::remove_stale_temporaries(path("other.glb").string(), later);  // its target is missing
    EXPECT_TRUE(fs::exists(path(".other.glb.old1")));
    animorder::remove_stale_temporaries(target, later);
    EXPECT_FALSE(fs::exists(path(".out.glb.tmp1")));
    EXPECT_FALSE(fs::exists(path(".out.glb.old1")));
}
