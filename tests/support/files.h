// Small helpers shared by the tests that read files and run programs: reading a file whole (and
// one that must be there, to compare it), counting lines, a scratch folder per test, running a
// command with its output captured, and the Khronos glTF validator.
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

// The bytes of `path`, for a test that compares them: the test fails (at the caller's line, naming
// the path) when the file is missing or empty, since slurp's "" for an absent file would compare
// equal to another absent file's. A missing file reads as a text naming it, never as "".
inline std::string slurp_existing(const std::filesystem::path& path, const char* file = __builtin_FILE(),
                                  int line = __builtin_LINE()) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
        ADD_FAILURE_AT(file, line) << path.string() << " is missing (or not a regular file)";
        return "(missing file " + path.string() + ")";
    }
    std::string bytes = slurp(path);
    if (bytes.empty()) ADD_FAILURE_AT(file, line) << path.string() << " is empty";
    return bytes;
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
        dir_ =
            std::filesystem::temp_directory_path() / (prefix_ + "-" + std::to_string(::getpid()) + "-" +
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
inline std::filesystem::path validator_modules() {
    return std::filesystem::path(ANIMORDER_SOURCE_DIR) / ".tools" / "node_modules";
}

// Whether the Khronos glTF validator (installed by scripts/install-deps.sh into .tools/) and node
// are there; `why` says what is missing. Pair it with ANIMORDER_REQUIRE_OR_SKIP("validator", ...).
inline bool validator_available(std::string& why) {
    if (!std::filesystem::exists(validator_modules() / "gltf-validator")) {
        why = "gltf-validator is not installed in " + validator_modules().string() + " (run scripts/install-deps.sh)";
        return false;
    }
    if (std::system("node --version >/dev/null 2>&1") != 0) {
        why = "node is not on the PATH (the glTF validator runs on it)";
        return false;
    }
    return true;
}

// Runs the validator on `file`: true when it reports no error; `report` gets its output. The
// output is captured in `scratch` (the test's own folder), never next to `file`, which may be
// read-only data.
inline bool validate_gltf(const std::filesystem::path& file, std::string& report,
                          const std::filesystem::path& scratch) {
    const std::filesystem::path script =
        std::filesystem::path(ANIMORDER_SOURCE_DIR) / "tools" / "validate" / "validate_gltf.js";
    std::string why;
    if (!validator_available(why)) {
        report = why;
        return false;
    }
    const std::filesystem::path out = scratch / (file.filename().string() + ".validator-report.json");
    const std::string command = "NODE_PATH='" + validator_modules().string() + "' node '" + script.string() + "' '" +
                                file.string() + "' > '" + out.string() + "' 2>&1";
    const int status = std::system(command.c_str());
    report = slurp(out);
    return status == 0;
}
#endif

}  // namespace animorder::test
