// Scoring triangle orders over many nodes: the measurement behind Han & Sander 2017 §3 (node
// assignment by measured overdraw) and every OVR in the reports.
//
// Nodes are independent, so they run in parallel (oneTBB). Each worker keeps one rasteriser and
// one clip-space buffer and writes each node's counts into that node's own slot: the numbers do
// not depend on the thread count or on scheduling, and memory grows with the workers, not with
// the nodes.
#include "animorder/overdraw.h"

#include "animorder/animated_mesh.h"
#include "animorder/camera.h"
#include "animorder/invalid_input.h"
#include "animorder/rasterizer.h"
#include "animorder/triangle_order.h"
#include "animorder/viewpoints.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <string>

namespace animorder {

std::vector<uint8_t> opaque_pass_modes(const AnimatedMesh& mesh) {
    std::vector<uint8_t> modes(mesh.triangle_count(), 0);
    bool any = false;
    for (const Primitive& p : mesh.primitives) {
        const uint8_t mode =
            uint8_t((p.double_sided ? kDrawBothFaces : 0) | (p.alpha_mode == AlphaMode::Blend ? kSkipTriangle : 0));
        any = any || mode;
        for (size_t t = p.first_index / 3; t < (p.first_index + p.index_count) / 3 && t < modes.size(); ++t)
            modes[t] = mode;
    }
    if (!any) modes.clear();
    return modes;
}

std::vector<uint8_t> full_pass_modes(const AnimatedMesh& mesh) { return double_sided_triangles(mesh); }

std::vector<uint8_t> blended_triangles(const AnimatedMesh& mesh) {
    std::vector<uint8_t> blended(mesh.triangle_count(), 0);
    for (const Primitive& p : mesh.primitives)
        if (p.alpha_mode == AlphaMode::Blend)
            std::fill(blended.begin() + ptrdiff_t(p.first_index / 3),
                      blended.begin() + ptrdiff_t((p.first_index + p.index_count) / 3), 1);
    return blended;
}

std::vector<uint32_t> make_rank_table(const std::vector<const uint32_t*>& orders, size_t triangle_count) {
    const size_t k = orders.size();
    std::vector<uint32_t> ranks(triangle_count * k);
    for (size_t o = 0; o < k; ++o) {
        validate_triangle_order(orders[o], triangle_count);
        for (size_t i = 0; i < triangle_count; ++i) ranks[size_t(orders[o][i]) * k + o] = uint32_t(i);
    }
    return ranks;
}

void score_nodes(uint64_t* visible, uint64_t* passed, const float* keyframe_positions, size_t vertex_count,
                 const Framing& framing, const uint32_t* indices, size_t index_count, const OverdrawNode* nodes,
                 size_t node_count, const uint32_t* ranks, size_t order_count, const ScoreSettings& settings) {
    validate_indices(indices, index_count, vertex_count);
    const size_t keyframes = framing.centres.size() / 3;
    for (size_t n = 0; n < node_count; ++n)
        if (nodes[n].keyframe >= keyframes)
            throw InvalidInput("node " + std::to_string(n) + " names keyframe " + std::to_string(nodes[n].keyframe) +
                               ", but there are " + std::to_string(keyframes));

    struct Worker {
        NodeRasterizer rasterizer;
        std::vector<float> clip;
    };
    tbb::enumerable_thread_specific<Worker> workers;
    std::atomic<size_t> done{0};
    std::mutex progress_mutex;
    const size_t report_every = std::max<size_t>(1, node_count / 100);

    auto body = [&](const tbb::blocked_range<size_t>& range) {
        Worker& w = workers.local();
        w.clip.resize(vertex_count * 4);
        for (size_t n = range.begin(); n != range.end(); ++n) {
            const OverdrawNode& node = nodes[n];
            const Mat4d vp = node_view_projection(node.direction, framing.radius);
            transform_to_clip(w.clip.data(), keyframe_positions + size_t(node.keyframe) * vertex_count * 3,
                              vertex_count, framing.centres.data() + 3 * size_t(node.keyframe), vp);
            w.rasterizer.rasterize(w.clip.data(), vertex_count, indices, index_count, settings.resolution,
                                   settings.triangle_modes);
            visible[n] = w.rasterizer.visible_pixels();
            w.rasterizer.score(passed + n * order_count, ranks, order_count);
            const size_t finished = ++done;
            if (settings.progress && (finished % report_every == 0 || finished == node_count)) {
                std::lock_guard<std::mutex> lock(progress_mutex);
                settings.progress(finished, node_count);
            }
        }
    };
    const int threads = settings.threads ? int(settings.threads) : tbb::this_task_arena::max_concurrency();
    tbb::task_arena arena(threads);
    arena.execute([&] { tbb::parallel_for(tbb::blocked_range<size_t>(0, node_count, 1), body); });
}

std::vector<NodeFragments> rasterize_nodes(const float* keyframe_positions, size_t vertex_count, const Framing& framing,
                                           const uint32_t* indices, size_t index_count, const OverdrawNode* nodes,
                                           size_t node_count, const ScoreSettings& settings, size_t max_bytes) {
    validate_indices(indices, index_count, vertex_count);
    const size_t keyframes = framing.centres.size() / 3;
    for (size_t n = 0; n < node_count; ++n)
        if (nodes[n].keyframe >= keyframes)
            throw InvalidInput("node " + std::to_string(n) + " names a missing keyframe");

    std::vector<NodeFragments> kept(node_count);
    // The total is the same whatever the schedule, so whether it fits is decided deterministically.
    std::atomic<size_t> total{0};
    std::atomic<bool> too_big{false};
    std::atomic<size_t> done{0};
    std::mutex progress_mutex;
    struct Worker {
        NodeRasterizer rasterizer;
        std::vector<float> clip;
    };
    tbb::enumerable_thread_specific<Worker> workers;
    auto body = [&](const tbb::blocked_range<size_t>& range) {
        Worker& w = workers.local();
        w.clip.resize(vertex_count * 4);
        for (size_t n = range.begin(); n != range.end() && !too_big; ++n) {
            const OverdrawNode& node = nodes[n];
            transform_to_clip(w.clip.data(), keyframe_positions + size_t(node.keyframe) * vertex_count * 3,
                              vertex_count, framing.centres.data() + 3 * size_t(node.keyframe),
                              node_view_projection(node.direction, framing.radius));
            w.rasterizer.rasterize(w.clip.data(), vertex_count, indices, index_count, settings.resolution,
                                   settings.triangle_modes);
            kept[n] = w.rasterizer.export_fragments();
            if ((total += kept[n].bytes()) > max_bytes) too_big = true;
            const size_t finished = ++done;
            if (settings.progress &&
                (finished % std::max<size_t>(1, node_count / 100) == 0 || finished == node_count)) {
                std::lock_guard<std::mutex> lock(progress_mutex);
                settings.progress(finished, node_count);
            }
        }
    };
    const int threads = settings.threads ? int(settings.threads) : tbb::this_task_arena::max_concurrency();
    tbb::task_arena arena(threads);
    arena.execute([&] { tbb::parallel_for(tbb::blocked_range<size_t>(0, node_count, 1), body); });
    if (too_big) return {};
    return kept;
}

void score_kept_nodes(uint64_t* visible, uint64_t* passed, const std::vector<NodeFragments>& nodes,
                      const uint32_t* ranks, size_t order_count, const ScoreSettings& settings) {
    const int threads = settings.threads ? int(settings.threads) : tbb::this_task_arena::max_concurrency();
    tbb::task_arena arena(threads);
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, nodes.size(), 64),
                          [&](const tbb::blocked_range<size_t>& range) {
                              for (size_t n = range.begin(); n != range.end(); ++n) {
                                  visible[n] = nodes[n].visible;
                                  score_fragments(passed + n * order_count, nodes[n], ranks, order_count);
                              }
                          });
    });
    if (settings.progress) settings.progress(nodes.size(), nodes.size());
}

}  // namespace animorder
