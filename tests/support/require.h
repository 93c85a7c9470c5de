// Prerequisites of a test that a machine may lack (an OpenGL context, the Khronos glTF validator,
// the real characters of ../shared/data, strace, PID namespaces, ...): without one, the test is
// skipped with the reason, so the skip shows in the CTest summary; and where the environment
// variable ANIMORDER_REQUIRE names the component (a comma list of kComponents below, or all), the
// test fails with the reason instead. .ci/run names every component CI has, so CI cannot pass by
// skipping. A test calls GTEST_SKIP itself only for what CI may lack too (the CPU's AVX2).
//
//   ANIMORDER_REQUIRE_OR_SKIP("data", fs::exists(path), path + " is absent");
//
// Use it in a test body (it returns from the function: GTEST_SKIP and FAIL do).
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <sstream>
#include <string>
#include <vector>

namespace animorder::test {

// The components a test can require; anything else in ANIMORDER_REQUIRE is a typo, and fails.
//   gl          an OpenGL context (Mesa's llvmpipe over EGL will do)
//   validator   the Khronos glTF validator (node, .tools/)
//   data        the real characters of ../shared/data
//   results     the committed results/ tables
//   gltf-tools  gltfpack, glTF-Transform, gltf-pipeline, python3-jsonschema
//   node        Node.js
//   browser     headless Chromium and the viewer's npm packages
//   strace      strace, with fault injection (-e inject=...:delay_enter=)
//   namespaces  unshare -p -f --mount-proc (util-linux; root): a PID namespace
//   root        running as root (files of another user, setresuid)
//   proc        /proc mounted
//   slurm       a one-node SLURM started in a scratch folder (slurm-wlm, munge; tests/tool/one-node-slurm.sh)
//   python      the Python module built, with Debian's python3-numpy and python3-pytest (scripts/test-python.sh)
inline constexpr const char* kComponents[] = {"gl",     "validator",  "data", "results", "gltf-tools", "node",
                                              "browser", "strace", "namespaces", "root",    "proc",       "slurm",
                                              "python"};

inline bool known_component(const std::string& name) {
    for (const char* c : kComponents)
        if (name == c) return true;
    return false;
}

inline std::string known_components() {
    std::string list;
    for (const char* c : kComponents) list += std::string(c) + ", ";
    return list + "all";
}

// Whether `requirement` (ANIMORDER_REQUIRE's value; null when unset) requires `component`.
// Unknown names in the list are reported as failures of the calling test.
inline bool requires_component(const char* requirement, const std::string& component) {
    if (!known_component(component)) {
        ADD_FAILURE() << "test code asks for an unknown prerequisite '" << component << "'";
        return true;
    }
    if (!requirement) return false;
    bool found = false;
    std::stringstream list(requirement);
    std::string item;
    while (std::getline(list, item, ',')) {
        const size_t first = item.find_first_not_of(" \t"), last = item.find_last_not_of(" \t");
        item = first == std::string::npos ? "" : item.substr(first, last - first + 1);
        if (item.empty()) continue;
        if (item == "all" || item == component)
            found = true;
        else if (!known_component(item))
            ADD_FAILURE() << "ANIMORDER_REQUIRE names an unknown component '" << item
                          << "' (known: " << known_components() << ")";
    }
    return found;
}

inline bool required(const std::string& component) {
    return requires_component(std::getenv("ANIMORDER_REQUIRE"), component);
}

// ../shared/data/RELATIVE, the real characters (read only: tests never write there).
inline std::filesystem::path shared_data_path(const std::string& relative = "") {
#ifdef ANIMORDER_SOURCE_DIR
    return std::filesystem::path(ANIMORDER_SOURCE_DIR) / ".." / "shared" / "data" / relative;
#else
    return std::filesystem::path("..") / "shared" / "data" / relative;
#endif
}

// The files of ../shared/data a loop over characters reads. Every listed file is checked: a missing
// one is recorded and the loop goes on with the rest (`continue`); after the loop,
// ANIMORDER_REQUIRE_ALL_DATA skips naming every missing file, or fails where data is required. A
// skip inside the loop left every character after the first absent one unchecked.
//
//   test::DataFiles data;
//   for (const char* f : files) {
//       if (!data.present(test::shared_data_path(f))) continue;
//       ...
//   }
//   ANIMORDER_REQUIRE_ALL_DATA(data);
class DataFiles {
public:
    // Whether every one of `paths` exists; those that do not are recorded.
    bool present(std::initializer_list<std::filesystem::path> paths) {
        bool all = true;
        for (const std::filesystem::path& p : paths) {
            ++checked_;
            if (!std::filesystem::exists(p)) {
                missing_.push_back(p.lexically_normal().string());
                all = false;
            }
        }
        return all;
    }
    bool present(const std::filesystem::path& path) { return present({path}); }

    bool complete() const { return missing_.empty(); }
    const std::vector<std::string>& missing() const { return missing_; }
    // "2 of 9 files are absent (../shared/data): A, B"
    std::string reason() const {
        std::string list;
        for (const std::string& m : missing_) list += (list.empty() ? "" : ", ") + m;
        return std::to_string(missing_.size()) + " of " + std::to_string(checked_) +
               " files are absent (../shared/data): " + list;
    }

private:
    std::vector<std::string> missing_;
    size_t checked_ = 0;
};

}  // namespace animorder::test

// Skips the test with `reason` when `condition` is false, or fails it when ANIMORDER_REQUIRE
// requires `component`.
#define ANIMORDER_REQUIRE_OR_SKIP(component, condition, reason)                                        \
    do {                                                                                               \
        /* read first, so a typo in ANIMORDER_REQUIRE fails even where everything is present */        \
        const bool animorder_required_ = ::animorder::test::required(component);                       \
        if (!(condition)) {                                                                            \
            if (animorder_required_)                                                                   \
                FAIL() << "required " << (component) << " (ANIMORDER_REQUIRE) is missing: " << reason; \
            else                                                                                       \
                GTEST_SKIP() << (component) << " missing: " << reason;                                 \
        }                                                                                              \
    } while (0)

// Skips (or fails, when data is required) unless the file or folder DATA_PATH of ../shared/data exists.
#define ANIMORDER_REQUIRE_DATA(data_path)                                 \
    ANIMORDER_REQUIRE_OR_SKIP("data", std::filesystem::exists(data_path), \
                              std::filesystem::path(data_path).string() + " is absent (../shared/data)")

// After a loop over characters: skips naming every file test::DataFiles found missing (or fails,
// when data is required); nothing when all were there.
#define ANIMORDER_REQUIRE_ALL_DATA(data_files) \
    ANIMORDER_REQUIRE_OR_SKIP("data", (data_files).complete(), (data_files).reason())
