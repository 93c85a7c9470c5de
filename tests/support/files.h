// Small helpers shared by the tests that read files and run programs: reading a file whole,
// counting lines, a scratch folder per test, running a command with its output captured, and the
// Khronos glTF validator.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>

namespace animorder::test {

inline std::string slurp(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

inline size_t line_count(const std::string& text) {
    size_t n = 0;
    for (char c : text) n += c == '\n';
    return n;
}

struct Outcome {
    int exit_code = -1;
    std::string out, err;
};

// Runs `command` through the shell with stdout and stderr captured in files under `dir`.
inline Outcome run_captured(const std::string& command, const std::filesystem::path& dir) {
    const std::filesystem::path out = dir / "stdout.txt", err = dir / "stderr.txt";
    const int status = std::system((command + " >" + out.string() + " 2>" + err.string()).c_str());
    Outcome o;
    o.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    o.out = slurp(out);
    o.err = slurp(err);
    return o;
}

// A fixture with a fresh folder per test (temp/PREFIX-PID-TEST), removed afterwards.
class ScratchFolderTest : public ::testing::Test {
protected:
    explicit ScratchFolderTest(std::string prefix) : prefix_(std::move(prefix)) {}
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               (prefix_ + "-" + std::to_string(::getpid()) + "-" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::remove_all(dir_);
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }
    std::filesystem::path path(const std::string& name) const { return dir_ / name; }

    std::string prefix_;
    std::filesystem::path dir_;
};

#ifdef ANIMORDER_SOURCE_DIR
// Runs the Khronos glTF validator (installed by scripts/install-deps.sh into .tools/) on `file`:
// true when it reports no error; `report` gets its output or why it could not run.
inline bool validate_gltf(const std::filesystem::path& file, std::string& report) {
    const std::filesystem::path tools = std::filesystem::path(ANIMORDER_SOURCE_DIR) / ".tools" / "node_modules";
    const std::filesystem::path script =
        std::filesystem::path(ANIMORDER_SOURCE_DIR) / "tools" / "validate" / "validate_gltf.js";
    if (!std::filesystem::exists(tools / "gltf-validator")) {
        report = "gltf-validator is not installed (run scripts/install-deps.sh)";
        return false;
    }
    const std::filesystem::path out = file.string() + ".report";
    const std::string command = "NODE_PATH='" + tools.string() + "' node '" + script.string() + "' '" + file.string() +
                                "' > '" + out.string() + "' 2>&1";
    const int status = std::system(command.c_str());
    report = slurp(out);
    return status == 0;
}
#endif

}  // namespace animorder::test
