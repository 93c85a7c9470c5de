// `animorder optimize`: run one method on the input and write what an application ships — the
// glTF with the orders (glTF input), the sidecar and its description — and the JSON report. Every
// output path is checked before any work; the outputs appear all together or not at all.
#include "optimize.h"

#include "commands.h"
#include "input.h"
#include "peak_memory.h"
#include "report.h"

#include "animorder/atomic_write.h"
#include "animorder/gltf_writer.h"
#include "animorder/load.h"
#include "animorder/sidecar.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <thread>

namespace animorder::tool {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// The files `-o OUT` names: OUT.glb / OUT.gltf (only for glTF input), OUT.animorder.bin and .json.
void output_paths(const OptimizeOptions& options, OptimizePlan& paths) {
    if (options.output.empty()) return;
    check_output_stem(options.output);
    std::string stem = options.output;
    const std::string extension = file_extension(options.output);
    if (extension == ".glb" || extension == ".gltf") {
        const std::string in_ext = file_extension(options.common.input);
        if (in_ext != ".glb" && in_ext != ".gltf")
            throw std::runtime_error(options.output +
                                     ": glTF output needs a glTF input (the sidecar works for any input)");
        paths.gltf = options.output;
        stem = options.output.substr(0, options.output.size() - extension.size());
    }
    paths.sidecar = stem + ".animorder.bin";
    paths.sidecar_json = stem + ".animorder.json";
}

}  // namespace

nlohmann::ordered_json optimize_settings_json(const OptimizeOptions& options, const OptimizePlan& plan,
                                              bool with_threads) {
    const MethodSettings& m = plan.settings;
    nlohmann::ordered_json settings = {{"method", method_name(plan.method)},
                                       {"lambda", m.lambda},
                                       {"cache_size", m.cache_size},
                                       {"keyframe", m.keyframe},
                                       {"clusters", m.clustering.clusters},
                                       {"views", m.clustering.views},
                                       {"resolution", m.clustering.resolution},
                                       {"seed", m.clustering.seed},
                                       {"min_separation_deg", m.clustering.min_separation_deg},
                                       {"max_iterations", m.clustering.max_iterations},
                                       {"distance", options.methods.distance},
                                       {"update", options.methods.update},
                                       {"nehab_clusters", m.nehab_clusters},
                                       {"nehab_views", m.nehab_views},
                                       {"nehab_all_keyframes", m.nehab_all_keyframes},
                                       {"blend_clusters", m.blend_clusters},
                                       {"planar_units", m.measured_planar_units},
                                       {"front_levels", m.clustering.front_levels}};
    if (with_threads) {  // how it ran, which changes no output: threads used, the memory budgets
        const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
        settings["threads"] = m.clustering.threads ? std::min(m.clustering.threads, cores) : cores;
        settings["fragment_memory"] = m.clustering.max_cache_bytes;
        settings["max_memory"] = options.common.max_memory;
    }
    return settings;
}

void name_outputs(const OptimizeOptions& options, OptimizePlan& plan) {
    plan.gltf.clear(), plan.sidecar.clear(), plan.sidecar_json.clear(), plan.outputs.clear();
    output_paths(options, plan);
    const std::string* named[] = {&plan.gltf, &plan.sidecar, &plan.sidecar_json, &options.report_path};
    for (const std::string* p : named)
        if (!p->empty()) plan.outputs.push_back(*p);
}

OptimizePlan plan_optimize(const OptimizeOptions& options) {
    OptimizePlan plan;
    Method method = parse_method(options.method);
    if (options.joint) {
        if (!method_has_joint_variant(method))
            throw std::runtime_error("--joint applies to the single and measured methods, not " + options.method);
        method = method_joint_variant(method);
    }
    if (!method_has_buffers(method))
        throw std::runtime_error(
            std::string(method_name(method)) +
            " is a bound (a new order at every node), not an order to ship; use evaluate --methods " +
            method_name(method));
    plan.method = method;
    plan.settings = method_settings(options.methods, options.common, method);
    validate_method_settings(plan.settings);
    name_outputs(options, plan);
    plan.inputs = input_files(options.common);
    plan.input_folders = input_folders(options.common);
    return plan;
}

OptimizeProduct produce_optimize(const OptimizeOptions& options, const OptimizePlan& plan, OutputSet& files,
                                 const std::function<void(const std::vector<std::string>& files_read)>& loaded) {
    const Clock::time_point start = Clock::now();
    const Method method = plan.method;
    const MethodSettings& settings = plan.settings;
    const OptimizePlan& paths = plan;
    std::string input_name;
    OptimizeProduct product;
    CommonOptions common = options.common;
    common.threads = settings.clustering.threads;
    product.mesh = load_drawable_input(common, input_name, &product.files_read);
    check_output_paths(plan.outputs, product.files_read);
    if (!plan.gltf.empty()) check_gltf_output(options.common.input, product.mesh);  // before the work
    if (loaded) loaded(product.files_read);
    const AnimatedMesh& mesh = product.mesh;
    if (method == Method::TipsifyPerFrame && (!paths.gltf.empty() || !paths.sidecar.empty()))
        for (const Clip& clip : product.mesh.clips)
            if (clip.keyframe_count > kMaxPerKeyframeBuffers)
                throw std::runtime_error("tipsify-per-frame writes one buffer per keyframe, and clip '" + clip.name +
                                         "' has " + std::to_string(clip.keyframe_count) +
                                         " keyframes: a lookup table names at most " +
                                         std::to_string(kMaxPerKeyframeBuffers) +
                                         "; keep shorter clips (--clip), or write only the report (no -o)");
    const double load_s = seconds_since(start);
    note(options.common, std::string(method_name(method)) + ": " + std::to_string(mesh.triangle_count()) +
                             " triangles, " + std::to_string(mesh.vertex_count) + " vertices, " +
                             std::to_string(mesh.keyframe_count()) + " keyframes (" + input_name + ")");

    // plan_optimize validated the settings (before loading): they are not checked again.
    const PeakResident memory;
    product.run = about_input(options.common, [&] { return run_validated_method(mesh, method, settings); });
    const std::optional<uint64_t> peak = memory.peak();
    const MethodResult& run = product.run;
    product.before = analyze_mesh_vertex_cache(mesh, mesh.indices, settings.cache_size);
    const VertexCacheStats& before = product.before;

    nlohmann::ordered_json written = {{"gltf", nullptr}, {"sidecar", nullptr}, {"sidecar_json", nullptr}};
    if (!paths.gltf.empty()) {
        const bool binary = file_extension(paths.gltf) == ".glb";
        std::string kept;
        files.add(paths.gltf, gltf_with_orders(options.common.input, paths.gltf, mesh, run.buffers, run.fallback,
                                               run.framing, method_name(method), binary, &kept));
        if (!kept.empty()) note(options.common, "note: " + kept);
        written["gltf"] = paths.gltf;
    }
    if (!paths.sidecar.empty()) {
        files.add(paths.sidecar, serialize_sidecar(mesh, run.buffers, run.framing));
        files.add(paths.sidecar_json, sidecar_json(mesh, run.buffers, method_name(method), run.fallback,
                                                   std::filesystem::path(paths.sidecar).filename().string()));
        written["sidecar"] = paths.sidecar;
        written["sidecar_json"] = paths.sidecar_json;
    }

    nlohmann::ordered_json& report = product.report;
    report = report_header(mesh, input_name);
    report["settings"] = optimize_settings_json(options, plan);
    report["input_order"] = cache_stats_json(before);
    report["methods"] = nlohmann::ordered_json::array({method_entry(mesh, run, settings, peak)});
    report["outputs"] = written;
    report["timings_s"] = {{"load", load_s}, {"method", run.seconds}, {"total", seconds_since(start)}};
    return product;
}

int run_optimize(const OptimizeOptions& options) {
    const OptimizePlan plan = plan_optimize(options);
    // Every output is checked now, not after minutes of work: folders exist, nothing is an input,
    // no file is named twice.
    check_outputs(plan.outputs, plan.inputs, plan.input_folders);

    OutputSet files;
    const OptimizeProduct product = produce_optimize(options, plan, files);
    if (!options.report_path.empty()) files.add(options.report_path, report_text(product.report));
    files.commit();
    for (const std::string& path : plan.outputs) note(options.common, "wrote " + path);

    const MethodResult& run = product.run;
    const VertexCacheStats& before = product.before;
    const std::string input_name = product.report["input"].get<std::string>();

    std::printf("%s on %s: %zu triangles, %zu buffers, ACMR %.4f -> %.4f, ATVR %.4f -> %.4f, %.3f s\n",
                method_name(plan.method), input_name.c_str(), product.mesh.triangle_count(), run.buffers.orders.size(),
                before.acmr, run.acmr_mean, before.atvr, run.atvr_mean, run.seconds);
    return 0;
}

}  // namespace animorder::tool
