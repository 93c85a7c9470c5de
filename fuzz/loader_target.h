// Shared by the loader fuzz targets: the bytes go to a file in a scratch folder of this process
// ($TMPDIR, else /dev/shm, else /tmp; removed at exit) and the loader reads it. LoadError and
// InvalidInput are the expected answers to bad bytes; anything else (another exception, a
// crash, a sanitizer report) is a finding. The keyframe budget is small so that a file claiming
// a huge animation is refused by the loader's own check, not by the fuzzer's memory limit.
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/gltf_loader.h"
#include "animorder/invalid_input.h"
#include "animorder/iqm_loader.h"
#include "animorder/load.h"
#include "animorder/md2_loader.h"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace animorder_fuzz {

inline const std::filesystem::path& scratch() {
    static const std::filesystem::path dir = [] {
        const char* base = std::getenv("TMPDIR");
        std::string root = base && *base ? base : (std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp");
        std::string tmpl = root + "/animorder-fuzz-XXXXXX";
        if (!mkdtemp(tmpl.data())) {
            std::perror("animorder fuzz: mkdtemp");
            std::abort();
        }
        std::atexit([] {
            std::error_code ec;
            std::filesystem::remove_all(scratch(), ec);
        });
        return std::filesystem::path(tmpl);
    }();
    return dir;
}

inline std::string write_input(const uint8_t* data, size_t size, const std::string& name) {
    const std::string path = (scratch() / name).string();
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f || (size && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
        std::perror("animorder fuzz: writing the input");
        std::abort();
    }
    return path;
}

inline animorder::LoadOptions options() {
    animorder::LoadOptions o;
    o.max_keyframe_bytes = size_t(64) << 20;
    return o;
}

// Runs load(path, options) and checks what it returns: a valid mesh, or an expected error.
template <class Load>
void run_loader(Load load, const std::string& path) {
    try {
        const animorder::AnimatedMesh mesh = load(path, options());
        animorder::validate_animated_mesh(mesh);  // a loaded mesh must keep its own invariants
    } catch (const animorder::LoadError&) {
    } catch (const animorder::InvalidInput&) {}
}

}  // namespace animorder_fuzz
