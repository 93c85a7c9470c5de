// Production scale (issue 19's goals): wall time and peak memory of the whole-set runs, each case
// in a child process of its own so its peak resident set (wait4's ru_maxrss) is its own, then the
// scoring engine against llvmpipe from bench_overdraw in the same run. A plain runner, never a test.
// Default protocol: 162 views, 256², k = 5, λ = 0.85, all cores (2 here).
//
//   build/bench/bench_scale                    every case (heavy: minutes, gigabytes)
//   build/bench/bench_scale clip60-single      one case (names below); --quick: tiny settings, a smoke run
//
// Cases and their goals:
//   ganfaul-joint   Ganfaul, joint over all 12 clips          <= 120 s, <= 3 GB
//   xbot-single     Xbot, single over every clip              <= 12 s,  <= 0.7 GB
//   clip60-single   Ganfaul Idle (13.8k triangles, 60 keyframes), single   <= 2.5 s
//   engine-ratio    bench_overdraw's engine vs llvmpipe, 5 orders per node  >= 40x
// Data from ../shared/data beside the repository (or $ANIMORDER_DATA); a case without its file
// says so and is skipped.
#include "animorder/load.h"
#include "animorder/methods.h"

#include "machine.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

using namespace animorder;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

struct Case {
    const char* name;
    const char* file;                // under the data folder
    std::vector<std::string> clips;  // empty: all
    Method method;
    const char* goal;
};

const std::vector<Case> kCases = {
    {"ganfaul-joint", "mixamo-ganfaul/Ganfaul.gltf", {}, Method::Joint, "<= 120 s, <= 3 GB"},
    {"xbot-single", "glb-xbot/Xbot.glb", {}, Method::Single, "<= 12 s, <= 0.7 GB"},
    {"clip60-single", "mixamo-ganfaul/Ganfaul.gltf", {"Idle"}, Method::Single, "<= 2.5 s"},
};

fs::path data_folder() {
    if (const char* d = std::getenv("ANIMORDER_DATA")) return d;
    return fs::path(ANIMORDER_SOURCE_DIR).parent_path() / "shared" / "data";
}

// In the child: load, run, print one line; exit code 0 when it ran.
int run_case(const Case& c, bool quick) {
    const fs::path file = data_folder() / c.file;
    if (!fs::exists(file)) {
        std::printf("%-14s skipped: %s is absent\n", c.name, file.string().c_str());
        return 0;
    }
    const Clock::time_point start = Clock::now();
    LoadOptions options;  // as `animorder optimize --clip`: only the case's clips are sampled
    options.clips = c.clips;
    AnimatedMesh mesh = load_character(file.string(), {}, options);
    if (!c.clips.empty())
        mesh = select_clips(mesh, c.clips);
    else if (quick && mesh.clips.size() > 2)
        mesh = select_clips(mesh, {mesh.clips[0].name, mesh.clips[1].name});
    const double load_s = std::chrono::duration<double>(Clock::now() - start).count();
    MethodSettings settings;  // the library's defaults: the protocol
    if (quick) {
        settings.clustering.views = 12;
        settings.clustering.resolution = 64;
        settings.clustering.clusters = 2;
        settings.clustering.max_iterations = 1;
    }
    const MethodResult r = run_method(mesh, c.method, settings);
    const double total_s = std::chrono::duration<double>(Clock::now() - start).count();
    size_t nodes = 0;
    for (const ClusteringResult& run : r.runs) nodes += run.assignment.size();
    std::printf("%-14s %6zu triangles %3zu clips %5zu keyframes %7zu nodes  load %.1f s  method %.1f s  total %.1f s",
                c.name, mesh.triangle_count(), mesh.clips.size(), mesh.keyframe_count(), nodes, load_s, r.seconds,
                total_s);
    std::fflush(stdout);
    return 0;
}

// bench_overdraw in a child; its lines are relayed (the "ratio" one is the goal's figure).
void engine_ratio() {
    const std::string command = std::string(BENCH_OVERDRAW_EXE) + " 2>&1";
    std::FILE* pipe = ::popen(command.c_str(), "r");
    if (!pipe) {
        std::printf("engine-ratio   cannot start %s\n", BENCH_OVERDRAW_EXE);
        return;
    }
    char line[1024];
    while (std::fgets(line, sizeof line, pipe))
        if (std::strstr(line, "ratio") || std::strstr(line, "OpenGL") || std::strstr(line, "orders per node"))
            std::printf("engine-ratio   %s", line);
    const int status = ::pclose(pipe);
    std::printf("engine-ratio   goal >= 40x (bench_overdraw exit status %d)\n", status);
}

}  // namespace

int main(int argc, char** argv) {
    bool quick = false;
    std::vector<std::string> wanted;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--quick") == 0)
            quick = true;
        else
            wanted.push_back(argv[i]);
    }
    auto selected = [&](const std::string& name) {
        if (wanted.empty()) return true;
        for (const std::string& w : wanted)
            if (w == name) return true;
        return false;
    };
    for (const std::string& w : wanted) {
        bool known = w == "engine-ratio";
        for (const Case& c : kCases) known = known || w == c.name;
        if (!known) {
            std::fprintf(stderr,
                         "bench_scale: unknown case '%s' (ganfaul-joint, xbot-single, clip60-single, engine-ratio)\n",
                         w.c_str());
            return 1;
        }
    }
    std::printf("machine: %s\n", animorder::bench::machine_description().c_str());
    std::printf("bench_scale: %s; data %s\n",
                quick
                    ? "QUICK smoke settings (12 views, 64^2, k 2, 1 iteration, at most 2 clips): not the goals' figures"
                    : "default protocol (162 views, 256^2, k = 5, lambda 0.85, all cores)",
                data_folder().string().c_str());
    std::fflush(stdout);
    for (const Case& c : kCases) {
        if (!selected(c.name)) continue;
        const pid_t child = fork();
        if (child < 0) {
            std::perror("fork");
            return 1;
        }
        if (child == 0) {
            try {
                _exit(run_case(c, quick));
            } catch (const std::exception& e) {
                std::printf("%-14s failed: %s", c.name, e.what());
                std::fflush(stdout);
                _exit(2);
            }
        }
        int status = 0;
        struct rusage usage {};
        const Clock::time_point start = Clock::now();
        wait4(child, &status, 0, &usage);
        const double wall = std::chrono::duration<double>(Clock::now() - start).count();
        // ru_maxrss is in KiB on Linux: the child's own peak resident set.
        std::printf("  wall %.1f s  peak RSS %.2f GB  (goal %s)\n", wall, double(usage.ru_maxrss) * 1024.0 / 1e9,
                    c.goal);
        std::fflush(stdout);
    }
    if (selected("engine-ratio") && !quick) engine_ratio();
    return 0;
}
