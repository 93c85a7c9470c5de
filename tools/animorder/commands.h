// The subcommands of the animorder tool, one source each (inspect.cpp, optimize.cpp,
// evaluate.cpp, heatmap.cpp, subdivide.cpp), and their options. Option defaults are the
// library's (MethodSettings, EvaluationSettings, LoadOptions): the tool spells none of its own.
// Each run_* returns the process exit code and throws for an error (main.cpp prints it).
#pragma once

#include "animorder/evaluation.h"
#include "animorder/load.h"
#include "animorder/methods.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace animorder::tool {

struct CommonOptions {
    std::string input;               // empty: the bundled procedural character
    bool quiet = false;              // no progress on stderr
    std::vector<std::string> clips;  // --clip: only these clips (all when empty), or clip files
    // batch: a clip is a file iff its path is absolute (the manifest's clip files are resolved so),
    // whatever the current folder holds; otherwise a clip is a file iff it exists (clip_is_file).
    bool clip_files_absolute = false;
    unsigned cache_size = kDefaultCacheSize;
    size_t max_memory = LoadOptions{}.max_keyframe_bytes;  // --max-memory: the loading budget in bytes
    unsigned threads = 0;  // threads that sample the keyframes (0: all cores): the command's --threads
};

// The settings of the methods, shared by optimize and evaluate: the library's MethodSettings,
// the k-means variants by name, and (evaluate only) lists that run every value.
struct MethodOptions {
    MethodSettings settings;
    std::string distance = distance_name(ClusteringSettings{}.distance);
    std::string update = update_name(ClusteringSettings{}.update);
    std::vector<double> lambdas;
    std::vector<size_t> cluster_list;
    std::vector<size_t> view_list;
};

struct InspectOptions {
    CommonOptions common;
    bool json = false;
};

struct OptimizeOptions {
    CommonOptions common;
    std::string method = method_name(kDefaultMethod);
    bool joint = false;  // --joint: the method's joint variant (method_joint_variant)
    MethodOptions methods;
    std::string output;       // OUT → OUT.animorder.bin and OUT.animorder.json (+ OUT.glb/.gltf)
    std::string report_path;  // JSON report, optional
};

struct EvaluateOptions {
    CommonOptions common;
    std::string methods = "original,static-sander07,single,measured";
    MethodOptions method_options;
    EvaluationSettings evaluation;  // views, seed, resolution (threads from --threads)
    std::string report_path;
    std::string csv_path;
    bool stored = false;        // --stored: also the orders stored in INPUT (ANIMORDER_animated_triangle_orders)
    bool single_sided = false;  // --single-sided: every material culled, as before issue 18 (its cost)
};

struct HeatmapOptions {
    CommonOptions common;
    std::string method = method_name(Method::Original);
    double lambda = kDefaultLambda;
    std::vector<float> view = {0.3f, 0.2f, 1.0f};  // direction from the character to the camera
    size_t keyframe = 0;
    unsigned resolution = EvaluationSettings{}.resolution;
    std::string output;
    bool blend = false;  // mis-sorted blended pairs per pixel instead of overdraw (issue 18)
};

struct SubdivideOptions {
    CommonOptions common;
    unsigned levels = 1;
    std::string output;  // OUT.glb or OUT.gltf
};

struct ViewOptions {
    CommonOptions common;     // input: the glb to show (empty: the bundled character, optimised)
    std::string original;     // --original: the un-optimised file, for the page's comparison
    unsigned port = 8417;     // 0: any free port
    bool open = true;         // start the default browser
    unsigned seconds = 0;     // stop after this long (0: until interrupted)
    std::string viewer_root;  // the folder holding viewer/ and js/ (default: the source tree)
};

struct CheckOptions {
    std::string file;    // a glTF/GLB file with (or without) ANIMORDER_animated_triangle_orders
    bool quiet = false;  // no error line on stderr (the JSON report still says it)
};

struct ReapplyOptions {
    std::string optimized, processed, output;
    double tolerance = 1e-3;  // corner distance allowed, as a fraction of OPTIMIZED's bounding-box diagonal
    double nearest = 0;       // > 0: unmatched triangles placed by the nearest optimised one within this fraction
    size_t max_memory = LoadOptions{}.max_keyframe_bytes;
    bool quiet = false;
};

int run_inspect(const InspectOptions& options);
int run_optimize(const OptimizeOptions& options);
int run_evaluate(const EvaluateOptions& options);
int run_heatmap(const HeatmapOptions& options);
int run_subdivide(const SubdivideOptions& options);
int run_view(const ViewOptions& options);
int run_check(const CheckOptions& options);
int run_reapply(const ReapplyOptions& options);

}  // namespace animorder::tool

namespace animorder::tool {

// `animorder batch MANIFEST` (batch.cpp): optimize every item of a manifest, skipping items whose
// outputs are up to date, one shard of the items when asked, and the summary merged from the
// items' reports. parse_item turns an item's optimize arguments into options (main.cpp's parser).
struct BatchOptions {
    std::string manifest;
    bool quiet = false;
    std::string shard;         // "I/N", "env/N" (JOB_COMPLETION_INDEX or SLURM_ARRAY_TASK_ID)
    bool shard_given = false;  // --shard given: its text must then be I/N or env/N (even empty, it is no "all")
    bool merge = false;        // only build the summary from the items' reports
    std::string summary;       // SUMMARY → SUMMARY.json and SUMMARY.md (default: beside the manifest)
    size_t eval_views = 10;    // OVR before/after per item: random views per keyframe (0: no OVR)
    unsigned eval_resolution = 256;
    bool no_timings = false;        // wall times left out: identical work gives byte-identical files
    bool force = false;             // redo items even when up to date
    bool item_failures_ok = false;  // exit 0 when items failed (not with --merge)
    bool dry_run = false;           // write nothing: print which items would run and why (JSON on stdout)
    bool allow_outside = false;     // items may write outside the manifest's folder (.., absolute paths, links out)
    unsigned threads = 0;
};
using ItemParser = std::function<OptimizeOptions(const std::vector<std::string>& args)>;
int run_batch(const BatchOptions& options, const ItemParser& parse_item);

}  // namespace animorder::tool
