// Rendering time of the "original" (Tipsify only) and "single" (Han & Sander 2017 k-means, k
// buffers per clip picked by the lookup table) orders in a real OpenGL, under a deliberately
// expensive fragment shader — the check behind Han & Sander 2017 §5, who report 18–20% faster
// rendering with their orders, matching the overdraw (OVR) drop.
//
// At every evaluation node (keyframes of each clip, every `--keyframe-stride`-th, × `--views`
// random directions from DESIGN.md's evaluation seed; DESIGN.md's framing and camera, exactly as
// the OpenGL cross-check) the clip-space vertices are uploaded once, then each method's index
// buffer is drawn into a cleared depth buffer (depth test LESS, back faces culled) with
// kExpensiveFragmentShader (gl_context.h: `--shader-iterations` rounds of transcendental math,
// `layout(early_fragment_tests) in;`, no discard, no shader depth write). Every draw is timed
// from the draw call to glFinish (steady_clock; GL_TIME_ELAPSED is reported beside it, but on
// llvmpipe it covers only part of a draw's work, so the wall time is the measure), the methods
// interleaved (A B A B …) `--repeats` times, the median kept per node and summed over nodes.
// GL_SAMPLES_PASSED of each draw gives both methods' OVR at the very same nodes. A draw of the
// original order with a zero-iteration shader at every node gives the part of a draw that is
// not fragment shading (vertex work, binning, rasterisation, depth test): the default
// iterations make it a small share of a draw, so the draws are fragment-bound.
//
// What this shows here, on Mesa's llvmpipe (a software rasteriser that tests depth before
// shading, in 4×4-pixel blocks, over LP_NUM_THREADS threads, all cores by default): that time
// follows the fragments that pass the early depth test, so an order with fewer of them renders
// faster in proportion to the shading work saved, and by how much for these orders. What it
// cannot show: a GPU's hierarchical-Z (coarse rejection before the per-pixel early-Z test), the
// ROP and memory-bandwidth costs of overdraw, or quad/warp granularity; so the ratios are not real
// GPU timings, which need a machine with a GPU (the program runs unchanged on one).
//
// Measured on 2 cores (llvmpipe, LLVM 15): the default run (bundled character, 200 nodes, 71 s)
// gives single/original time 0.809 against OVR 0.811 (per-node correlation 0.92); Ganfaul's Idle
// (--views 20 --keyframe-stride 2, 600 nodes) time 0.800 against OVR 0.787 — the paper's 18–20%.
//
//   build/bench/render_time [INPUT] [--clip NAME]… [--views 10] [--keyframe-stride 4]
//                           [--resolution 512] [--shader-iterations 64] [--repeats 3]
//                           [--lambda 0.85] [-k 5] [--json OUT.json] [--quiet]
#include "gl_context.h"

#include "animorder/animated_mesh.h"
#include "animorder/atomic_write.h"
#include "animorder/camera.h"
#include "animorder/evaluation.h"
#include "animorder/invalid_input.h"
#include "animorder/load.h"
#include "animorder/methods.h"
#include "animorder/patches.h"
#include "animorder/procedural_character.h"
#include "animorder/selection_table.h"
#include "animorder/triangle_order.h"
#include "animorder/viewpoints.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

using namespace animorder;

namespace {

struct Options {
    std::string input;  // empty: the bundled character
    std::vector<std::string> clips;
    size_t views = 10;
    size_t keyframe_stride = 4;
    unsigned resolution = 512;
    int iterations = 64;
    int repeats = 3;
    double lambda = kDefaultLambda;
    size_t clusters = 5;
    std::string json;
    bool quiet = false;
};

const char* const kUsage =
    "usage: render_time [INPUT] [--clip NAME]... [--views N] [--keyframe-stride S] [--resolution 512]\n"
    "                   [--shader-iterations I] [--repeats R] [--lambda L] [-k K] [--json OUT.json] [--quiet]\n";

unsigned long long parse_count(const std::string& option, const std::string& text, unsigned long long minimum) {
    size_t used = 0;
    unsigned long long value = 0;
    try {
        if (!text.empty() && text[0] != '-') value = std::stoull(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != text.size() || value < minimum || value > 1000000000ull)
        throw InvalidInput(option + " needs a whole number of at least " + std::to_string(minimum) + ", not '" + text +
                           "'");
    return value;
}

Options parse_options(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) throw InvalidInput(a + " needs a value");
            return argv[++i];
        };
        if (a == "--clip")
            o.clips.push_back(value());
        else if (a == "--views")
            o.views = parse_count(a, value(), 1);
        else if (a == "--keyframe-stride")
            o.keyframe_stride = parse_count(a, value(), 1);
        else if (a == "--resolution")
            o.resolution = unsigned(parse_count(a, value(), 1));
        else if (a == "--shader-iterations")
            o.iterations = int(parse_count(a, value(), 0));
        else if (a == "--repeats")
            o.repeats = int(parse_count(a, value(), 1));
        else if (a == "-k")
            o.clusters = parse_count(a, value(), 1);
        else if (a == "--json")
            o.json = value();
        else if (a == "--quiet")
            o.quiet = true;
        else if (a == "--lambda") {
            const std::string text = value();
            char* end = nullptr;
            o.lambda = std::strtod(text.c_str(), &end);
            if (text.empty() || *end != '\0' || !std::isfinite(o.lambda) || o.lambda < 0)
                throw InvalidInput("--lambda needs a number of at least 0, not '" + text + "'");
        } else if (a == "-h" || a == "--help") {
            std::fputs(kUsage, stdout);
            std::exit(0);
        } else if (!a.empty() && a[0] == '-') {
            throw InvalidInput("unknown option " + a);
        } else if (o.input.empty()) {
            o.input = a;
        } else {
            throw InvalidInput("one input file only (got " + o.input + " and " + a + ")");
        }
    }
    if (o.resolution > 16384) throw InvalidInput("--resolution is at most 16384");
    return o;
}

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// Pearson's correlation; 0 where either series is constant.
double correlation(const std::vector<double>& x, const std::vector<double>& y) {
    const double n = double(x.size());
    const double mx = std::accumulate(x.begin(), x.end(), 0.0) / n, my = std::accumulate(y.begin(), y.end(), 0.0) / n;
    double sxy = 0, sxx = 0, syy = 0;
    for (size_t i = 0; i < x.size(); ++i) {
        sxy += (x[i] - mx) * (y[i] - my);
        sxx += (x[i] - mx) * (x[i] - mx);
        syy += (y[i] - my) * (y[i] - my);
    }
    return sxx > 0 && syy > 0 ? sxy / std::sqrt(sxx * syy) : 0.0;
}

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\')
            out += '\\', out += c;
        else if (static_cast<unsigned char>(c) < 0x20) {
            char escape[8];
            std::snprintf(escape, sizeof escape, "\\u%04x", c);
            out += escape;
        } else
            out += c;
    }
    return out + "\"";
}

struct Node {
    size_t clip = 0, keyframe = 0, view = 0;
    uint32_t single_buffer = 0;  // index into the single method's orders
};

struct MethodTotals {
    const char* name;
    double seconds = 0, gl_seconds = 0, ratio_sum = 0, passed = 0;
};

int run(const Options& options) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    auto log = [&](const std::string& line) {
        if (!options.quiet) std::fprintf(stderr, "render_time: %s\n", line.c_str());
    };
    AnimatedMesh mesh;
    std::string input_name;
    if (options.input.empty()) {
        mesh = make_procedural_character();
        input_name = kProceduralCharacterName;
        log("no input given: using the bundled procedural character");
    } else {
        mesh = load_character(options.input);
        input_name = options.input;
    }
    if (!options.clips.empty()) mesh = select_clips(mesh, options.clips);
    validate_animated_mesh(mesh);

    // The two methods, built with the library's defaults (λ, cache, k, 162 views at 256²).
    MethodSettings settings;
    settings.lambda = options.lambda;
    settings.clustering.clusters = options.clusters;
    const std::vector<uint32_t> original = run_method(mesh, Method::Original, settings).buffers.orders[0];
    log("clustering (single, k = " + std::to_string(options.clusters) + ", " +
        std::to_string(settings.clustering.views) + " views at " + std::to_string(settings.clustering.resolution) +
        "²) ...");
    const MethodResult single = run_method(mesh, Method::Single, settings);
    const MethodBuffers& buffers = single.buffers;
    const double seconds_methods = std::chrono::duration<double>(Clock::now() - start).count();
    log("methods ready in " + std::to_string(seconds_methods) + " s");

    // The nodes: every keyframe_stride-th keyframe of each clip × random evaluation directions;
    // single's buffer picked as evaluation.cpp does (table_base[clip] + the table's cell).
    const std::vector<float> directions = random_sphere_directions(options.views, kEvaluationSeed);
    const Framing all = frame_animated_mesh(mesh);
    std::vector<Node> nodes;
    std::vector<float> radius(mesh.clips.size());
    for (size_t c = 0; c < mesh.clips.size(); ++c) {
        const Clip& clip = mesh.clips[c];
        std::vector<uint32_t> keyframes(clip.keyframe_count);
        std::iota(keyframes.begin(), keyframes.end(), uint32_t(clip.first_keyframe));
        radius[c] = frame_subset(all, keyframes).radius;
        for (size_t f = 0; f < clip.keyframe_count; f += options.keyframe_stride)
            for (size_t v = 0; v < options.views; ++v) {
                Node n;
                n.clip = c;
                n.keyframe = clip.first_keyframe + f;
                n.view = v;
                n.single_buffer = buffers.table_base[c] + select_buffer(buffers.tables[c], f, &directions[3 * v]);
                if (n.single_buffer >= buffers.orders.size())
                    throw InvalidInput("a lookup table names a missing buffer");
                nodes.push_back(n);
            }
    }

    GlContext gl(options.resolution, kExpensiveFragmentShader);
    const std::string renderer = gl.renderer();
    log("OpenGL renderer: " + renderer + "; " + std::to_string(nodes.size()) + " nodes at " +
        std::to_string(options.resolution) + "², " + std::to_string(options.iterations) + " shader iterations, " +
        std::to_string(options.repeats) + " repeats");
    auto upload = [&](const std::vector<uint32_t>& order) {
        std::vector<uint32_t> indices(mesh.indices.size());
        apply_triangle_order(indices.data(), mesh.indices.data(), order.data(), order.size());
        return gl.add_index_buffer(indices.data(), indices.size());
    };
    const size_t original_id = upload(original);
    std::vector<size_t> single_ids;
    for (const auto& order : buffers.orders) single_ids.push_back(upload(order));

    MethodTotals totals[2] = {{"original"}, {"single"}};
    std::vector<double> time_ratio(nodes.size()), ovr_ratio(nodes.size());
    std::vector<double> node_seconds, node_fragments;  // both methods, every node
    double base_seconds = 0, visible_total = 0;
    std::vector<float> clip(mesh.vertex_count * 4);
    const uint64_t pixels = uint64_t(options.resolution) * options.resolution;
    for (size_t i = 0; i < nodes.size(); ++i) {
        const Node& n = nodes[i];
        transform_to_clip(clip.data(), mesh.keyframe(n.keyframe), mesh.vertex_count, &all.centres[3 * n.keyframe],
                          node_view_projection(&directions[3 * n.view], radius[n.clip]));
        gl.set_vertices(clip.data(), mesh.vertex_count);
        const size_t ids[2] = {original_id, single_ids[n.single_buffer]};

        // Not fragment shading: the original order with a zero-iteration shader.
        gl.set_uniform("iterations", 0);
        gl.draw(ids[0], true);  // warm-up (first use of these vertices)
        base_seconds += gl.draw(ids[0], true).seconds;
        const uint64_t visible = gl.covered_pixels();
        if (visible == 0 || visible > pixels)
            throw std::runtime_error("implausible visible pixel count " + std::to_string(visible) + " at node " +
                                     std::to_string(i));
        gl.set_uniform("iterations", options.iterations);

        std::vector<double> seconds[2], gl_seconds[2];
        uint64_t passed[2] = {0, 0};
        for (int r = 0; r < options.repeats; ++r)
            for (int m = 0; m < 2; ++m) {  // interleaved: A B A B …
                const GlDraw d = gl.draw(ids[m], true);
                if (r > 0 && d.samples_passed != passed[m])
                    throw std::runtime_error("GL_SAMPLES_PASSED changed between repeats of one draw (" +
                                             std::to_string(passed[m]) + ", then " + std::to_string(d.samples_passed) +
                                             "): a corrupt query");
                if (d.samples_passed < visible)
                    throw std::runtime_error("implausible query result (passed " + std::to_string(d.samples_passed) +
                                             ", visible " + std::to_string(visible) + ")");
                passed[m] = d.samples_passed;
                seconds[m].push_back(d.seconds);
                gl_seconds[m].push_back(d.gpu_seconds);
            }
        double node_time[2];
        for (int m = 0; m < 2; ++m) {
            node_time[m] = median(seconds[m]);
            totals[m].seconds += node_time[m];
            totals[m].gl_seconds += median(gl_seconds[m]);
            totals[m].ratio_sum += double(passed[m]) / double(visible);
            totals[m].passed += double(passed[m]);
            node_seconds.push_back(node_time[m]);
            node_fragments.push_back(double(passed[m]));
        }
        visible_total += double(visible);
        time_ratio[i] = node_time[1] / node_time[0];
        ovr_ratio[i] = double(passed[1]) / double(passed[0]);
        if (!options.quiet && (i + 1) % std::max<size_t>(1, nodes.size() / 20) == 0)
            std::fprintf(stderr, "render_time: %zu/%zu nodes\n", i + 1, nodes.size());
    }

    const double count = double(nodes.size());
    const double ovr[2] = {totals[0].ratio_sum / count, totals[1].ratio_sum / count};
    const double t_ratio = totals[1].seconds / totals[0].seconds, o_ratio = ovr[1] / ovr[0];
    const double corr = correlation(time_ratio, ovr_ratio);
    const double corr_fragments = correlation(node_fragments, node_seconds);
    const double total_seconds = std::chrono::duration<double>(Clock::now() - start).count();

    std::printf(
        "%s: %zu triangles, %zu clips, %zu nodes (%zu views, keyframe stride %zu), %u², %d shader iterations, "
        "median of %d\nOpenGL renderer: %s\n",
        input_name.c_str(), mesh.triangle_count(), mesh.clips.size(), nodes.size(), options.views,
        options.keyframe_stride, options.resolution, options.iterations, options.repeats, renderer.c_str());
    std::printf("| method   | buffers | OVR mean | OVR pooled | time (s) | GL_TIME_ELAPSED (s) |\n");
    std::printf("|----------|--------:|---------:|-----------:|---------:|--------------------:|\n");
    for (int m = 0; m < 2; ++m)
        std::printf("| %-8s | %7zu | %8.4f | %10.4f | %8.3f | %19.3f |\n", totals[m].name,
                    m == 0 ? size_t(1) : buffers.orders.size(), ovr[m], totals[m].passed / visible_total,
                    totals[m].seconds, totals[m].gl_seconds);
    std::printf("single/original: time %.4f, OVR %.4f; per-node correlation of the two ratios %.3f\n", t_ratio, o_ratio,
                corr);
    std::printf(
        "per-draw correlation of time with passed fragments %.3f; a draw without shading costs %.1f%% of "
        "original's (%.3f s over all nodes)\n",
        corr_fragments, 100.0 * base_seconds / totals[0].seconds, base_seconds);

    if (!options.json.empty()) {
        // Written in memory, then to the file atomically (src/io/atomic_write.cpp), as every output.
        char* text = nullptr;
        size_t text_size = 0;
        FILE* f = ::open_memstream(&text, &text_size);
        if (!f) throw std::runtime_error("out of memory writing " + options.json);
        std::fprintf(f, "{\n  \"tool\": \"render_time\",\n  \"input\": %s,\n  \"renderer\": %s,\n",
                     json_string(input_name).c_str(), json_string(renderer).c_str());
        const char* threads = std::getenv("LP_NUM_THREADS");
        std::fprintf(f, "  \"lp_num_threads\": %s,\n", threads ? json_string(threads).c_str() : "null");
        std::fprintf(f, "  \"triangles\": %zu,\n  \"clips\": [", mesh.triangle_count());
        for (size_t c = 0; c < mesh.clips.size(); ++c)
            std::fprintf(f, "%s%s", c ? ", " : "", json_string(mesh.clips[c].name).c_str());
        std::fprintf(f,
                     "],\n  \"nodes\": %zu,\n  \"views\": %zu,\n  \"keyframe_stride\": %zu,\n  \"resolution\": %u,\n"
                     "  \"shader_iterations\": %d,\n  \"repeats\": %d,\n  \"lambda\": %.17g,\n  \"clusters\": %zu,\n"
                     "  \"clustering_views\": %zu,\n  \"clustering_resolution\": %u,\n  \"methods\": [\n",
                     nodes.size(), options.views, options.keyframe_stride, options.resolution, options.iterations,
                     options.repeats, options.lambda, options.clusters, settings.clustering.views,
                     settings.clustering.resolution);
        for (int m = 0; m < 2; ++m)
            std::fprintf(
                f,
                "    {\"name\": \"%s\", \"buffers\": %zu, \"ovr\": %.17g, \"ovr_pooled\": %.17g, \"seconds\": %.17g, "
                "\"gl_time_elapsed_s\": %.17g}%s\n",
                totals[m].name, m == 0 ? size_t(1) : buffers.orders.size(), ovr[m], totals[m].passed / visible_total,
                totals[m].seconds, totals[m].gl_seconds, m == 0 ? "," : "");
        std::fprintf(f,
                     "  ],\n  \"time_ratio\": %.17g,\n  \"ovr_ratio\": %.17g,\n  \"correlation\": %.17g,\n"
                     "  \"correlation_time_fragments\": %.17g,\n  \"unshaded_seconds\": %.17g,\n"
                     "  \"seconds_methods\": %.17g,\n  \"seconds_total\": %.17g\n}\n",
                     t_ratio, o_ratio, corr, corr_fragments, base_seconds, seconds_methods, total_seconds);
        const bool closed = std::fclose(f) == 0;
        const std::string json = closed ? std::string(text, text_size) : std::string();
        std::free(text);
        if (!closed) throw std::runtime_error("out of memory writing " + options.json);
        write_file_atomically(options.json, json);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(parse_options(argc, argv));
    } catch (const InvalidInput& e) {
        std::fprintf(stderr, "render_time: %s\n%s", e.what(), kUsage);
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "render_time: %s\n", e.what());
        return 1;
    }
}
