#include "report.h"

#include "animorder/clustering.h"

namespace animorder::tool {

nlohmann::ordered_json report_header(const AnimatedMesh& mesh, const std::string& input_name) {
    nlohmann::ordered_json report;
    report["tool"] = "animorder";
    report["version"] = ANIMORDER_VERSION;
    report["input"] = input_name;
    report["triangles"] = mesh.triangle_count();
    report["vertices"] = mesh.vertex_count;
    // Clip files made for a differently proportioned skeleton, and how each was retargeted.
    nlohmann::ordered_json retargeted = nlohmann::ordered_json::array();
    for (const Clip& clip : mesh.clips)
        if (!clip.retargeted.empty()) retargeted.push_back({{"clip", clip.name}, {"note", clip.retargeted}});
    if (!retargeted.empty()) report["retargeted_clips"] = retargeted;
    return report;
}

nlohmann::ordered_json cache_stats_json(const VertexCacheStats& stats) {
    return {{"acmr", stats.acmr}, {"atvr", stats.atvr}, {"misses", stats.misses}};
}

// A name or path that is not UTF-8 (Linux allows any bytes) is written with U+FFFD for the bad
// bytes rather than failing after the work is done.
std::string report_text(const nlohmann::ordered_json& report) {
    return report.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

namespace {

nlohmann::ordered_json clustering_details(const AnimatedMesh& mesh, const MethodResult& r, const MethodSettings& m) {
    using json = nlohmann::ordered_json;
    double assignment = 0, update = 0, rasterization = 0, held_out = 0;
    bool checked = false;
    json runs = json::array();
    for (size_t i = 0; i < r.runs.size(); ++i) {
        rasterization += r.runs[i].seconds_rasterization;
        held_out += r.runs[i].seconds_held_out;
        checked = checked || !r.runs[i].held_out_distance.empty();
        json iterations = json::array();
        for (size_t it = 0; it < r.runs[i].iterations.size(); ++it) {
            const ClusteringIteration& x = r.runs[i].iterations[it];
            assignment += x.seconds_assignment;
            update += x.seconds_update;
            iterations.push_back({{"iteration", it + 1},
                                  {"mean_ovr", x.mean_ovr},
                                  {"reassigned", x.reassigned},
                                  {"reseeded", x.reseeded},
                                  {"improved_buffers", x.accepted},
                                  {"seconds_assignment", x.seconds_assignment},
                                  {"seconds_update", x.seconds_update}});
        }
        runs.push_back({{"clips", method_is_joint(r.method) ? json("all") : json(mesh.clips[i].name)},
                        {"nodes", r.runs[i].assignment.size()},
                        {"view_radius", r.run_radius[i]},
                        {"converged", r.runs[i].converged},
                        {"stop", r.runs[i].stop_reason},
                        {"best_iteration", r.runs[i].best_iteration + 1},
                        {"kept_nodes", r.runs[i].kept_nodes},
                        {"kept_bytes", r.runs[i].kept_bytes},
                        {"iterations", iterations}});
        if (!r.runs[i].held_out_distance.empty()) {
            size_t kept = 0;
            for (const uint8_t d : r.runs[i].held_out_distance) kept += d;
            runs.back()["held_out"] = {{"nodes", r.runs[i].held_out_nodes},
                                       {"distance_orders_kept", kept},
                                       {"seconds", r.runs[i].seconds_held_out}};
        }
    }
    json details = {{"clusters", m.clustering.clusters},
            {"views", m.clustering.views},
            {"resolution", m.clustering.resolution},
            {"seed", m.clustering.seed},
            {"distance", distance_name(m.clustering.distance)},
            {"update", update_name(m.clustering.update)},
            {"patches", r.patch_count},
            {"runs", runs},
            {"stages_s",
             {{"patches", r.seconds_patches},
              {"rasterization", rasterization},
              {"assignment", assignment},
              {"update", update}}}};
    if (checked) details["stages_s"]["held_out"] = held_out;
    return details;
}

}  // namespace

nlohmann::ordered_json method_entry(const AnimatedMesh& mesh, const MethodResult& r, const MethodSettings& m,
                                    std::optional<uint64_t> peak_resident) {
    using json = nlohmann::ordered_json;
    const bool clustered = method_uses_clusters(r.method);
    json entry = {{"name", method_name(r.method)},
                  {"lambda", method_uses_lambda(r.method) ? json(m.lambda) : json(nullptr)},
                  {"clusters", clustered ? json(m.clustering.clusters) : json(nullptr)},
                  {"views", clustered ? json(m.clustering.views) : json(nullptr)},
                  {"buffers", r.buffers.orders.size()},
                  {"acmr", r.acmr_mean},
                  {"atvr", r.atvr_mean},
                  {"ovr_mean", nullptr},
                  {"ovr_pooled", nullptr},
                  {"time_s", r.seconds},
                  {"peak_rss_bytes", peak_resident ? json(*peak_resident) : json(nullptr)}};
    json details;
    if (clustered)
        details = clustering_details(mesh, r, m);
    else if (r.method == Method::StaticNehab06)
        details = {{"planar_clusters", r.patch_count}};
    else if (r.method == Method::TipsifyPerFrame || r.method == Method::Oracle)
        details = {{"patches", r.patch_count}};
    else
        details = {{"patches", r.patch_count}, {"hard_boundaries", r.hard_boundary_count}};
    for (auto it = details.begin(); it != details.end(); ++it) entry[it.key()] = it.value();
    return entry;
}

}  // namespace animorder::tool
