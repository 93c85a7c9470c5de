// animorder — command-line entry point: parses options, dispatches to a subcommand, and turns
// every failure into one line on stderr and a non-zero exit code (never a crash).
#include "commands.h"
#include "peak_memory.h"

#include "animorder/atomic_write.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

// The text of an unsigned option: digits only (a sign would wrap "-1" around to 2^64 - 1) and a
// value that fits in 64 bits (a larger one would be taken as the largest, silently).
const CLI::Validator kWholeNumber(
    [](std::string& text) -> std::string {
        if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos)
            return "must be a whole number (digits only), not '" + text + "'";
        try {
            (void)std::stoull(text);
        } catch (const std::out_of_range&) {
            return text + " is larger than 2^64 - 1";
        }
        return "";
    },
    "UINT");

// A path option given as "" (an unset shell variable, say): refused, where it would otherwise read as
// the option left out (no output written, the bundled character loaded) without a word.
const CLI::Validator kPath([](std::string& text) -> std::string { return text.empty() ? "must not be empty" : ""; },
                           "PATH");

void add_common(CLI::App& command, animorder::tool::CommonOptions& common) {
    command.add_option("input", common.input, "Input mesh (default: the bundled procedural character)")->check(kPath);
    command.add_flag("-q,--quiet", common.quiet, "No progress or notes on stderr");
    command
        .add_option("--clip", common.clips,
                    "A clip to keep (by name), or a clip file / folder of clip files to add (Mixamo style); repeatable")
        ->allow_extra_args(false)  // one value a --clip: `--clip Idle FILE` leaves FILE the input
        ->check(kPath);
    command.add_option("--cache-size", common.cache_size, "FIFO vertex cache entries for ACMR and Tipsify")
        ->check(CLI::Range(3u, 1024u));
    command
        .add_option("--max-memory", common.max_memory,
                    "Loading budget in bytes for the sampled animation (keyframes x vertices x 12)")
        ->capture_default_str()
        ->check(kWholeNumber)
        ->check(CLI::Range(size_t(1) << 20, std::numeric_limits<size_t>::max()));
}

// sweep: -l, -k and --views take comma-separated lists (evaluate runs every combination).
void add_method_options(CLI::App& command, animorder::tool::MethodOptions& options, bool sweep = false) {
    animorder::MethodSettings& m = options.settings;
    animorder::ClusteringSettings& c = m.clustering;
    const char* lambda_help =
        "Patch threshold: soft boundary when a patch's local ACMR < lambda "
        "(<0.5: hard boundaries only, >=3: single triangles)";
    if (sweep) {
        options.lambdas = {m.lambda};
        options.cluster_list = {c.clusters};
        options.view_list = {c.views};
        command.add_option("-l,--lambda", options.lambdas, std::string(lambda_help) + "; a list runs each value")
            ->delimiter(',')
            ->allow_extra_args(false)  // a list is one comma-separated value
            ->capture_default_str()
            ->check(CLI::Range(0.0, 1000.0));
        command
            .add_option("-k,--clusters", options.cluster_list,
                        "k-means methods: number of buffers k; a list runs each value")
            ->delimiter(',')
            ->allow_extra_args(false)  // a list is one comma-separated value
            ->capture_default_str()
            ->check(CLI::Range(size_t(1), animorder::kMaxClusters));
        command
            .add_option("--views", options.view_list,
                        "k-means methods: clustering viewpoints (12, 42, 162, 642); a list runs each value")
            ->delimiter(',')
            ->allow_extra_args(false)  // a list is one comma-separated value
            ->capture_default_str()
            ->check(kWholeNumber);
    } else {
        command.add_option("-l,--lambda", m.lambda, lambda_help)->capture_default_str()->check(CLI::Range(0.0, 1000.0));
        command.add_option("-k,--clusters", c.clusters, "k-means methods: number of buffers k")
            ->capture_default_str()
            ->check(CLI::Range(size_t(1), animorder::kMaxClusters));
        command.add_option("--views", c.views, "k-means methods: clustering viewpoints (12, 42, 162, 642)")
            ->capture_default_str()
            ->check(kWholeNumber);
    }
    command.add_option("--frame", m.keyframe, "static methods: keyframe whose positions they sort with")
        ->capture_default_str()
        ->check(kWholeNumber);
    command.add_option("--resolution", c.resolution, "k-means methods, static-nehab06: clustering viewport in pixels")
        ->capture_default_str()
        ->check(CLI::Range(8u, 4096u));
    command.add_option("--seed", c.seed, "k-means methods: seed of the bootstrap viewpoints")
        ->capture_default_str()
        ->check(kWholeNumber);
    command.add_option("--min-separation", c.min_separation_deg, "k-means methods: degrees between bootstrap viewpoints")
        ->capture_default_str();
    command.add_option("--max-iterations", c.max_iterations, "k-means methods: cap on k-means iterations")
        ->capture_default_str()
        ->check(CLI::Range(size_t(1), size_t(1000)));
    command.add_option("--distance", options.distance, "k-means methods: jcgt (sum) or i3d (visible-only mean)")
        ->capture_default_str();
    command
        .add_option("--update", options.update,
                    "k-means methods: monotone (keep a cluster's new order only if its nodes' OVR falls) or paper")
        ->capture_default_str();
    command.add_flag(
        "--blend-clusters", m.blend_clusters,
        "k-means methods: blended primitives get their own k clusters (buffers: the cluster pairs, up to k^2 per clip)");
    command.add_option("--nehab-clusters", m.nehab_clusters, "static-nehab06: planar clusters (0: automatic)")
        ->capture_default_str()
        ->check(CLI::Range(size_t(0), size_t(1) << 20));
    command.add_option("--nehab-views", m.nehab_views, "static-nehab06: measuring viewpoints (12, 42, 162, 642)")
        ->capture_default_str()
        ->check(kWholeNumber);
    command.add_flag("--nehab-all-keyframes", m.nehab_all_keyframes,
                     "static-nehab06: measure also at 8 keyframes spread over the clips (default: --frame only)");
    command.add_flag("--planar-units", m.measured_planar_units,
                     "measured: Nehab 2006 planar clusters as units (as many as lambda's patches), not patches");
    command
        .add_option("--front-levels", c.front_levels,
                    "measured: count each unit against the units of this many nearest depth levels in front "
                    "(0: every level)")
        ->capture_default_str()
        ->check(CLI::Range(0u, animorder::kMaxFrontLevels));
    command
        .add_option("--fragment-memory", c.max_cache_bytes,
                    "k-means methods: bytes for the nodes' kept fragments; nodes beyond are rasterised again "
                    "each iteration (same result, slower)")
        ->capture_default_str()
        ->check(kWholeNumber);
    command.add_option("--threads", c.threads, "Worker threads (0: all cores)")
        ->capture_default_str()
        ->check(kWholeNumber)
        ->check(CLI::Range(0u, 1024u));
}

// The method names for help texts, from the library's one list.
std::string method_list(bool shippable_only) {
    std::string list;
    for (animorder::Method m : animorder::all_methods())
        if (!shippable_only || animorder::method_has_buffers(m))
            list += std::string(list.empty() ? "" : ", ") + animorder::method_name(m);
    return list;
}

void add_optimize_options(CLI::App& command, animorder::tool::OptimizeOptions& optimize) {
    add_common(command, optimize.common);
    command.add_option("-m,--method", optimize.method, "One of: " + method_list(true))->capture_default_str();
    command.add_flag("--joint", optimize.joint,
                     "One set of buffers for all clips: the method's joint variant (measured-joint, joint)");
    add_method_options(command, optimize.methods);
    command
        .add_option("-o,--output", optimize.output,
                    "Write OUT.animorder.bin (buffers + lookup tables) and OUT.animorder.json; "
                    "OUT.glb or OUT.gltf (glTF input) also writes the glTF with the orders")
        ->check(kPath);
    command.add_option("-r,--report", optimize.report_path, "Write the JSON report to this file")->check(kPath);
}

// A batch item's optimize arguments → options, by the optimize subcommand's own parser.
animorder::tool::OptimizeOptions parse_batch_item(const std::vector<std::string>& args) {
    CLI::App item{"batch item"};
    animorder::tool::OptimizeOptions options;
    add_optimize_options(item, options);
    std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 takes them last first
    try {
        item.parse(reversed);
    } catch (const CLI::Success&) {  // --help, --version: not an item's option
        throw std::runtime_error("--help and --version are not options of an item");
    } catch (const CLI::ParseError& e) {
        throw std::runtime_error(e.what());
    }
    return options;
}

}  // namespace

// An error message as one line: a line break inside it (a path with a newline in its name) shown
// as \n or \r, so that a script reading stderr line by line sees one error.
static std::string one_line(const char* message) {
    std::string out;
    for (const char* c = message; *c; ++c) out += *c == '\n' ? "\\n" : *c == '\r' ? "\\r" : std::string(1, *c);
    return out;
}

int main(int argc, char** argv) {
    using namespace animorder::tool;
    CLI::App app{
        "animorder: triangle orders for animated meshes with low overdraw and a good vertex cache\n"
        "(Han & Sander 2017; Sander, Nehab & Barczak 2007)"};
    app.set_version_flag("--version", std::string("animorder ") + ANIMORDER_VERSION);
    app.require_subcommand(1);
    // SIGTERM ends a run at any moment, also as a container's first process (PID 1), which the
    // signal's default action would leave running until it is killed.
    animorder::install_signal_cleanup();
    fix_allocator_threshold();

    InspectOptions inspect;
    CLI::App* inspect_cmd =
        app.add_subcommand("inspect", "Print triangles, vertices, clips and the ACMR of the current order");
    add_common(*inspect_cmd, inspect.common);
    inspect_cmd->add_flag("--json", inspect.json, "Print JSON instead of text");

    OptimizeOptions optimize;
    CLI::App* optimize_cmd =
        app.add_subcommand("optimize", "Reorder triangles with a method; write buffers, table, report");
    add_optimize_options(*optimize_cmd, optimize);

    EvaluateOptions evaluate;
    CLI::App* evaluate_cmd =
        app.add_subcommand("evaluate", "Score methods' overdraw (OVR) and ACMR over the evaluation nodes (DESIGN.md)");
    add_common(*evaluate_cmd, evaluate.common);
    evaluate_cmd->add_option("--methods", evaluate.methods, "Comma-separated, of: " + method_list(false))
        ->capture_default_str();
    add_method_options(*evaluate_cmd, evaluate.method_options, true);
    evaluate_cmd->add_option("--eval-views", evaluate.evaluation.views, "Random viewpoints per keyframe")
        ->capture_default_str()
        ->check(CLI::Range(size_t(1), size_t(100000)));
    evaluate_cmd->add_option("--eval-resolution", evaluate.evaluation.resolution, "Viewport size in pixels")
        ->capture_default_str()
        ->check(CLI::Range(1u, 8192u));
    evaluate_cmd->add_option("--eval-seed", evaluate.evaluation.seed, "Seed of the evaluation viewpoints")
        ->capture_default_str()
        ->check(kWholeNumber);
    evaluate_cmd->add_option("-r,--report", evaluate.report_path, "Write the JSON report to this file")->check(kPath);
    evaluate_cmd->add_option("--csv", evaluate.csv_path, "Write the table as CSV to this file")->check(kPath);
    evaluate_cmd->add_flag(
        "--stored", evaluate.stored,
        "Also evaluate the orders stored in INPUT (ANIMORDER_animated_triangle_orders): row 'stored'");
    evaluate_cmd->add_flag("--single-sided", evaluate.single_sided,
                           "Draw every material single-sided (back faces culled), orders and OVR, as before issue 18: "
                           "with a plain run, the cost of double-sided materials");

    HeatmapOptions heatmap;
    CLI::App* heatmap_cmd = app.add_subcommand("heatmap", "Draw a per-pixel overdraw image of one node as PNG");
    add_common(*heatmap_cmd, heatmap.common);
    heatmap_cmd->add_option("--order", heatmap.method, "A single-buffer method: original, static-sander07, ...")
        ->capture_default_str();
    heatmap_cmd->add_option("-l,--lambda", heatmap.lambda, "Patch threshold for static-sander07")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 1000.0));
    heatmap_cmd->add_option("--view", heatmap.view, "Direction from the character to the camera, x,y,z")
        ->delimiter(',')
        ->allow_extra_args(false)  // x,y,z is one value: the input may follow
        ->expected(3);
    heatmap_cmd->add_option("--frame", heatmap.keyframe, "Keyframe (over all clips)")
        ->capture_default_str()
        ->check(kWholeNumber);
    heatmap_cmd->add_option("--resolution", heatmap.resolution, "Image size in pixels")
        ->capture_default_str()
        ->check(CLI::Range(16u, 8192u));
    heatmap_cmd->add_option("-o,--output", heatmap.output, "PNG file to write")->required()->check(kPath);
    heatmap_cmd->add_flag("--blend", heatmap.blend,
                          "Show the blended primitives' mis-sorted fragment pairs per pixel (drawn back to front: 0)");

    SubdivideOptions subdivide;
    CLI::App* subdivide_cmd = app.add_subcommand(
        "subdivide", "Loop-subdivide every keyframe; write a new glTF/GLB (keyframes as morph targets)");
    add_common(*subdivide_cmd, subdivide.common);
    subdivide_cmd->add_option("-n,--levels", subdivide.levels, "Levels of Loop subdivision (each: 4x the triangles)")
        ->required();
    subdivide_cmd
        ->add_option("-o,--output", subdivide.output,
                     "OUT.glb or OUT.gltf; one morph target per keyframe, so the file is large "
                     "(vertices x keyframes x 12 bytes): keep fewer clips with --clip NAME")
        ->required()
        ->check(kPath);

    BatchOptions batch;
    CLI::App* batch_cmd = app.add_subcommand(
        "batch", "Optimize every item of a manifest (JSON or CSV); up-to-date items skipped; shards; summary");
    batch_cmd->add_option("manifest", batch.manifest, "Manifest: JSON {\"items\": [...]} or CSV with a header line")
        ->required()
        ->check(kPath);
    batch_cmd->add_flag("-q,--quiet", batch.quiet, "No progress or notes on stderr");
    batch_cmd->add_option("--shard", batch.shard,
                          "I/N: only items i with i % N == I (0-based); env/N: I from JOB_COMPLETION_INDEX or "
                          "SLURM_ARRAY_TASK_ID");
    batch_cmd->add_flag("--merge", batch.merge,
                        "Run nothing: build the summary from the items' reports (after the shards)");
    batch_cmd
        ->add_option("--summary", batch.summary,
                     "Write SUMMARY.json and SUMMARY.md (SUMMARY.json says the same; default: the manifest's name + "
                     ".summary)")
        ->check(kPath);
    batch_cmd->add_option("--eval-views", batch.eval_views, "OVR before/after: random views per keyframe (0: no OVR)")
        ->capture_default_str()
        ->check(CLI::Range(size_t(0), size_t(100000)));
    batch_cmd->add_option("--eval-resolution", batch.eval_resolution, "OVR before/after: viewport in pixels")
        ->capture_default_str()
        ->check(CLI::Range(8u, 8192u));
    batch_cmd->add_flag("--no-timings", batch.no_timings,
                        "Leave wall times out of reports and summary (identical work: byte-identical files)");
    batch_cmd->add_flag("--force", batch.force, "Redo items whose outputs are up to date");
    batch_cmd->add_flag("--item-failures-ok", batch.item_failures_ok,
                        "Exit 0 when items failed (each recorded for the merge, which still exits 3): for farms "
                        "whose retry would only fail the same items again");
    batch_cmd->add_flag("--dry-run", batch.dry_run,
                        "Write nothing: print which of the shard's items would run and why (JSON on stdout)");
    batch_cmd->add_flag("--allow-outside", batch.allow_outside,
                        "Let items write outside the manifest's folder (an output with .., an absolute one, a link "
                        "to a folder elsewhere); refused without it");
    batch_cmd->add_option("--threads", batch.threads, "Worker threads per item (0: all cores)")
        ->capture_default_str()
        ->check(kWholeNumber)
        ->check(CLI::Range(0u, 1024u));

    ViewOptions view;
    CLI::App* view_cmd = app.add_subcommand(
        "view", "Serve the viewer page and a glb on 127.0.0.1 (the bundled character, optimised, by default)");
    view_cmd
        ->add_option("input", view.common.input,
                     "The optimised glb to show (default: the bundled character, optimised)")
        ->check(kPath);
    view_cmd->add_flag("-q,--quiet", view.common.quiet, "No progress or notes on stderr");
    view_cmd->add_option("--original", view.original, "The un-optimised file, to compare its order in the page")
        ->check(kPath);
    view_cmd->add_option("--port", view.port, "Port on 127.0.0.1 (0: any free one)")
        ->capture_default_str()
        ->check(CLI::Range(0u, 65535u));
    view_cmd->add_flag("!--no-open", view.open, "Do not start a browser; just print the address");
    view_cmd->add_option("--seconds", view.seconds, "Stop serving after this many seconds (0: until interrupted)")
        ->check(kWholeNumber)
        ->check(CLI::Range(0u, 100000000u));
    view_cmd
        ->add_option("--viewer-root", view.viewer_root, "The folder holding viewer/ and js/ (default: the source tree)")
        ->check(kPath);

    CheckOptions check;
    CLI::App* check_cmd = app.add_subcommand(
        "check",
        "Check the ANIMORDER_animated_triangle_orders orders of a glTF file (JSON report; exit 1 when unusable)");
    check_cmd->add_option("file", check.file, "glTF/GLB file")->required()->check(kPath);
    check_cmd->add_flag("-q,--quiet", check.quiet, "No error line on stderr (the JSON report still has it)");

    ReapplyOptions reapply;
    CLI::App* reapply_cmd = app.add_subcommand("reapply",
                                               "Map an optimised file's orders onto a processed copy of it (gltfpack, "
                                               "gltf-pipeline...) by matching triangles");
    reapply_cmd->add_option("optimized", reapply.optimized, "The file animorder optimize wrote")
        ->required()
        ->check(kPath);
    reapply_cmd->add_option("processed", reapply.processed, "The same file after another tool")
        ->required()
        ->check(kPath);
    reapply_cmd->add_option("-o,--output", reapply.output, "OUT.glb or OUT.gltf: PROCESSED with the orders")
        ->required()
        ->check(kPath);
    const CLI::Validator number(
        [](std::string& text) {  // CLI::Range lets NaN through (every comparison with it is false)
            const double v = std::strtod(text.c_str(), nullptr);
            return std::isnan(v) ? std::string("must be a number, not '") + text + "'" : std::string();
        },
        "NUMBER");
    reapply_cmd
        ->add_option("--tolerance", reapply.tolerance,
                     "Corner distance allowed, as a fraction of the bounding-box diagonal")
        ->capture_default_str()
        ->check(number)
        ->check(CLI::Range(0.0, 0.1));
    reapply_cmd
        ->add_option("--nearest", reapply.nearest,
                     "A simplified PROCESSED: a triangle found nowhere is drawn where the optimised triangle with the "
                     "nearest posed centroid is, when within this fraction of the bounding-box diagonal (0: off)")
        ->capture_default_str()
        ->check(number)
        ->check(CLI::Range(0.0, 1.0));
    reapply_cmd->add_option("--max-memory", reapply.max_memory, "Loading budget in bytes for the sampled animation")
        ->capture_default_str()
        ->check(kWholeNumber)
        ->check(CLI::Range(size_t(1) << 20, std::numeric_limits<size_t>::max()));
    reapply_cmd->add_flag("-q,--quiet", reapply.quiet, "No progress or notes on stderr");

    if (argc == 1) {  // no arguments: the basics, and where to look next (gltfpack style)
        std::fputs(app.help().c_str(), stderr);
        return 2;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::Success& e) {  // --help, --version
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // Every option error the same way as every other error: one line, exit code 1.
        std::fprintf(stderr, "animorder: error: %s\n", one_line(e.what()).c_str());
        return 1;
    }

    try {
        if (*inspect_cmd) return run_inspect(inspect);
        if (*optimize_cmd) return run_optimize(optimize);
        if (*evaluate_cmd) return run_evaluate(evaluate);
        if (*heatmap_cmd) return run_heatmap(heatmap);
        if (*subdivide_cmd) return run_subdivide(subdivide);
        if (*batch_cmd) {
            batch.shard_given = batch_cmd->count("--shard") > 0;  // --shard "" is an error, not every item
            return run_batch(batch, parse_batch_item);
        }
        if (*view_cmd) return run_view(view);
        if (*check_cmd) return run_check(check);
        if (*reapply_cmd) return run_reapply(reapply);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "animorder: error: %s\n", one_line(e.what()).c_str());
        return 1;
    }
    return 2;
}
