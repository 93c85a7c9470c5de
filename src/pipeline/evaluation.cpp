// Overdraw ratios of methods over DESIGN.md's evaluation nodes.
//
// Han & Sander 2017 §4 evaluate every method on every keyframe from 300 random viewpoints and
// report the mean overdraw ratio; we also keep the pooled ratio (total passed over total
// visible), which weights a node by its pixel count. Each node is rasterised once
// (NodeRasterizer keeps every pixel's fragments); then the buffer each method draws at that node
// — fixed, chosen by a lookup table, one per keyframe (tipsify-per-frame), or sorted for that
// very node (the oracle) — is scored from the same fragments, so methods are compared on exactly
// the same pixels and a method with many buffers costs no more than one with a single buffer.
#include "animorder/evaluation.h"

#include "animorder/animated_mesh.h"
#include "animorder/camera.h"
#include "animorder/invalid_input.h"
#include "animorder/mesh_patches.h"
#include "animorder/methods.h"
#include "animorder/overdraw.h"
#include "animorder/rasterizer.h"
#include "animorder/selection_table.h"
#include "animorder/triangle_order.h"
#include "animorder/viewpoints.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <numeric>

namespace animorder {
namespace {

struct Accumulator {
    double ratio_sum = 0, passed = 0, visible = 0;
    size_t nodes = 0;
    void add(uint64_t node_passed, uint64_t node_visible) {
        if (node_visible == 0) return;  // nothing on screen: no ratio (cannot happen when framed)
        ratio_sum += double(node_passed) / double(node_visible);
        passed += double(node_passed);
        visible += double(node_visible);
        ++nodes;
    }
    OverdrawSummary summary() const {
        OverdrawSummary s;
        s.nodes = nodes;
        s.ovr_mean = nodes ? ratio_sum / double(nodes) : 0.0;
        s.ovr_pooled = visible > 0 ? passed / visible : 0.0;
        return s;
    }
};

void check_method(const AnimatedMesh& mesh, const MethodBuffers& m) {
    const size_t triangles = mesh.triangle_count();
    if (m.front_to_back) {
        const MeshPatches& p = *m.front_to_back;
        if (p.cache_order.size() != triangles || p.patch_starts.size() != p.patch_count() + 1 ||
            p.patch_starts.back() != triangles)
            throw InvalidInput("the oracle's patches do not cover the mesh's " + std::to_string(triangles) +
                               " triangles");
        validate_triangle_order(p.cache_order.data(), triangles);
        return;
    }
    if (m.orders.empty()) throw InvalidInput("a method has no buffer");
    for (const auto& order : m.orders) {
        if (order.size() != triangles)
            throw InvalidInput("an order has " + std::to_string(order.size()) + " triangles, the mesh " +
                               std::to_string(triangles));
        validate_triangle_order(order.data(), triangles);
    }
    if (!m.keyframe_buffer.empty()) {
        if (m.keyframe_buffer.size() != mesh.keyframe_count())
            throw InvalidInput("a per-keyframe method needs one buffer per keyframe (" +
                               std::to_string(mesh.keyframe_count()) + "), it names " +
                               std::to_string(m.keyframe_buffer.size()));
        for (uint32_t b : m.keyframe_buffer)
            if (b >= m.orders.size()) throw InvalidInput("a per-keyframe method names a missing buffer");
        return;
    }
    if (!m.tables.empty() && (m.tables.size() != mesh.clips.size() || m.table_base.size() != mesh.clips.size()))
        throw InvalidInput("a method with lookup tables needs one table per clip");
}

}  // namespace

std::vector<uint32_t> front_to_back_patch_order(const float* centroids, size_t patch_count, const float eye[3]) {
    std::vector<float> distance(patch_count);
    for (size_t p = 0; p < patch_count; ++p) {
        const float* c = centroids + 3 * p;
        const float d[3] = {c[0] - eye[0], c[1] - eye[1], c[2] - eye[2]};
        distance[p] = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    }
    std::vector<uint32_t> order(patch_count);
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(),
              [&](uint32_t a, uint32_t b) { return distance[a] != distance[b] ? distance[a] < distance[b] : a < b; });
    return order;
}

std::vector<OrderEvaluation> evaluate_methods(const AnimatedMesh& mesh, const std::vector<MethodBuffers>& methods,
                                              const EvaluationSettings& settings) {
    validate_animated_mesh(mesh);
    if (settings.views == 0) throw InvalidInput("evaluation needs at least one viewpoint");
    if (settings.resolution == 0) throw InvalidInput("evaluation needs a resolution of at least one pixel");
    for (const MethodBuffers& m : methods) check_method(mesh, m);
    const size_t triangles = mesh.triangle_count(), method_count = methods.size();

    // rank_of[m][b][t]: the position at which buffer b of method m draws triangle t.
    std::vector<std::vector<std::vector<uint32_t>>> rank_of(method_count);
    for (size_t m = 0; m < method_count; ++m)
        for (const auto& order : methods[m].orders) {
            std::vector<uint32_t> rank(triangles);
            for (size_t i = 0; i < triangles; ++i) rank[order[i]] = uint32_t(i);
            rank_of[m].push_back(std::move(rank));
        }

    const std::vector<uint8_t> modes = opaque_pass_modes(mesh);
    const Framing all = frame_animated_mesh(mesh);
    const std::vector<float> directions = random_sphere_directions(settings.views, settings.seed);
    size_t total_nodes = 0, done_before = 0;
    for (const Clip& c : mesh.clips) total_nodes += c.keyframe_count * settings.views;

    std::vector<Accumulator> overall(method_count);
    std::vector<std::vector<Accumulator>> per_clip(method_count, std::vector<Accumulator>(mesh.clips.size()));
    struct Worker {
        NodeRasterizer rasterizer;
        std::vector<float> clip;
        std::vector<uint32_t> ranks;  // this node's table: triangles × methods
    };
    tbb::enumerable_thread_specific<Worker> workers;
    const int threads = settings.threads ? int(settings.threads) : tbb::this_task_arena::max_concurrency();
    tbb::task_arena arena(threads);
    std::mutex progress_mutex;

    for (size_t c = 0; c < mesh.clips.size(); ++c) {
        const Clip& clip = mesh.clips[c];
        std::vector<uint32_t> keyframes(clip.keyframe_count);
        std::iota(keyframes.begin(), keyframes.end(), uint32_t(clip.first_keyframe));
        const Framing framing = frame_subset(all, keyframes);  // R of this animation
        // The oracles' patch centroids at every keyframe of the clip.
        std::vector<std::vector<float>> centroids(method_count);
        for (size_t m = 0; m < method_count; ++m)
            if (methods[m].front_to_back)
                centroids[m] = patch_centroids(mesh, *methods[m].front_to_back, all, keyframes);

        const size_t node_count = keyframes.size() * settings.views;
        std::vector<uint64_t> visible(node_count), passed(node_count * method_count);
        std::atomic<size_t> done{0};
        const size_t report_every = std::max<size_t>(1, total_nodes / 200);
        auto body = [&](const tbb::blocked_range<size_t>& range) {
            Worker& w = workers.local();
            w.clip.resize(mesh.vertex_count * 4);
            w.ranks.resize(triangles * method_count);
            for (size_t n = range.begin(); n != range.end(); ++n) {
                const size_t f = n / settings.views, keyframe = keyframes[f];
                const float* direction = &directions[3 * (n % settings.views)];
                for (size_t m = 0; m < method_count; ++m) {
                    const MethodBuffers& method = methods[m];
                    if (method.front_to_back) {
                        const MeshPatches& patches = *method.front_to_back;
                        const float eye[3] = {3 * framing.radius * direction[0], 3 * framing.radius * direction[1],
                                              3 * framing.radius * direction[2]};
                        const std::vector<uint32_t> order = patch_order_to_triangle_order(
                            patches, front_to_back_patch_order(&centroids[m][f * patches.patch_count() * 3],
                                                               patches.patch_count(), eye));
                        for (size_t i = 0; i < triangles; ++i)
                            w.ranks[size_t(order[i]) * method_count + m] = uint32_t(i);
                        continue;
                    }
                    size_t buffer = 0;
                    if (!method.keyframe_buffer.empty())
                        buffer = method.keyframe_buffer[keyframe];
                    else if (!method.tables.empty())
                        buffer = method.table_base[c] + select_buffer(method.tables[c], f, direction);
                    if (buffer >= rank_of[m].size()) throw InvalidInput("a lookup table names a missing buffer");
                    const uint32_t* rank = rank_of[m][buffer].data();
                    for (size_t t = 0; t < triangles; ++t) w.ranks[t * method_count + m] = rank[t];
                }
                transform_to_clip(w.clip.data(), mesh.keyframe(keyframe), mesh.vertex_count, &all.centres[3 * keyframe],
                                  node_view_projection(direction, framing.radius));
                w.rasterizer.rasterize(w.clip.data(), mesh.vertex_count, mesh.indices.data(), mesh.indices.size(),
                                       settings.resolution, modes.empty() ? nullptr : modes.data());
                visible[n] = w.rasterizer.visible_pixels();
                w.rasterizer.score(&passed[n * method_count], w.ranks.data(), method_count);
                const size_t finished = ++done;
                if (settings.progress && (finished % report_every == 0 || finished == node_count)) {
                    std::lock_guard<std::mutex> lock(progress_mutex);
                    settings.progress(done_before + finished, total_nodes);
                }
            }
        };
        arena.execute([&] { tbb::parallel_for(tbb::blocked_range<size_t>(0, node_count, 1), body); });
        done_before += node_count;

        for (size_t n = 0; n < node_count; ++n)  // in node order: sums independent of the schedule
            for (size_t m = 0; m < method_count; ++m) {
                overall[m].add(passed[n * method_count + m], visible[n]);
                per_clip[m][c].add(passed[n * method_count + m], visible[n]);
            }
    }
    std::vector<OrderEvaluation> result(method_count);
    for (size_t m = 0; m < method_count; ++m) {
        result[m].overall = overall[m].summary();
        for (const Accumulator& a : per_clip[m]) result[m].per_clip.push_back(a.summary());
    }
    return result;
}

}  // namespace animorder
