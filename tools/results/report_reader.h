// make_results' typed view of RESULTS_DIR (report_reader.cpp): the `animorder evaluate --report`
// files (Report), bench/render_time's --json file (RenderTime), the benchmarks' *.txt output and
// the lead's notes-<section>.md, every field read and checked before anything is written. A
// malformed file throws std::runtime_error naming the file and the key ("sweep-k.json:
// methods[2].acmr: expected a number, got string"). Optional numbers left out or null read as NaN
// (counts as -1), so the sections write "—" for them.
#pragma once

#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace animorder::results {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One clip's numbers of a method (methods[i].per_clip[c]).
struct ClipResult {
    std::string clip;
    double ovr_mean = kNaN, ovr_pooled = kNaN, time_s = kNaN;
    long long nodes = -1;
};

// The blend error of an order over a report's nodes (issue 18: methods[i].blend,
// blend_input_order, blend_bound); present only for inputs with blended primitives.
struct BlendResult {
    bool present = false;
    double missorted_pair_fraction = kNaN, missorted_pixel_fraction = kNaN;
    long long pairs = -1, covered_pixels = -1, nodes = -1;
};

// One row of a report's methods: a method at one setting (λ, k, views).
struct Method {
    std::string name;
    double lambda = kNaN;  // NaN: the method does not use it (null)
    long long clusters = -1, views = -1;
    long long buffers = 0;
    double acmr = kNaN, atvr = kNaN, ovr_mean = kNaN, ovr_pooled = kNaN, time_s = kNaN;
    double peak_rss_bytes = kNaN;  // the process's peak while the method ran (absent in older reports)
    std::vector<ClipResult> per_clip;
    std::map<std::string, size_t> iterations;  // k-means iterations per run ("all" for joint)
    BlendResult blend;
    std::map<std::string, double> stages;  // stages_s: seconds per preprocessing stage (clustered methods)
};

struct Clip {
    std::string name;
    long long keyframes = 0;
};

// An `animorder evaluate --report` file.
struct Report {
    std::string file, input;
    long long triangles = -1, vertices = -1, nodes = -1, threads = -1;
    bool blend_clusters = false;  // settings.blend_clusters: k-means buffers with their own blend clusters
    bool single_sided = false;    // settings.single_sided: every material culled (evaluate --single-sided)
    long long eval_views = -1, eval_resolution = -1, eval_seed = -1, resolution = -1, seed = -1, cache_size = -1;
    std::vector<double> lambdas;
    std::vector<long long> clusters, views;
    std::vector<Clip> clips;
    std::vector<Method> methods;
    double t_methods = kNaN, t_evaluation = kNaN, t_total = kNaN;
    BlendResult blend_input_order, blend_bound;
};

// A `bench/render_time --json` file.
struct RenderTime {
    struct Row {
        std::string name;
        double ovr = kNaN, seconds = kNaN;
        long long buffers = -1;
    };
    std::string input, renderer;
    long long nodes = -1, resolution = -1, shader_iterations = -1, triangles = -1, views = -1, keyframe_stride = -1,
              repeats = -1;
    std::vector<Row> methods;
    double time_ratio = kNaN, ovr_ratio = kNaN, correlation = kNaN, unshaded_seconds = kNaN;
};

// The ids a notes-<id>.md may name, one per section of RESULTS.md.
extern const std::vector<std::string> kSectionIds;

// Everything in RESULTS_DIR that make_results reads.
struct Inputs {
    std::map<std::string, Report> reports;         // by file name (relative to RESULTS_DIR)
    std::vector<std::string> characters;           // "characters/x.json", sorted
    std::vector<std::string> materials;            // "materials/x.json", sorted
    std::vector<std::string> measured_characters;  // "measured/x.json" but the three Ganfaul ones, sorted
    std::unique_ptr<RenderTime> render_time;
    std::map<std::string, std::string> texts;  // *.txt by name, sorted
    std::map<std::string, std::string> notes;  // section id -> notes-<id>.md (templates.h)
    std::string readme;                        // readme.md of the notes folder: README.md's generated block
    bool has_readme = false;
    const Report* get(const std::string& name) const;
};

// Reads and checks every known file of `dir` (every one optional), and the notes-<id>.md and
// readme.md of `notes_dir`; throws std::runtime_error on the first malformed one. A notes file
// naming no section is ignored with a line on stderr.
Inputs load_inputs(const std::filesystem::path& dir, const std::filesystem::path& notes_dir);

}  // namespace animorder::results
