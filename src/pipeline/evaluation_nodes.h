// What both evaluations (evaluation.cpp: overdraw; blend_evaluation.cpp: blend error) share: the
// checks of a method's buffers, the rank tables of its buffers, the buffer a method draws at a
// node (through its lookup table, as the runtime), and the walk over DESIGN.md's evaluation
// nodes — every keyframe of every clip × random views, R per clip — in parallel, deterministic.
#pragma once

#include "../support/worker_threads.h"
#include "animorder/animated_mesh.h"
#include "animorder/evaluation.h"
#include "animorder/invalid_input.h"
#include "animorder/methods.h"
#include "animorder/selection_table.h"
#include "animorder/triangle_order.h"
#include "animorder/viewpoints.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <numeric>
#include <string>
#include <vector>

namespace animorder::evaluation_detail {

// Throws InvalidInput unless the method's buffers fit the mesh: permutations of its triangles, a
// per-keyframe buffer per keyframe, a table per clip; the oracle's patches cover the mesh.
inline void check_method(const AnimatedMesh& mesh, const MethodBuffers& m) {
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

// rank_of[m][b][t]: the position at which buffer b of method m draws triangle t.
using RankTables = std::vector<std::vector<std::vector<uint32_t>>>;
inline RankTables rank_tables(const std::vector<MethodBuffers>& methods, size_t triangles) {
    RankTables rank_of(methods.size());
    for (size_t m = 0; m < methods.size(); ++m)
        for (const auto& order : methods[m].orders) {
            std::vector<uint32_t> rank(triangles);
            for (size_t i = 0; i < triangles; ++i) rank[order[i]] = uint32_t(i);
            rank_of[m].push_back(std::move(rank));
        }
    return rank_of;
}

// The ranks of the buffer `method` draws at a node: per keyframe, or through the clip's lookup
// table at (clip-local keyframe f, view direction), exactly as an application does; else buffer 0.
inline const uint32_t* node_ranks(const MethodBuffers& method, const std::vector<std::vector<uint32_t>>& ranks,
                                  size_t clip, size_t f, size_t keyframe, const float* direction) {
    size_t buffer = 0;
    if (!method.keyframe_buffer.empty())
        buffer = method.keyframe_buffer[keyframe];
    else if (!method.tables.empty())
        buffer = method.table_base[clip] + select_buffer(method.tables[clip], f, direction);
    if (buffer >= ranks.size()) throw InvalidInput("a lookup table names a missing buffer");
    return ranks[buffer].data();
}

// One evaluation node as the walk hands it over.
struct Node {
    size_t clip = 0;                   // mesh.clips index
    size_t index = 0;                  // node index within the clip: f · views + v
    size_t f = 0;                      // keyframe within the clip
    size_t keyframe = 0;               // keyframe of the mesh
    const float* direction = nullptr;  // unit view direction
    const Framing* framing = nullptr;  // the clip's framing (R of this animation)
};

// For each clip in order: begin(clip, keyframes, framing, node_count); then visit(node) for each of
// its nodes in parallel on `threads` threads (0: all); then end(clip, node_count), where results
// are summed in node order so that they do not depend on the schedule. progress(done, total) is
// called now and then, never concurrently.
template <typename Begin, typename Visit, typename End>
void for_each_evaluation_node(const AnimatedMesh& mesh, const Framing& all, const EvaluationSettings& settings,
                              Begin begin, Visit visit, End end) {
    const std::vector<float> directions = random_sphere_directions(settings.views, settings.seed);
    size_t total_nodes = 0, done_before = 0;
    for (const Clip& c : mesh.clips) total_nodes += c.keyframe_count * settings.views;
    const int threads = worker_threads(settings.threads);
    tbb::task_arena arena(threads);
    std::mutex progress_mutex;
    for (size_t c = 0; c < mesh.clips.size(); ++c) {
        const Clip& clip = mesh.clips[c];
        std::vector<uint32_t> keyframes(clip.keyframe_count);
        std::iota(keyframes.begin(), keyframes.end(), uint32_t(clip.first_keyframe));
        const Framing framing = frame_subset(all, keyframes);  // R of this animation
        const size_t node_count = keyframes.size() * settings.views;
        begin(c, keyframes, framing, node_count);
        if (framing.shows_nothing()) {
            // Every keyframe of the clip shrinks the mesh to a point: nothing is drawn at any of
            // its nodes (no pixel to count), and no camera can be placed at 3R = 0.
            done_before += node_count;
            if (settings.progress && total_nodes) settings.progress(done_before, total_nodes);
            end(c, node_count);
            continue;
        }
        std::atomic<size_t> done{0};
        const size_t report_every = std::max<size_t>(1, total_nodes / 200);
        auto body = [&](const tbb::blocked_range<size_t>& range) {
            for (size_t n = range.begin(); n != range.end(); ++n) {
                Node node;
                node.clip = c;
                node.index = n;
                node.f = n / settings.views;
                node.keyframe = keyframes[node.f];
                node.direction = &directions[3 * (n % settings.views)];
                node.framing = &framing;
                visit(node);
                const size_t finished = ++done;
                if (settings.progress && (finished % report_every == 0 || finished == node_count)) {
                    std::lock_guard<std::mutex> lock(progress_mutex);
                    settings.progress(done_before + finished, total_nodes);
                }
            }
        };
        arena.execute([&] { tbb::parallel_for(tbb::blocked_range<size_t>(0, node_count, 1), body); });
        done_before += node_count;
        end(c, node_count);
    }
}

}  // namespace animorder::evaluation_detail
