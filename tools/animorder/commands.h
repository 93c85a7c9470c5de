// The subcommands of the animorder tool. Each returns the process exit code.
#pragma once

#include "animorder/animated_mesh.h"

#include <cstdint>
#include <string>
#include <vector>

namespace animorder::tool {

struct CommonOptions {
    std::string input;   // empty: the bundled procedural character
    bool quiet = false;  // no progress on stderr
    std::vector<std::string> clips;  // --clip: only these clips (all when empty)
    unsigned cache_size = 16;
};

struct InspectOptions {
    CommonOptions common;
    bool json = false;
};

// Settings of the methods (DESIGN.md names), shared by optimize and evaluate.
struct MethodOptions {
    double lambda = 0.85;
    size_t keyframe = 0;  // static-sander07: the keyframe whose positions it sorts with
    size_t clusters = 5;  // single / joint: k
    size_t views = 162;
    unsigned resolution = 256;
    uint64_t seed = 1;
    double min_separation = 30;
    size_t max_iterations = 30;
    std::string distance = "jcgt";
    std::string update = "monotone";
    unsigned threads = 0;
    // static-nehab06: clusters (0: automatic), measuring views, and whether 8 keyframes spread over
    // the clips are measured too (default: the --frame keyframe only).
    size_t nehab_clusters = 0;
    size_t nehab_views = 162;
    bool nehab_all_keyframes = false;
    // evaluate only: every value of each list is run (methods that use it get a row per value).
    std::vector<double> lambdas;
    std::vector<size_t> cluster_list;
    std::vector<size_t> view_list;
};

struct OptimizeOptions {
    CommonOptions common;
    std::string method = "static-sander07";
    bool joint = false;       // --joint: the same as --method joint
    MethodOptions settings;
    std::string output;       // OUT → OUT.animorder.bin and OUT.animorder.json
    std::string report_path;  // JSON report, optional
};

struct EvaluateOptions {
    CommonOptions common;
    std::string methods = "original,static-sander07,single";
    MethodOptions settings;
    size_t views = 300;
    unsigned resolution = 512;
    uint64_t seed = 20170501;
    std::string report_path;
    std::string csv_path;
};

struct HeatmapOptions {
    CommonOptions common;
    std::string method = "original";
    double lambda = 0.85;
    std::vector<float> view = {0.3f, 0.2f, 1.0f};  // direction from the character to the camera
    size_t keyframe = 0;
    unsigned resolution = 512;
    std::string output;
};

// Progress and notes go to stderr ("animorder: TEXT"), unless --quiet.
void note(const CommonOptions& common, const std::string& text);
// The input named on the command line (or the bundled character, saying so). --clip values that
// exist on disk are clip files or folders (Mixamo style); the others name the clips to keep.
AnimatedMesh load_animated_input(const CommonOptions& common, std::string& input_name);

int run_inspect(const InspectOptions& options);
int run_optimize(const OptimizeOptions& options);
int run_evaluate(const EvaluateOptions& options);
int run_heatmap(const HeatmapOptions& options);

}  // namespace animorder::tool
