// RESULTS.md's "Materials" (issue 18): from materials/*.json, each report's protocol and OVR table
// (double-sided materials drawn without culling, blended primitives out of the opaque pass) and,
// for inputs with blended primitives, the blend table: mis-sorted pairs and pixels of the input
// order, every method and the per-node back-to-front sort, with each method's share of the way
// from `original` to that sort in mis-sorted pixels; then the two goals on the bundled
// character (k = 5 buffers ≥ 90% of the way; the best single static order less than half of it);
// and, for a report with a `--single-sided` twin, the OVR both ways (the cost of double-sidedness).
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "markdown.h"
#include "report_text.h"
#include "sections.h"

namespace animorder::results {

namespace fs = std::filesystem;

namespace {

std::string percent1(double v) {
    if (!std::isfinite(v)) return kDash;
    char text[32];
    std::snprintf(text, sizeof text, "%.1f%%", v * 100.0);
    return text;
}

// Share of the way from the original order's mis-sorted pixel fraction to the bound's.
double way_to_bound(const Report& r, const BlendResult& b) {
    const Method* original = find_method(r, "original", kNaN);
    if (!original || !original->blend.present || !b.present) return kNaN;
    const double from = original->blend.missorted_pixel_fraction, to = r.blend_bound.missorted_pixel_fraction;
    return from != to ? (from - b.missorted_pixel_fraction) / (from - to) : kNaN;
}

bool is_kmeans(const Method& m) { return m.clusters >= 0; }

std::string blend_label(const Report& r, const Method& m) {
    std::string label = method_label(m, varies(r), false);
    if (is_kmeans(m)) label += " k=" + count(m.clusters) + (r.blend_clusters ? " --blend-clusters" : "");
    return label;
}

std::string blend_table(const Report& r) {
    std::vector<std::vector<std::string>> rows;
    auto row = [&](const std::string& name, const std::string& buffers, const BlendResult& b) {
        rows.push_back({name, buffers, f3(b.missorted_pair_fraction), f3(b.missorted_pixel_fraction),
                        percent1(way_to_bound(r, b))});
    };
    if (r.blend_input_order.present) row("input order", "1", r.blend_input_order);
    for (const Method& m : r.methods)
        if (m.blend.present) row(blend_label(r, m), std::to_string(m.buffers), m.blend);
    row("back-to-front sort per node (bound)", "per node", r.blend_bound);
    return table({"order", "buffers", "mis-sorted pairs", "mis-sorted pixels", "of the way to the bound"}, rows);
}

// The cost of double-sided materials: each report beside its `--single-sided` twin (the same
// input and methods with every material culled): OVR mean per method, both ways.
std::string double_sided_table(const Inputs& in) {
    std::vector<std::vector<std::string>> rows;
    for (const std::string& name : in.materials) {
        const Report& r = *in.get(name);
        if (r.single_sided) continue;
        const Report* culled = nullptr;
        for (const std::string& other : in.materials) {
            const Report& o = *in.get(other);
            if (o.single_sided && o.input == r.input && o.clips.size() == r.clips.size() &&
                o.eval_views == r.eval_views && o.eval_resolution == r.eval_resolution)
                culled = &o;
        }
        if (!culled) continue;
        for (const Method& m : r.methods) {
            const Method* c = nullptr;
            for (const Method& x : culled->methods)
                if (x.name == m.name && x.clusters == m.clusters && x.views == m.views &&
                    (same_lambda(x.lambda, m.lambda) || (std::isnan(x.lambda) && std::isnan(m.lambda))))
                    c = &x;
            if (!c) continue;
            rows.push_back({fs::path(name).stem().string(), method_label(m, varies(r), true), f3(m.ovr_mean),
                            f3(c->ovr_mean), percent1(m.ovr_mean / c->ovr_mean - 1.0)});
        }
    }
    if (rows.empty()) return "";
    return table({"report", "method", "OVR, double-sided drawn", "OVR, all culled (`--single-sided`)", "difference"},
                 rows, 2);
}

}  // namespace

Section materials_section(const Inputs& in) {
    Section s{"materials", "Materials: double-sided and blended primitives", ""};
    std::string& b = s.body;
    if (in.materials.empty()) {
        b += not_run("materials/*.json");
        return s;
    }
    b += "One `animorder evaluate` run per report of `materials/` (commands in `docs/results/reports/MANIFEST.md`). "
         "OVR counts the opaque pass: OPAQUE and MASK primitives, double-sided ones drawn without culling; blended "
         "primitives are drawn after it, depth test on and depth writes off, and are scored by their blend error "
         "(docs/DESIGN.md): the fraction of fragment pairs drawn nearer-before-farther and of covered pixels with "
         "at least one such pair. \"Of the way to the bound\" is (original − method) / (original − bound) in "
         "mis-sorted pixels, the bound being each node's blended triangles sorted back to front by centroid "
         "distance (not a lower bound: it mis-sorts intersecting and overlapping cards too).\n\n";

    // The goals, on the bundled character (the report without an input file name).
    std::vector<std::string> goal_lines;
    for (const std::string& name : in.materials) {
        const Report& r = *in.get(name);
        if (!r.blend_bound.present || r.input.find("bundled") == std::string::npos) continue;
        double best_static = kNaN;
        std::string best_static_name;
        for (const Method& m : r.methods) {
            if (!m.blend.present || is_kmeans(m) || m.name == "original") continue;
            const double w = way_to_bound(r, m.blend);
            if (std::isfinite(w) && !(w <= best_static)) best_static = w, best_static_name = m.name;
        }
        for (const Method& m : r.methods) {
            if (!m.blend.present || !is_kmeans(m) || m.clusters != 5) continue;
            const double w = way_to_bound(r, m.blend);
            std::string line = "- `" + name + "`, " + blend_label(r, m) + ": " + percent1(w) +
                               " of the way (goal ≥ 90%: " + (w >= 0.9 ? "met" : "not met") + ")";
            if (std::isfinite(best_static))
                line += "; the best single static order, " + best_static_name + ": " + percent1(best_static) +
                        " (goal < half of k = 5's: " + (best_static < w / 2 ? "met" : "not met") + ")";
            goal_lines.push_back(line + ".");
        }
    }
    if (!goal_lines.empty()) {
        b += "Goals of issue 18 on the bundled character's blended hair cards and cape:\n\n";
        for (const std::string& l : goal_lines) b += l + "\n";
        b += "\n";
    }
    const std::string sided = double_sided_table(in);
    if (!sided.empty())
        b += "The cost of double-sided materials: each run beside the same run with every material culled "
             "(`evaluate --single-sided`: orders and OVR as before issue 18), mean OVR:\n\n" +
             sided + "\n";
    for (const std::string& name : in.materials) {
        const Report& r = *in.get(name);
        b += "### " + fs::path(name).stem().string() + "\n\n";
        b += protocol(r) + (r.blend_clusters ? " k-means with `--blend-clusters`." : "") +
             (r.single_sided ? " Every material culled (`--single-sided`)." : "") + " Clips: " +
             clip_list(r) + ".\n\n" + compact_table(r) + "\n";
        if (r.blend_bound.present) b += "Blended primitives:\n\n" + blend_table(r) + "\n";
    }
    return s;
}

}  // namespace animorder::results
