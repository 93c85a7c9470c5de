// `animorder evaluate`: run methods (every value of the swept settings) and score each over the
// evaluation nodes of DESIGN.md; print a table shaped like the paper's Table 1, and write the
// JSON report and a CSV.
#include "commands.h"
#include "input.h"
#include "peak_memory.h"
#include "report.h"

#include "animorder/atomic_write.h"
#include "animorder/gltf_extension.h"
#include "animorder/triangle_matching.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace animorder::tool {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

std::vector<std::string> split_list(const std::string& text) {
    std::vector<std::string> items;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ','))
        if (!item.empty()) items.push_back(item);
    return items;
}

// One row of the table: a method with the settings it ran with.
struct Row {
    MethodResult result;
    MethodSettings settings;
    std::optional<uint64_t> peak_resident;  // the process's peak while the method ran (peak_memory.h)
};

// Every combination of the swept settings, for the methods that use them.
std::vector<std::pair<Method, MethodOptions>> plan_rows(const std::vector<Method>& methods, const MethodOptions& base,
                                                        const std::vector<double>& lambdas,
                                                        const std::vector<size_t>& ks,
                                                        const std::vector<size_t>& views) {
    std::vector<std::pair<Method, MethodOptions>> plan;
    for (Method n : methods)
        for (size_t li = 0; li < (method_uses_lambda(n) ? lambdas.size() : 1); ++li)
            for (size_t ki = 0; ki < (method_uses_clusters(n) ? ks.size() : 1); ++ki)
                for (size_t vi = 0; vi < (method_uses_clusters(n) ? views.size() : 1); ++vi) {
                    MethodOptions m = base;
                    m.settings.lambda = lambdas[li];
                    m.settings.clustering.clusters = ks[ki];
                    m.settings.clustering.views = views[vi];
                    plan.emplace_back(n, m);
                }
    return plan;
}

nlohmann::ordered_json blend_json(const BlendSummary& s) {
    return {{"missorted_pair_fraction", s.missorted_pair_fraction},
            {"missorted_pixel_fraction", s.missorted_pixel_fraction},
            {"pairs", s.pairs},
            {"covered_pixels", s.covered},
            {"nodes", s.nodes}};
}

// The blend error table (issue 18; DESIGN.md "Blend error"): every method's buffers on the blended
// primitives, the file's own order, and the per-node back-to-front sort (the bound). "of the way"
// is (original − method) / (original − bound) of the mis-sorted pixel fraction. Adds "blend" to
// the report's method entries and "blend_input_order", "blend_bound" to the report. Returns seconds.
double evaluate_blend_rows(const AnimatedMesh& mesh, const std::vector<Row>& rows, std::vector<MethodBuffers> buffers,
                           const EvaluationSettings& eval, const EvaluateOptions& options,
                           nlohmann::ordered_json& report) {
    const Clock::time_point start = Clock::now();
    MethodBuffers input;
    input.orders.emplace_back(mesh.triangle_count());
    for (size_t t = 0; t < mesh.triangle_count(); ++t) input.orders[0][t] = uint32_t(t);
    buffers.push_back(input);
    EvaluationSettings settings = eval;
    settings.progress = progress_printer(options.common, "blend error");
    const std::vector<BlendEvaluation> blend = evaluate_blend(mesh, buffers, settings);
    const BlendSummary& bound = blend.back().overall;
    double original = -1;
    for (size_t m = 0; m < rows.size(); ++m)
        if (rows[m].result.method == Method::Original) original = blend[m].overall.missorted_pixel_fraction;
    std::string table =
        "\n| blended primitives | k | buffers | mis-sorted pairs | mis-sorted pixels | of the way to the bound |\n"
        "|---|---|---|---|---|---|\n";
    auto add_row = [&](const std::string& name, const std::string& k, const std::string& count, const BlendSummary& s) {
        char cells[256];
        const double span = original - bound.missorted_pixel_fraction;
        const std::string way =
            original >= 0 && span > 0
                ? format_number(std::round(1000 * (original - s.missorted_pixel_fraction) / span) / 10) + "%"
                : "";
        std::snprintf(cells, sizeof cells, "| %s | %s | %s | %.4f | %.4f | %s |\n", name.c_str(), k.c_str(),
                      count.c_str(), s.missorted_pair_fraction, s.missorted_pixel_fraction, way.c_str());
        table += cells;
    };
    add_row("input order", "", "1", blend[rows.size()].overall);
    for (size_t m = 0; m < rows.size(); ++m) {
        const MethodResult& run = rows[m].result;
        if (!method_has_buffers(run.method)) continue;
        add_row(method_name(run.method),
                method_uses_clusters(run.method) ? std::to_string(rows[m].settings.clustering.clusters) : "",
                std::to_string(run.buffers.orders.size()), blend[m].overall);
        nlohmann::ordered_json entry = blend_json(blend[m].overall);
        entry["per_clip"] = nlohmann::ordered_json::array();
        for (size_t c = 0; c < mesh.clips.size(); ++c) {
            nlohmann::ordered_json clip = blend_json(blend[m].per_clip[c]);
            clip["clip"] = mesh.clips[c].name;
            entry["per_clip"].push_back(clip);
        }
        report["methods"][m]["blend"] = entry;
    }
    add_row("back-to-front per node (bound)", "", "per node", bound);
    std::fputs(table.c_str(), stdout);
    report["blend_input_order"] = blend_json(blend[rows.size()].overall);
    report["blend_bound"] = blend_json(bound);
    return seconds_since(start);
}

// --stored: the orders and tables of INPUT's ANIMORDER_animated_triangle_orders extension as a
// method (read_orders_extension checks them first). Each order becomes a permutation of the
// loaded triangles (primitives without orders keep theirs); each loaded clip takes the table of
// the stored clip of its name, its keyframes mapped by time as the runtime does.
MethodBuffers stored_buffers(const AnimatedMesh& mesh, const std::string& path) {
    const OrdersExtensionCheck ext = read_orders_extension(path);
    MethodBuffers m;
    m.orders.assign(ext.buffer_count, std::vector<uint32_t>(mesh.triangle_count()));
    for (const Primitive& p : mesh.primitives) {
        const size_t first = p.first_index / 3, count = p.index_count / 3;
        const ExtensionPrimitive* e = nullptr;
        for (const ExtensionPrimitive& x : ext.primitives)
            if (x.mesh == p.source_mesh && x.primitive == p.source_primitive) e = &x;
        for (uint32_t b = 0; b < ext.buffer_count; ++b) {
            std::vector<uint32_t> perm;
            if (e) {
                if (e->indices.size() != p.index_count)
                    throw std::runtime_error(path + ": primitive " + p.name + " reads back with another index count");
                perm = triangle_permutation(e->indices.data(), e->orders.data() + b * p.index_count, count);
            } else {
                perm.resize(count);
                for (size_t t = 0; t < count; ++t) perm[t] = uint32_t(t);
            }
            for (size_t t = 0; t < count; ++t) m.orders[b][first + t] = uint32_t(first + perm[t]);
        }
    }
    for (const Clip& c : mesh.clips) {
        const ExtensionClip* e = nullptr;
        for (const ExtensionClip& x : ext.clips)
            if (x.name == c.name) e = &x;
        if (!e)
            throw std::runtime_error(path + ": clip '" + c.name +
                                     "' has no stored table (keep the stored clips with --clip NAME)");
        SelectionTable t;
        t.keyframes = uint32_t(c.keyframe_count);
        t.theta_steps = e->theta_steps;
        t.phi_steps = e->phi_steps;
        const size_t cells = size_t(e->theta_steps) * e->phi_steps;
        for (size_t f = 0; f < c.keyframe_count; ++f) {
            const double k =
                std::floor((c.start_time_s + double(f) / c.sample_rate - e->start_time) * e->sample_rate + 0.5);
            const size_t g = k <= 0 ? 0 : (k >= double(e->keyframes - 1) ? e->keyframes - 1 : size_t(k));
            t.cells.insert(t.cells.end(), e->cells.begin() + ptrdiff_t(g * cells),
                           e->cells.begin() + ptrdiff_t((g + 1) * cells));
        }
        m.tables.push_back(std::move(t));
        m.table_base.push_back(e->buffer_base);
    }
    return m;
}

}  // namespace

int run_evaluate(const EvaluateOptions& options) {
    using json = nlohmann::ordered_json;
    const Clock::time_point start = Clock::now();
    const MethodOptions& base = options.method_options;
    const std::vector<std::string> names = split_list(options.methods);
    if (names.empty()) throw std::runtime_error("--methods names no method");
    std::vector<Method> methods;
    for (const std::string& n : names) methods.push_back(parse_method(n));
    const MethodSettings& b = base.settings;
    const std::vector<double> lambdas = base.lambdas.empty() ? std::vector<double>{b.lambda} : base.lambdas;
    const std::vector<size_t> ks =
        base.cluster_list.empty() ? std::vector<size_t>{b.clustering.clusters} : base.cluster_list;
    const std::vector<size_t> views = base.view_list.empty() ? std::vector<size_t>{b.clustering.views} : base.view_list;
    std::vector<std::pair<Method, MethodSettings>> plan;
    for (const auto& [n, m] : plan_rows(methods, base, lambdas, ks, views)) {
        plan.emplace_back(n, method_settings(m, options.common, n));
        validate_method_settings(plan.back().second);
    }
    std::vector<std::string> outputs;
    for (const std::string* p : {&options.report_path, &options.csv_path})
        if (!p->empty()) outputs.push_back(*p);
    check_outputs_before_loading(outputs, options.common);

    std::string input_name;
    CommonOptions common = options.common;
    common.threads = b.clustering.threads;
    std::vector<std::string> files_read;
    AnimatedMesh loaded = load_drawable_input(common, input_name, &files_read);
    check_output_paths(outputs, files_read);
    if (options.single_sided)  // the cost of double-sidedness: orders and OVR with every back face culled
        for (Primitive& p : loaded.primitives) p.double_sided = false;
    const AnimatedMesh& mesh = loaded;
    // The stored orders read now, so that a file without them is refused before the methods run.
    std::vector<MethodBuffers> stored;
    if (options.stored) stored.push_back(stored_buffers(mesh, options.common.input));
    std::vector<Row> rows;
    for (const auto& [n, m] : plan) {
        std::string label = method_name(n);
        if (method_uses_lambda(n) && lambdas.size() > 1) label += " lambda=" + format_number(m.lambda);
        if (method_uses_clusters(n) && ks.size() > 1) label += " k=" + std::to_string(m.clustering.clusters);
        if (method_uses_clusters(n) && views.size() > 1) label += " views=" + std::to_string(m.clustering.views);
        note(options.common, "running " + label);
        // Each row's settings were validated with the plan (before loading): not checked again.
        const PeakResident memory;
        rows.push_back(
            {about_input(options.common, [&, n = n, m = m] { return run_validated_method(mesh, n, m); }), m, {}});
        rows.back().peak_resident = memory.peak();
    }
    const double methods_s = seconds_since(start);

    EvaluationSettings eval = options.evaluation;
    eval.threads = b.clustering.threads;
    eval.progress = progress_printer(options.common, "evaluating");
    note(options.common, "evaluating " + std::to_string(rows.size()) + " methods at " +
                             std::to_string(mesh.keyframe_count() * eval.views) + " nodes (" +
                             std::to_string(mesh.keyframe_count()) + " keyframes x " + std::to_string(eval.views) +
                             " views, " + std::to_string(eval.resolution) + "^2)");
    std::vector<MethodBuffers> buffers;
    for (const Row& r : rows) buffers.push_back(r.result.buffers);
    for (MethodBuffers& m : stored) buffers.push_back(std::move(m));
    const Clock::time_point eval_start = Clock::now();
    const std::vector<OrderEvaluation> results =
        about_input(options.common, [&] { return evaluate_methods(mesh, buffers, eval); });
    const double eval_s = seconds_since(eval_start);
    const size_t nodes = mesh.keyframe_count() * eval.views;

    json report = report_header(mesh, input_name);
    report["settings"] = {{"methods", names},
                          {"lambda", lambdas},
                          {"clusters", ks},
                          {"views", views},
                          {"resolution", b.clustering.resolution},
                          {"seed", b.clustering.seed},
                          {"nehab_clusters", b.nehab_clusters},
                          {"nehab_views", b.nehab_views},
                          {"nehab_all_keyframes", b.nehab_all_keyframes},
                          {"blend_clusters", b.blend_clusters},
                          {"front_levels", b.clustering.front_levels},
                          {"single_sided", options.single_sided},
                          {"cache_size", options.common.cache_size},
                          {"eval_views", eval.views},
                          {"eval_resolution", eval.resolution},
                          {"eval_seed", eval.seed},
                          {"clips", options.common.clips}};
    report["clips"] = json::array();
    for (const Clip& c : mesh.clips) report["clips"].push_back({{"name", c.name}, {"keyframes", c.keyframe_count}});
    report["methods"] = json::array();
    // A clip whose nodes draw nothing (every keyframe a point: a clip that hides the mesh) has no
    // overdraw ratio: null in the report, a dash in the table.
    const auto ovr_json = [](const OverdrawSummary& s, double value) { return s.nodes ? json(value) : json(nullptr); };
    const auto ovr_cell = [](const OverdrawSummary& s) {
        char cell[32];
        std::snprintf(cell, sizeof cell, s.nodes ? " %.3f |" : " — |", s.ovr_mean);
        return std::string(cell);
    };
    std::string table = "| method | lambda | k | views | buffers | ACMR | ATVR | OVR mean | OVR pooled | time s |";
    std::string rule = "|---|---|---|---|---|---|---|---|---|---|";
    for (const Clip& c : mesh.clips) {
        table += " " + c.name + " |";
        rule += "---|";
    }
    table += "\n" + rule + "\n";
    std::string csv = "method,lambda,clusters,views,buffers,acmr,atvr,ovr_mean,ovr_pooled,time_s\n";
    for (size_t m = 0; m < rows.size(); ++m) {
        const MethodResult& run = rows[m].result;
        const MethodSettings& s = rows[m].settings;
        const OrderEvaluation& r = results[m];
        const char* name = method_name(run.method);
        json entry = method_entry(mesh, run, s, rows[m].peak_resident);
        const bool per_node = !method_has_buffers(run.method);
        entry["buffers"] = per_node ? nodes : run.buffers.orders.size();
        entry["ovr_mean"] = r.overall.ovr_mean;
        entry["ovr_pooled"] = r.overall.ovr_pooled;
        entry["per_clip"] = json::array();
        for (size_t c = 0; c < mesh.clips.size(); ++c)
            entry["per_clip"].push_back(
                {{"clip", mesh.clips[c].name},
                 {"ovr_mean", ovr_json(r.per_clip[c], r.per_clip[c].ovr_mean)},
                 {"ovr_pooled", ovr_json(r.per_clip[c], r.per_clip[c].ovr_pooled)},
                 {"nodes", r.per_clip[c].nodes},
                 {"time_s", method_runs_per_clip(run.method) && c < run.run_seconds.size() ? json(run.run_seconds[c])
                                                                                           : json(nullptr)}});
        const std::string lambda = method_uses_lambda(run.method) ? format_number(s.lambda) : "";
        const std::string k = method_uses_clusters(run.method) ? std::to_string(s.clustering.clusters) : "";
        const std::string v = method_uses_clusters(run.method) ? std::to_string(s.clustering.views) : "";
        const std::string count = per_node ? "per node" : std::to_string(run.buffers.orders.size());
        char cells[256];
        std::snprintf(cells, sizeof cells, "| %s | %s | %s | %s | %s | %.3f | %.3f | %.3f | %.3f | %.1f |", name,
                      lambda.c_str(), k.c_str(), v.c_str(), count.c_str(), run.acmr_mean, run.atvr_mean,
                      r.overall.ovr_mean, r.overall.ovr_pooled, run.seconds);
        table += cells;
        for (size_t c = 0; c < mesh.clips.size(); ++c) table += ovr_cell(r.per_clip[c]);
        table += "\n";
        std::snprintf(cells, sizeof cells, "%s,%s,%s,%s,%zu,%.6f,%.6f,%.6f,%.6f,%.6f\n", name, lambda.c_str(),
                      k.c_str(), v.c_str(), per_node ? nodes : run.buffers.orders.size(), run.acmr_mean, run.atvr_mean,
                      r.overall.ovr_mean, r.overall.ovr_pooled, run.seconds);
        csv += cells;
        report["methods"].push_back(entry);
    }
    if (options.stored) {
        const OrderEvaluation& r = results.back();
        char cells[256];
        std::snprintf(cells, sizeof cells, "| stored |  |  |  | %zu |  |  | %.3f | %.3f |  |",
                      buffers.back().orders.size(), r.overall.ovr_mean, r.overall.ovr_pooled);
        table += cells;
        json entry = {{"name", "stored"},
                      {"buffers", buffers.back().orders.size()},
                      {"ovr_mean", r.overall.ovr_mean},
                      {"ovr_pooled", r.overall.ovr_pooled},
                      {"per_clip", json::array()}};
        for (size_t c = 0; c < mesh.clips.size(); ++c) {
            table += ovr_cell(r.per_clip[c]);
            entry["per_clip"].push_back({{"clip", mesh.clips[c].name},
                                         {"ovr_mean", ovr_json(r.per_clip[c], r.per_clip[c].ovr_mean)},
                                         {"ovr_pooled", ovr_json(r.per_clip[c], r.per_clip[c].ovr_pooled)},
                                         {"nodes", r.per_clip[c].nodes}});
        }
        table += "\n";
        report["methods"].push_back(entry);
    }
    std::fputs(table.c_str(), stdout);
    double blend_s = 0;
    if (has_blended_primitives(mesh)) {
        blend_s = evaluate_blend_rows(mesh, rows, buffers, eval, options, report);
        note(options.common, "blend evaluation took " + format_number(blend_s) + " s");
    }
    report["nodes"] = nodes;
    report["timings_s"] = {{"methods", methods_s}, {"evaluation", eval_s}, {"total", seconds_since(start)}};
    if (blend_s > 0) report["timings_s"]["blend_evaluation"] = blend_s;
    report["machine"] = {
        {"threads", b.clustering.threads ? b.clustering.threads : std::thread::hardware_concurrency()}};
    OutputSet files;
    if (!options.report_path.empty()) files.add(options.report_path, report_text(report));
    if (!options.csv_path.empty()) files.add(options.csv_path, csv);
    files.commit();
    note(options.common,
         "evaluation took " + format_number(eval_s) + " s (" + format_number(seconds_since(start)) + " s in all)");
    return 0;
}

}  // namespace animorder::tool
