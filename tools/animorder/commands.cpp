// inspect and optimize: load the input (or the bundled character), run, print and write.
#include "commands.h"

#include "output.h"
#include "report.h"

#include "heatmap_image.h"

#include "animorder/evaluation.h"
#include "animorder/io.h"
#include "animorder/methods.h"
#include "animorder/sidecar.h"
#include "animorder/overdraw.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <sstream>
#include <string>
#include <thread>

namespace animorder::tool {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

const char* const kBundledName = "procedural-character (bundled)";

// The input of the commands that reorder: load_animated_input's mesh, refused when it has
// nothing to draw.
AnimatedMesh load_input(const CommonOptions& common, std::string& input_name) {
    const AnimatedMesh mesh = load_animated_input(common, input_name);
    // A mesh with no area at its first keyframe has nothing to draw, so nothing to reorder.
    double area = 0;
    const float* p = mesh.keyframe_count() ? mesh.keyframe(0) : nullptr;
    for (size_t t = 0; p && t < mesh.indices.size() && area == 0; t += 3) {
        const float *a = p + 3 * mesh.indices[t], *b = p + 3 * mesh.indices[t + 1], *c = p + 3 * mesh.indices[t + 2];
        const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        area += std::fabs(u[1] * v[2] - u[2] * v[1]) + std::fabs(u[2] * v[0] - u[0] * v[2]) + std::fabs(u[0] * v[1] - u[1] * v[0]);
    }
    if (area == 0) throw std::runtime_error(input_name + ": every triangle has zero area: nothing to reorder");
    return mesh;
}

// The view radius R of every clip (DESIGN.md framing): the largest per-keyframe bounding radius.
std::vector<float> clip_radii(const AnimatedMesh& mesh) {
    const Framing all = frame_keyframes(mesh.keyframe_positions.data(), mesh.keyframe_count(), mesh.vertex_count,
                                        mesh.indices.data(), mesh.indices.size());
    std::vector<float> radii;
    for (const Clip& c : mesh.clips) {
        float r = 0;
        for (size_t f = 0; f < c.keyframe_count; ++f) r = std::max(r, all.radii[c.first_keyframe + f]);
        radii.push_back(r);
    }
    return radii;
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
    const std::vector<float> radii = clip_radii(mesh);
    for (size_t i = 0; i < mesh.clips.size(); ++i) {
        const Clip& c = mesh.clips[i];
        std::printf("  clip %-12s %.3f s  %zu keyframes at %g/s  bounding radius %.4g\n", c.name.c_str(), c.duration_s,
                    c.keyframe_count, c.sample_rate, radii[i]);
    }
}

}  // namespace

// Notes go to stderr, so stdout stays clean for text or JSON a script may read.
void note(const CommonOptions& common, const std::string& text) {
    if (!common.quiet) std::fprintf(stderr, "animorder: %s\n", text.c_str());
}

AnimatedMesh load_animated_input(const CommonOptions& common, std::string& input_name) {
    std::vector<std::string> clip_files, clip_names;
    for (const std::string& c : common.clips) (std::filesystem::exists(c) ? clip_files : clip_names).push_back(c);
    AnimatedMesh mesh;
    if (common.input.empty()) {
        if (!clip_files.empty()) throw std::runtime_error("clip files need an input character file");
        note(common, "no input file given: using the bundled procedural character");
        input_name = kBundledName;
        mesh = make_procedural_character();
    } else {
        input_name = common.input;
        mesh = load_character(common.input, clip_files);
        note(common, "loaded " + common.input + ": " + std::to_string(mesh.triangle_count()) + " triangles, " +
                         std::to_string(mesh.clips.size()) + " clips, " + std::to_string(mesh.keyframe_count()) +
                         " keyframes");
    }
    if (!clip_names.empty()) mesh = select_clips(mesh, clip_names);
    return mesh;
}

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
    for (const Primitive& p : mesh.primitives) {
        std::vector<uint8_t> used(mesh.vertex_count, 0);
        size_t vertices = 0;
        for (size_t i = p.first_index; i < p.first_index + p.index_count; ++i)
            vertices += used[mesh.indices[i]] ? 0 : (used[mesh.indices[i]] = 1);
        report["primitives"].push_back({{"name", p.name}, {"triangles", p.index_count / 3}, {"vertices", vertices}});
    }
    const std::vector<float> radii = clip_radii(mesh);
    for (size_t i = 0; i < mesh.clips.size(); ++i)
        report["clips"].push_back({{"name", mesh.clips[i].name},
                                   {"duration_s", mesh.clips[i].duration_s},
                                   {"keyframes", mesh.clips[i].keyframe_count},
                                   {"sample_rate", mesh.clips[i].sample_rate},
                                   {"bounding_radius", radii[i]}});
    std::fputs(report_text(report).c_str(), stdout);
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
    auto last = std::make_shared<double>(-1.0);
    return [stage, start, last](size_t done, size_t total) {
        const double now = seconds_since(start);
        if (done != total && now - *last < 0.5) return;  // at most two updates a second
        *last = now;
        std::fprintf(stderr, "\ranimorder: %s: %zu/%zu nodes, %.1f s", stage.c_str(), done, total, now);
        if (done == total) std::fputc('\n', stderr);
        std::fflush(stderr);
    };
}

// Numbers in labels and tables: the shortest form that reads back the same ("0.85", "3").
std::string format_number(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", value);
    return text;
}

// The DESIGN.md method names; oracle is a bound evaluated per node, so optimize has no output for it.
void check_method_name(const std::string& name, bool for_optimize) {
    if (name == "oracle") {
        if (for_optimize) throw std::runtime_error("oracle is a bound (a new order at every node), not an order to ship; use evaluate --methods oracle");
        return;
    }
    if (name == "single" || name == "joint" || name == "tipsify-per-frame") return;
    try {
        parse_static_method(name);
    } catch (const InvalidInput&) {
        throw std::runtime_error("unknown method '" + name +
                                 "' (known: original, static-sander07, static-nehab06, tipsify-per-frame, meshopt, "
                                 "single, joint, oracle)");
    }
}

void check_lambda(double lambda) {
    if (!std::isfinite(lambda)) throw std::runtime_error("--lambda must be a finite number");
}

// One method run on the whole character: its buffers, how it picks them, and its report entry.
struct MethodRun {
    std::string name;
    MethodBuffers buffers;
    Framing framing;  // for the sidecar's keyframe centres
    VertexCacheStats cache;  // of the first buffer; "acmr" in reports is the mean over buffers
    double acmr_mean = 0, atvr_mean = 0;
    double seconds = 0;
    uint32_t fallback = 0;  // the buffer most nodes chose: what viewers without the table draw
    nlohmann::ordered_json details;
    MethodOptions options;              // the settings it ran with
    std::vector<double> clip_seconds;   // single: each clip's k-means run
};

bool uses_lambda(const std::string& name) { return name != "original" && name != "meshopt" && name != "static-nehab06"; }
bool uses_clusters(const std::string& name) { return name == "single" || name == "joint"; }

DistanceVariant parse_distance(const std::string& name) {
    if (name == "jcgt") return DistanceVariant::Jcgt;
    if (name == "i3d") return DistanceVariant::I3d;
    throw std::runtime_error("--distance must be jcgt or i3d, not '" + name + "'");
}

UpdateRule parse_update(const std::string& name) {
    if (name == "monotone") return UpdateRule::Monotone;
    if (name == "paper") return UpdateRule::Paper;
    throw std::runtime_error("--update must be monotone or paper, not '" + name + "'");
}

void check_method_options(const MethodOptions& m) {
    check_lambda(m.lambda);
    if (m.clusters == 0 || m.clusters > 255) throw std::runtime_error("-k/--clusters must be between 1 and 255");
    if (!(m.min_separation >= 0 && m.min_separation <= 180))
        throw std::runtime_error("--min-separation must be between 0 and 180 degrees");
    icosphere_subdivisions_for(m.views);  // throws for a count that is no icosphere
    parse_distance(m.distance);
    parse_update(m.update);
}

MethodRun run_method(const AnimatedMesh& mesh, const std::string& name, const MethodOptions& m,
                     const CommonOptions& common) {
    MethodRun run;
    run.name = name;
    run.options = m;
    const Clock::time_point start = Clock::now();
    if (name == "single" || name == "joint") {
        ClusteringSettings settings;
        settings.clusters = m.clusters;
        settings.views = m.views;
        settings.resolution = m.resolution;
        settings.seed = m.seed;
        settings.min_separation_deg = m.min_separation;
        settings.max_iterations = m.max_iterations;
        settings.distance = parse_distance(m.distance);
        settings.update = parse_update(m.update);
        settings.threads = m.threads;
        settings.log = [&common, name](const std::string& line) { note(common, name + ": " + line); };
        settings.progress = progress_printer(common, name + ": assigning nodes");
        const AnimatedMethodResult r = run_han_sander(mesh, name == "joint", m.lambda, common.cache_size, settings);
        run.buffers = r.buffers;
        run.framing = r.framing;
        std::vector<size_t> chosen(r.buffers.orders.size(), 0);
        for (size_t i = 0; i < r.runs.size(); ++i)
            for (uint32_t c : r.runs[i].assignment) ++chosen[(name == "joint" ? 0 : i * m.clusters) + c];
        run.fallback = uint32_t(std::max_element(chosen.begin(), chosen.end()) - chosen.begin());
        double raster = 0, update = 0, rasterization = 0;
        nlohmann::ordered_json runs = nlohmann::ordered_json::array();
        for (size_t i = 0; i < r.runs.size(); ++i) {
            rasterization += r.runs[i].seconds_rasterization;
            double run_seconds = r.runs[i].seconds_rasterization;
            for (const ClusteringIteration& x : r.runs[i].iterations) run_seconds += x.seconds_assignment + x.seconds_update;
            run.clip_seconds.push_back(run_seconds);
            nlohmann::ordered_json iterations = nlohmann::ordered_json::array();
            for (size_t it = 0; it < r.runs[i].iterations.size(); ++it) {
                const ClusteringIteration& x = r.runs[i].iterations[it];
                raster += x.seconds_assignment;
                update += x.seconds_update;
                iterations.push_back({{"iteration", it + 1},
                                      {"mean_ovr", x.mean_ovr},
                                      {"reassigned", x.reassigned},
                                      {"reseeded", x.reseeded},
                                      {"improved_buffers", x.accepted},
                                      {"seconds_assignment", x.seconds_assignment},
                                      {"seconds_update", x.seconds_update}});
            }
            runs.push_back({{"clips", name == "joint" ? nlohmann::ordered_json("all") : nlohmann::ordered_json(mesh.clips[i].name)},
                            {"nodes", r.runs[i].assignment.size()},
                            {"view_radius", r.run_radius[i]},
                            {"converged", r.runs[i].converged},
                            {"stop", r.runs[i].stop_reason},
                            {"best_iteration", r.runs[i].best_iteration + 1},
                            {"iterations", iterations}});
        }
        run.details = {{"clusters", m.clusters},
                       {"views", m.views},
                       {"resolution", m.resolution},
                       {"seed", m.seed},
                       {"distance", m.distance},
                       {"update", m.update},
                       {"patches", r.patches.patch_count()},
                       {"runs", runs},
                       {"stages_s",
                        {{"patches", r.seconds_patches},
                         {"rasterization", rasterization},
                         {"assignment", raster},
                         {"update", update}}}};
    } else if (name == "tipsify-per-frame") {
        // static-sander07 sorted at every keyframe: the paper's "Tipsify" column. A keyframe's table
        // cell names its own buffer, so the sidecar and glTF writers take it as they are (clips of up
        // to 256 keyframes; the table cells are bytes).
        StaticMethodSettings settings;
        settings.lambda = m.lambda;
        settings.cache_size = common.cache_size;
        size_t patches = 0;
        for (size_t f = 0; f < mesh.keyframe_count(); ++f) {
            settings.keyframe = f;
            StaticMethodResult r = run_static_method(mesh, StaticMethod::StaticSander07, settings);
            patches = r.patch_count;
            run.buffers.orders.push_back(std::move(r.order));
            run.buffers.keyframe_buffer.push_back(uint32_t(f));
        }
        run.framing = frame_keyframes(mesh.keyframe_positions.data(), mesh.keyframe_count(), mesh.vertex_count,
                                      mesh.indices.data(), mesh.indices.size());
        bool fits = true;
        for (const Clip& c : mesh.clips) fits = fits && c.keyframe_count <= 256;
        for (size_t c = 0; fits && c < mesh.clips.size(); ++c) {
            SelectionTable t;
            t.keyframes = uint32_t(mesh.clips[c].keyframe_count);
            t.theta_steps = 2;
            t.phi_steps = 1;
            for (uint32_t f = 0; f < t.keyframes; ++f) t.cells.insert(t.cells.end(), 2, uint8_t(f));
            run.buffers.tables.push_back(t);
            run.buffers.table_base.push_back(uint32_t(mesh.clips[c].first_keyframe));
        }
        run.details = {{"patches", patches}};
    } else if (name == "oracle") {
        // A bound, not a product: every evaluation node draws the patches sorted front-to-back for
        // itself (evaluation.cpp). Its ACMR is the mean over the orders of 12 icosahedron views at
        // each clip's first keyframe.
        auto patches = std::make_shared<MeshPatches>(build_mesh_patches(mesh, m.lambda, common.cache_size));
        run.buffers.front_to_back = patches;
        run.framing = frame_keyframes(mesh.keyframe_positions.data(), mesh.keyframe_count(), mesh.vertex_count,
                                      mesh.indices.data(), mesh.indices.size());
        const std::vector<float> views = icosphere_directions(0);
        std::vector<uint32_t> indices(mesh.indices.size());
        size_t samples = 0;
        for (const Clip& clip : mesh.clips) {
            const std::vector<uint32_t> first = {uint32_t(clip.first_keyframe)};
            const std::vector<float> centroids = patch_centroids(mesh, *patches, run.framing, first);
            for (size_t v = 0; v < views.size() / 3; ++v) {
                const float eye[3] = {3 * run.framing.radius * views[3 * v], 3 * run.framing.radius * views[3 * v + 1],
                                      3 * run.framing.radius * views[3 * v + 2]};
                const std::vector<uint32_t> order = patch_order_to_triangle_order(
                    *patches, front_to_back_patch_order(centroids.data(), patches->patch_count(), eye));
                apply_triangle_order(indices.data(), mesh.indices.data(), order.data(), mesh.triangle_count());
                const VertexCacheStats s = analyze_mesh_vertex_cache(mesh, indices, common.cache_size);
                run.acmr_mean += s.acmr;
                run.atvr_mean += s.atvr;
                ++samples;
            }
        }
        run.acmr_mean /= double(std::max<size_t>(1, samples));
        run.atvr_mean /= double(std::max<size_t>(1, samples));
        run.details = {{"patches", patches->patch_count()}};
        run.seconds = seconds_since(start);
        return run;
    } else {
        StaticMethodSettings settings;
        settings.lambda = m.lambda;
        settings.cache_size = common.cache_size;
        settings.keyframe = m.keyframe;
        settings.nehab_clusters = m.nehab_clusters;
        settings.nehab_views = m.nehab_views;
        settings.nehab_resolution = m.resolution;
        settings.nehab_all_keyframes = m.nehab_all_keyframes;
        settings.threads = m.threads;
        const StaticMethod method = parse_static_method(name);
        StaticMethodResult r = run_static_method(mesh, method, settings);
        run.buffers.orders.push_back(std::move(r.order));
        run.framing = frame_keyframes(mesh.keyframe_positions.data(), mesh.keyframe_count(), mesh.vertex_count,
                                      mesh.indices.data(), mesh.indices.size());
        for (const Clip& c : mesh.clips) {  // one buffer: a table that always says 0
            SelectionTable t;
            t.keyframes = uint32_t(c.keyframe_count);
            t.theta_steps = 2;
            t.phi_steps = 1;
            t.cells.assign(size_t(t.keyframes) * 2, 0);
            run.buffers.tables.push_back(t);
            run.buffers.table_base.push_back(0);
        }
        if (method == StaticMethod::StaticNehab06)
            run.details = {{"planar_clusters", r.patch_count}};
        else
            run.details = {{"patches", r.patch_count}, {"hard_boundaries", r.hard_boundary_count}};
    }
    run.seconds = seconds_since(start);
    std::vector<uint32_t> indices(mesh.indices.size());
    for (size_t b = 0; b < run.buffers.orders.size(); ++b) {
        apply_triangle_order(indices.data(), mesh.indices.data(), run.buffers.orders[b].data(), mesh.triangle_count());
        const VertexCacheStats s = analyze_mesh_vertex_cache(mesh, indices, common.cache_size);
        if (b == 0) run.cache = s;
        run.acmr_mean += s.acmr / double(run.buffers.orders.size());
        run.atvr_mean += s.atvr / double(run.buffers.orders.size());
    }
    return run;
}

nlohmann::ordered_json method_entry(const MethodRun& run) {
    using json = nlohmann::ordered_json;
    const bool clustered = uses_clusters(run.name);
    json entry = {{"name", run.name},
                  {"lambda", uses_lambda(run.name) ? json(run.options.lambda) : json(nullptr)},
                  {"clusters", clustered ? json(run.options.clusters) : json(nullptr)},
                  {"views", clustered ? json(run.options.views) : json(nullptr)},
                  {"buffers", run.buffers.orders.size()},
                  {"acmr", run.acmr_mean},
                  {"atvr", run.atvr_mean},
                  {"ovr_mean", nullptr},
                  {"ovr_pooled", nullptr},
                  {"time_s", run.seconds}};
    for (auto it = run.details.begin(); it != run.details.end(); ++it) entry[it.key()] = it.value();
    return entry;
}

std::string sidecar_json(const AnimatedMesh& mesh, const MethodRun& run, const std::string& binary_name) {
    nlohmann::ordered_json j;
    j["format"] = "animorder-sidecar";
    j["version"] = 1;
    j["binary"] = binary_name;
    j["method"] = run.name;
    j["buffers"] = run.buffers.orders.size();
    j["fallback"] = run.fallback;
    j["index_count"] = mesh.indices.size();
    j["primitives"] = nlohmann::ordered_json::array();
    for (const Primitive& p : mesh.primitives)
        j["primitives"].push_back({{"name", p.name}, {"first_index", p.first_index}, {"index_count", p.index_count}});
    j["clips"] = nlohmann::ordered_json::array();
    for (size_t c = 0; c < mesh.clips.size(); ++c)
        j["clips"].push_back({{"name", mesh.clips[c].name},
                              {"keyframes", mesh.clips[c].keyframe_count},
                              {"sample_rate", mesh.clips[c].sample_rate},
                              {"buffer_base", run.buffers.table_base[c]},
                              {"theta_steps", run.buffers.tables[c].theta_steps},
                              {"phi_steps", run.buffers.tables[c].phi_steps}});
    j["table"] = "cell (f, i, j): theta = i*pi/(theta_steps-1) from +Y, phi = j*2*pi/phi_steps from +Z towards +X; "
                 "buffer = buffer_base + cell (see animorder_runtime.h)";
    return j.dump(2) + "\n";
}

}  // namespace

int run_optimize(const OptimizeOptions& options) {
    const Clock::time_point start = Clock::now();
    check_method_options(options.settings);
    const std::string method = options.joint ? "joint" : options.method;
    if (options.joint && options.method != "single" && options.method != "joint" && options.method != "static-sander07")
        throw std::runtime_error("--joint applies to the single method, not " + options.method);
    check_method_name(method, true);  // reject unknown names early

    std::string input_name;
    const AnimatedMesh mesh = load_input(options.common, input_name);
    validate_animated_mesh(mesh);
    const double load_s = seconds_since(start);
    note(options.common, "loaded " + input_name + ": " + std::to_string(mesh.triangle_count()) + " triangles, " +
                             std::to_string(mesh.vertex_count) + " vertices, " + std::to_string(mesh.keyframe_count()) +
                             " keyframes");

    const MethodRun run = run_method(mesh, method, options.settings, options.common);
    const VertexCacheStats before = analyze_mesh_vertex_cache(mesh, mesh.indices, options.common.cache_size);

    nlohmann::ordered_json outputs = {{"gltf", nullptr}, {"sidecar", nullptr}, {"sidecar_json", nullptr}};
    if (!options.output.empty()) {
        std::string stem = options.output;
        const std::string extension = std::filesystem::path(options.output).extension().string();
        if (extension == ".glb" || extension == ".gltf") {
            const std::string in_ext = std::filesystem::path(options.common.input).extension().string();
            if (in_ext != ".glb" && in_ext != ".gltf")
                throw std::runtime_error(options.output + ": glTF output needs a glTF input (the sidecar works for any input)");
            std::error_code same_error;
            if (std::filesystem::equivalent(options.output, options.common.input, same_error))
                throw std::runtime_error(options.output + ": refusing to overwrite the input; name another output");
            write_file_atomically(options.output, gltf_with_orders(options.common.input, options.output, mesh, run.buffers, run.fallback,
                                                                   run.framing, method, extension == ".glb"));
            outputs["gltf"] = options.output;
            note(options.common, "wrote " + options.output);
            stem = options.output.substr(0, options.output.size() - extension.size());
        }
        const std::string binary = stem + ".animorder.bin", json = stem + ".animorder.json";
        write_file_atomically(binary, serialize_sidecar(mesh, run.buffers, run.framing));
        const size_t slash = binary.find_last_of('/');
        write_file_atomically(json, sidecar_json(mesh, run, slash == std::string::npos ? binary : binary.substr(slash + 1)));
        outputs["sidecar"] = binary;
        outputs["sidecar_json"] = json;
        note(options.common, "wrote " + binary + " and " + json);
    }

    nlohmann::ordered_json report = report_header(mesh, input_name);
    report["settings"] = {{"method", method},
                          {"lambda", options.settings.lambda},
                          {"cache_size", options.common.cache_size},
                          {"keyframe", options.settings.keyframe},
                          {"clusters", options.settings.clusters},
                          {"views", options.settings.views},
                          {"resolution", options.settings.resolution},
                          {"seed", options.settings.seed},
                          {"min_separation_deg", options.settings.min_separation},
                          {"max_iterations", options.settings.max_iterations},
                          {"distance", options.settings.distance},
                          {"update", options.settings.update},
                          {"nehab_clusters", options.settings.nehab_clusters},
                          {"nehab_views", options.settings.nehab_views},
                          {"nehab_all_keyframes", options.settings.nehab_all_keyframes},
                          {"threads", options.settings.threads}};
    report["input_order"] = cache_stats_json(before);
    report["methods"] = nlohmann::ordered_json::array({method_entry(run)});
    report["outputs"] = outputs;
    report["timings_s"] = {{"load", load_s}, {"method", run.seconds}, {"total", seconds_since(start)}};
    if (!options.report_path.empty()) {
        write_file_atomically(options.report_path, report_text(report));
        note(options.common, "wrote " + options.report_path);
    }
    std::printf("%s on %s: %zu triangles, %zu buffers, ACMR %.4f -> %.4f, ATVR %.4f -> %.4f, %.3f s\n", method.c_str(),
                input_name.c_str(), mesh.triangle_count(), run.buffers.orders.size(), before.acmr, run.acmr_mean,
                before.atvr, run.atvr_mean, run.seconds);
    return 0;
}

int run_evaluate(const EvaluateOptions& options) {
    using json = nlohmann::ordered_json;
    const Clock::time_point start = Clock::now();
    const MethodOptions& base = options.settings;
    const std::vector<std::string> names = split_list(options.methods);
    if (names.empty()) throw std::runtime_error("--methods names no method");
    for (const std::string& n : names) check_method_name(n, false);
    // Every combination of the swept settings, for the methods that use them.
    std::vector<MethodOptions> variants;
    const std::vector<double> lambdas = base.lambdas.empty() ? std::vector<double>{base.lambda} : base.lambdas;
    const std::vector<size_t> ks = base.cluster_list.empty() ? std::vector<size_t>{base.clusters} : base.cluster_list;
    const std::vector<size_t> views = base.view_list.empty() ? std::vector<size_t>{base.views} : base.view_list;
    std::vector<std::pair<std::string, MethodOptions>> plan;
    for (const std::string& n : names)
        for (size_t li = 0; li < (uses_lambda(n) ? lambdas.size() : 1); ++li)
            for (size_t ki = 0; ki < (uses_clusters(n) ? ks.size() : 1); ++ki)
                for (size_t vi = 0; vi < (uses_clusters(n) ? views.size() : 1); ++vi) {
                    MethodOptions m = base;
                    m.lambda = lambdas[li];
                    m.clusters = ks[ki];
                    m.views = views[vi];
                    check_method_options(m);
                    plan.emplace_back(n, m);
                }

    std::string input_name;
    const AnimatedMesh mesh = load_input(options.common, input_name);
    validate_animated_mesh(mesh);
    std::vector<MethodRun> runs;
    for (const auto& [n, m] : plan) {
        std::string label = n;
        if (uses_lambda(n) && lambdas.size() > 1) label += " lambda=" + format_number(m.lambda);
        if (uses_clusters(n) && ks.size() > 1) label += " k=" + std::to_string(m.clusters);
        if (uses_clusters(n) && views.size() > 1) label += " views=" + std::to_string(m.views);
        note(options.common, "running " + label);
        runs.push_back(run_method(mesh, n, m, options.common));
    }
    const double methods_s = seconds_since(start);

    EvaluationSettings eval;
    eval.views = options.views;
    eval.seed = options.seed;
    eval.resolution = options.resolution;
    eval.threads = base.threads;
    eval.progress = progress_printer(options.common, "evaluating");
    note(options.common, "evaluating " + std::to_string(runs.size()) + " methods at " +
                             std::to_string(mesh.keyframe_count() * options.views) + " nodes (" +
                             std::to_string(mesh.keyframe_count()) + " keyframes x " + std::to_string(options.views) +
                             " views, " + std::to_string(options.resolution) + "^2)");
    std::vector<MethodBuffers> buffers;
    for (const MethodRun& r : runs) buffers.push_back(r.buffers);
    const Clock::time_point eval_start = Clock::now();
    const std::vector<OrderEvaluation> results = evaluate_methods(mesh, buffers, eval);
    const double eval_s = seconds_since(eval_start);
    const size_t nodes = mesh.keyframe_count() * options.views;

    json report = report_header(mesh, input_name);
    report["settings"] = {{"methods", names},
                          {"lambda", lambdas},
                          {"clusters", ks},
                          {"views", views},
                          {"resolution", base.resolution},
                          {"seed", base.seed},
                          {"nehab_clusters", base.nehab_clusters},
                          {"nehab_views", base.nehab_views},
                          {"nehab_all_keyframes", base.nehab_all_keyframes},
                          {"cache_size", options.common.cache_size},
                          {"eval_views", options.views},
                          {"eval_resolution", options.resolution},
                          {"eval_seed", options.seed},
                          {"clips", options.common.clips}};
    report["clips"] = json::array();
    for (const Clip& c : mesh.clips) report["clips"].push_back({{"name", c.name}, {"keyframes", c.keyframe_count}});
    report["methods"] = json::array();
    std::string table = "| method | lambda | k | views | buffers | ACMR | ATVR | OVR mean | OVR pooled | time s |";
    std::string rule = "|---|---|---|---|---|---|---|---|---|---|";
    for (const Clip& c : mesh.clips) {
        table += " " + c.name + " |";
        rule += "---|";
    }
    table += "\n" + rule + "\n";
    std::string csv = "method,lambda,clusters,views,buffers,acmr,atvr,ovr_mean,ovr_pooled,time_s\n";
    for (size_t m = 0; m < runs.size(); ++m) {
        const MethodRun& run = runs[m];
        const OrderEvaluation& r = results[m];
        json entry = method_entry(run);
        const bool per_node = run.name == "oracle";
        entry["buffers"] = per_node ? nodes : run.buffers.orders.size();
        entry["ovr_mean"] = r.overall.ovr_mean;
        entry["ovr_pooled"] = r.overall.ovr_pooled;
        entry["per_clip"] = json::array();
        for (size_t c = 0; c < mesh.clips.size(); ++c)
            entry["per_clip"].push_back({{"clip", mesh.clips[c].name},
                                         {"ovr_mean", r.per_clip[c].ovr_mean},
                                         {"ovr_pooled", r.per_clip[c].ovr_pooled},
                                         {"nodes", r.per_clip[c].nodes},
                                         {"time_s", run.name == "single" && c < run.clip_seconds.size()
                                                        ? json(run.clip_seconds[c])
                                                        : json(nullptr)}});
        const std::string lambda = uses_lambda(run.name) ? format_number(run.options.lambda) : "";
        const std::string k = uses_clusters(run.name) ? std::to_string(run.options.clusters) : "";
        const std::string v = uses_clusters(run.name) ? std::to_string(run.options.views) : "";
        const std::string count = per_node ? "per node" : std::to_string(run.buffers.orders.size());
        char cells[256];
        std::snprintf(cells, sizeof cells, "| %s | %s | %s | %s | %s | %.3f | %.3f | %.3f | %.3f | %.1f |",
                      run.name.c_str(), lambda.c_str(), k.c_str(), v.c_str(), count.c_str(), run.acmr_mean,
                      run.atvr_mean, r.overall.ovr_mean, r.overall.ovr_pooled, run.seconds);
        table += cells;
        for (size_t c = 0; c < mesh.clips.size(); ++c) {
            std::snprintf(cells, sizeof cells, " %.3f |", r.per_clip[c].ovr_mean);
            table += cells;
        }
        table += "\n";
        std::snprintf(cells, sizeof cells, "%s,%s,%s,%s,%zu,%.6f,%.6f,%.6f,%.6f,%.6f\n", run.name.c_str(),
                      lambda.c_str(), k.c_str(), v.c_str(), per_node ? nodes : run.buffers.orders.size(), run.acmr_mean,
                      run.atvr_mean, r.overall.ovr_mean, r.overall.ovr_pooled, run.seconds);
        csv += cells;
        report["methods"].push_back(entry);
    }
    std::fputs(table.c_str(), stdout);
    report["nodes"] = nodes;
    report["timings_s"] = {{"methods", methods_s}, {"evaluation", eval_s}, {"total", seconds_since(start)}};
    report["machine"] = {{"threads", base.threads ? base.threads : std::thread::hardware_concurrency()}};
    if (!options.report_path.empty()) write_file_atomically(options.report_path, report_text(report));
    if (!options.csv_path.empty()) write_file_atomically(options.csv_path, csv);
    note(options.common, "evaluation took " + format_number(eval_s) + " s (" + format_number(seconds_since(start)) +
                             " s in all)");
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
