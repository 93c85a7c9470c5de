// inspect and optimize: load the input (or the bundled character), run, print and write.
#include "commands.h"

#include "output.h"
#include "report.h"

#include "heatmap_image.h"

#include "animorder/evaluation.h"
#include "animorder/methods.h"
#include "animorder/overdraw.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <sstream>
#include <string>

namespace animorder::tool {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

const char* const kBundledName = "procedural-character (bundled)";

// Progress and notes go to stderr, so stdout stays clean for text or JSON a script may read.
void note(const CommonOptions& common, const std::string& text) {
    if (!common.quiet) std::fprintf(stderr, "animorder: %s\n", text.c_str());
}

AnimatedMesh load_input(const CommonOptions& common, std::string& input_name) {
    if (common.input.empty()) {
        note(common, "no input file given: using the bundled procedural character");
        input_name = kBundledName;
        return make_procedural_character();
    }
    input_name = common.input;
    throw std::runtime_error(common.input +
                             ": cannot read this file yet: only the bundled procedural character is "
                             "supported in this version (run without an input file)");
}

void print_inspect_text(const AnimatedMesh& mesh, const std::string& input_name, const VertexCacheStats& cache,
                        unsigned cache_size) {
    std::printf("%s\n", input_name.c_str());
    std::printf("  triangles %zu  vertices %zu  joints %zu  morph targets %zu  keyframes %zu\n",
                mesh.triangle_count(), mesh.vertex_count, mesh.joint_count, mesh.morph_target_count,
                mesh.keyframe_count());
    std::printf("  ACMR %.4f  ATVR %.4f  (FIFO cache of %u, current order)\n", cache.acmr, cache.atvr, cache_size);
    for (const Primitive& p : mesh.primitives)
        std::printf("  primitive %-12s triangles %zu\n", p.name.c_str(), p.index_count / 3);
    for (const Clip& c : mesh.clips)
        std::printf("  clip %-12s %.3f s  %zu keyframes at %g/s\n", c.name.c_str(), c.duration_s, c.keyframe_count,
                    c.sample_rate);
}

}  // namespace

int run_inspect(const InspectOptions& options) {
    std::string input_name;
    const AnimatedMesh mesh = load_input(options.common, input_name);
    validate_animated_mesh(mesh);
    const VertexCacheStats cache = analyze_mesh_vertex_cache(mesh, mesh.indices, options.common.cache_size);
    if (!options.json) {
        print_inspect_text(mesh, input_name, cache, options.common.cache_size);
        return 0;
    }
    nlohmann::ordered_json report = report_header(mesh, input_name);
    report["joints"] = mesh.joint_count;
    report["morph_targets"] = mesh.morph_target_count;
    report["keyframes"] = mesh.keyframe_count();
    report["cache_size"] = options.common.cache_size;
    report["input_order"] = cache_stats_json(cache);
    for (const Primitive& p : mesh.primitives)
        report["primitives"].push_back({{"name", p.name}, {"triangles", p.index_count / 3}});
    for (const Clip& c : mesh.clips)
        report["clips"].push_back({{"name", c.name},
                                   {"duration_s", c.duration_s},
                                   {"keyframes", c.keyframe_count},
                                   {"sample_rate", c.sample_rate}});
    std::fputs(report_text(report).c_str(), stdout);
    return 0;
}

int run_optimize(const OptimizeOptions& options) {
    const Clock::time_point start = Clock::now();
    if (!std::isfinite(options.lambda)) throw std::runtime_error("--lambda must be a finite number");
    const StaticMethod method = parse_static_method(options.method);

    std::string input_name;
    const AnimatedMesh mesh = load_input(options.common, input_name);
    const double load_s = seconds_since(start);
    note(options.common, "loaded " + input_name + ": " + std::to_string(mesh.triangle_count()) + " triangles, " +
                             std::to_string(mesh.vertex_count) + " vertices, " +
                             std::to_string(mesh.keyframe_count()) + " keyframes");

    StaticMethodSettings settings;
    settings.lambda = options.lambda;
    settings.cache_size = options.common.cache_size;
    settings.keyframe = options.keyframe;
    const Clock::time_point method_start = Clock::now();
    const StaticMethodResult result = run_static_method(mesh, method, settings);
    const double method_s = seconds_since(method_start);

    const VertexCacheStats before = analyze_mesh_vertex_cache(mesh, mesh.indices, settings.cache_size);
    const VertexCacheStats after = analyze_mesh_vertex_cache(mesh, result.indices, settings.cache_size);
    note(options.common, std::string(method_name(method)) + ": ACMR " + std::to_string(before.acmr) + " -> " +
                             std::to_string(after.acmr) + ", " + std::to_string(result.patch_count) + " patches");

    if (!options.output.empty()) {
        std::string bytes(result.indices.size() * 4, '\0');
        for (size_t i = 0; i < result.indices.size(); ++i)
            for (int b = 0; b < 4; ++b) bytes[4 * i + b] = char((result.indices[i] >> (8 * b)) & 0xff);
        write_file_atomically(options.output, bytes);
        note(options.common, "wrote " + options.output);
    }

    nlohmann::ordered_json report = report_header(mesh, input_name);
    report["settings"] = {{"method", method_name(method)},
                          {"lambda", options.lambda},
                          {"cache_size", settings.cache_size},
                          {"keyframe", settings.keyframe}};
    report["input_order"] = cache_stats_json(before);
    nlohmann::ordered_json entry = {{"name", method_name(method)},
                                    {"buffers", 1},
                                    {"acmr", after.acmr},
                                    {"atvr", after.atvr},
                                    {"ovr_mean", nullptr},
                                    {"time_s", method_s}};
    if (method == StaticMethod::StaticSander07) entry["lambda"] = options.lambda;
    entry["patches"] = result.patch_count;
    entry["hard_boundaries"] = result.hard_boundary_count;
    report["methods"] = nlohmann::ordered_json::array({entry});
    report["outputs"] = {{"indices", options.output.empty() ? nlohmann::ordered_json(nullptr)
                                                             : nlohmann::ordered_json(options.output)}};
    report["timings_s"] = {{"load", load_s}, {"method", method_s}, {"total", seconds_since(start)}};

    if (!options.report_path.empty()) {
        write_file_atomically(options.report_path, report_text(report));
        note(options.common, "wrote " + options.report_path);
    }
    std::printf("%s on %s: %zu triangles, ACMR %.4f -> %.4f, ATVR %.4f -> %.4f, %zu patches, %.3f s\n",
                method_name(method), input_name.c_str(), mesh.triangle_count(), before.acmr, after.acmr, before.atvr,
                after.atvr, result.patch_count, method_s);
    return 0;
}

namespace {

std::vector<std::string> split_list(const std::string& text) {
    std::vector<std::string> items;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ','))
        if (!item.empty()) items.push_back(item);
    return items;
}

// A progress line on stderr that rewrites itself, so it never fights with log lines.
std::function<void(size_t, size_t)> progress_printer(const CommonOptions& common, const std::string& stage) {
    if (common.quiet) return {};
    const Clock::time_point start = Clock::now();
    return [stage, start](size_t done, size_t total) {
        std::fprintf(stderr, "\ranimorder: %s: %zu/%zu nodes, %.1f s", stage.c_str(), done, total, seconds_since(start));
        if (done == total) std::fputc('\n', stderr);
        std::fflush(stderr);
    };
}

void check_lambda(double lambda) {
    if (!std::isfinite(lambda)) throw std::runtime_error("--lambda must be a finite number");
}

}  // namespace

int run_evaluate(const EvaluateOptions& options) {
    const Clock::time_point start = Clock::now();
    check_lambda(options.lambda);
    std::vector<StaticMethod> methods;
    for (const std::string& name : split_list(options.methods)) methods.push_back(parse_static_method(name));
    if (methods.empty()) throw std::runtime_error("--methods names no method");

    std::string input_name;
    const AnimatedMesh mesh = load_input(options.common, input_name);
    validate_animated_mesh(mesh);

    StaticMethodSettings settings;
    settings.lambda = options.lambda;
    settings.cache_size = options.common.cache_size;
    std::vector<std::vector<uint32_t>> orders;
    std::vector<VertexCacheStats> cache;
    std::vector<double> method_seconds;
    for (StaticMethod method : methods) {
        const Clock::time_point t = Clock::now();
        StaticMethodResult result = run_static_method(mesh, method, settings);
        method_seconds.push_back(seconds_since(t));
        cache.push_back(analyze_mesh_vertex_cache(mesh, result.indices, settings.cache_size));
        orders.push_back(std::move(result.order));
    }

    EvaluationSettings eval;
    eval.views = options.views;
    eval.seed = options.seed;
    eval.resolution = options.resolution;
    eval.threads = options.threads;
    eval.progress = progress_printer(options.common, "evaluating");
    note(options.common, "evaluating " + std::to_string(methods.size()) + " methods at " +
                             std::to_string(mesh.keyframe_count() * options.views) + " nodes (" +
                             std::to_string(mesh.keyframe_count()) + " keyframes x " + std::to_string(options.views) +
                             " views, " + std::to_string(options.resolution) + "^2)");
    const Clock::time_point eval_start = Clock::now();
    const std::vector<OrderEvaluation> results = evaluate_single_orders(mesh, orders, eval);
    const double eval_s = seconds_since(eval_start);

    nlohmann::ordered_json report = report_header(mesh, input_name);
    report["settings"] = {{"methods", options.methods},       {"lambda", options.lambda},
                          {"cache_size", settings.cache_size}, {"eval_views", options.views},
                          {"eval_resolution", options.resolution}, {"seed", options.seed}};
    report["methods"] = nlohmann::ordered_json::array();
    std::printf("| method | buffers | ACMR | ATVR | OVR mean | OVR pooled |");
    for (const Clip& c : mesh.clips) std::printf(" %s |", c.name.c_str());
    std::printf("\n|---|---|---|---|---|---|");
    for (size_t c = 0; c < mesh.clips.size(); ++c) std::printf("---|");
    std::printf("\n");
    std::string csv = "method,lambda,buffers,acmr,atvr,ovr_mean,ovr_pooled,time_s\n";
    for (size_t m = 0; m < methods.size(); ++m) {
        const OrderEvaluation& r = results[m];
        nlohmann::ordered_json entry = {{"name", method_name(methods[m])},
                                        {"lambda", methods[m] == StaticMethod::StaticSander07
                                                       ? nlohmann::ordered_json(options.lambda)
                                                       : nlohmann::ordered_json(nullptr)},
                                        {"buffers", 1},
                                        {"acmr", cache[m].acmr},
                                        {"atvr", cache[m].atvr},
                                        {"ovr_mean", r.overall.ovr_mean},
                                        {"ovr_pooled", r.overall.ovr_pooled},
                                        {"per_clip", nlohmann::ordered_json::array()},
                                        {"time_s", method_seconds[m]}};
        std::printf("| %s | 1 | %.3f | %.3f | %.3f | %.3f |", method_name(methods[m]), cache[m].acmr, cache[m].atvr,
                    r.overall.ovr_mean, r.overall.ovr_pooled);
        for (size_t c = 0; c < mesh.clips.size(); ++c) {
            entry["per_clip"].push_back({{"clip", mesh.clips[c].name},
                                         {"ovr_mean", r.per_clip[c].ovr_mean},
                                         {"ovr_pooled", r.per_clip[c].ovr_pooled},
                                         {"nodes", r.per_clip[c].nodes}});
            std::printf(" %.3f |", r.per_clip[c].ovr_mean);
        }
        std::printf("\n");
        report["methods"].push_back(entry);
        char line[256];
        std::snprintf(line, sizeof line, "%s,%g,1,%.6f,%.6f,%.6f,%.6f,%.6f\n", method_name(methods[m]), options.lambda,
                      cache[m].acmr, cache[m].atvr, r.overall.ovr_mean, r.overall.ovr_pooled, method_seconds[m]);
        csv += line;
    }
    report["nodes"] = mesh.keyframe_count() * options.views;
    report["timings_s"] = {{"evaluation", eval_s}, {"total", seconds_since(start)}};
    if (!options.report_path.empty()) write_file_atomically(options.report_path, report_text(report));
    if (!options.csv_path.empty()) write_file_atomically(options.csv_path, csv);
    return 0;
}

int run_heatmap(const HeatmapOptions& options) {
    check_lambda(options.lambda);
    if (options.view.size() != 3) throw std::runtime_error("--view takes three numbers: x,y,z");
    const double length = std::sqrt(double(options.view[0]) * options.view[0] + double(options.view[1]) * options.view[1] +
                                    double(options.view[2]) * options.view[2]);
    if (!(length > 1e-9) || !std::isfinite(length)) throw std::runtime_error("--view must be a non-zero finite direction");
    if (options.output.empty()) throw std::runtime_error("heatmap needs an output file (-o out.png)");
    const StaticMethod method = parse_static_method(options.method);

    std::string input_name;
    const AnimatedMesh mesh = load_input(options.common, input_name);
    validate_animated_mesh(mesh);
    if (options.keyframe >= mesh.keyframe_count())
        throw std::runtime_error("keyframe " + std::to_string(options.keyframe) + " does not exist (the mesh has " +
                                 std::to_string(mesh.keyframe_count()) + ")");
    StaticMethodSettings settings;
    settings.lambda = options.lambda;
    settings.cache_size = options.common.cache_size;
    const StaticMethodResult result = run_static_method(mesh, method, settings);

    const Framing framing = frame_keyframes(mesh.keyframe_positions.data(), mesh.keyframe_count(), mesh.vertex_count,
                                            mesh.indices.data(), mesh.indices.size());
    const float direction[3] = {float(options.view[0] / length), float(options.view[1] / length),
                                float(options.view[2] / length)};
    std::vector<float> clip(mesh.vertex_count * 4);
    transform_to_clip(clip.data(), mesh.keyframe(options.keyframe), mesh.vertex_count,
                      &framing.centres[3 * options.keyframe], node_view_projection(direction, framing.radius));
    NodeRasterizer rasterizer;
    rasterizer.rasterize(clip.data(), mesh.vertex_count, mesh.indices.data(), mesh.indices.size(), options.resolution);
    const std::vector<uint32_t> ranks = make_rank_table({result.order.data()}, mesh.triangle_count());
    uint64_t passed = 0;
    rasterizer.score(&passed, ranks.data(), 1);
    const double ovr = rasterizer.visible_pixels() ? double(passed) / double(rasterizer.visible_pixels()) : 0.0;

    char caption[256];
    std::snprintf(caption, sizeof caption, "%s  keyframe %zu  view (%.2f, %.2f, %.2f)  OVR %.3f", method_name(method),
                  options.keyframe, direction[0], direction[1], direction[2], ovr);
    write_file_atomically(options.output,
                          heatmap_png(rasterizer.passed_per_pixel(ranks.data(), 1, 0), options.resolution, caption));
    note(options.common, "wrote " + options.output);
    std::printf("%s: visible %llu, shaded %llu, OVR %.4f\n", method_name(method),
                (unsigned long long)rasterizer.visible_pixels(), (unsigned long long)passed, ovr);
    return 0;
}

}  // namespace animorder::tool
