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

#include "evaluation_nodes.h"

#include "animorder/animated_mesh.h"
#include "animorder/camera.h"
#include "animorder/facing_filter.h"
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
    using namespace evaluation_detail;
    validate_animated_mesh(mesh);
    if (settings.views == 0) throw InvalidInput("evaluation needs at least one viewpoint");
    if (settings.resolution == 0) throw InvalidInput("evaluation needs a resolution of at least one pixel");
    for (const MethodBuffers& m : methods) check_method(mesh, m);
    const size_t triangles = mesh.triangle_count(), method_count = methods.size();
    const RankTables rank_of = rank_tables(methods, triangles);
    const std::vector<uint8_t> modes = opaque_pass_modes(mesh);
    const Framing all = frame_animated_mesh(mesh);

    std::vector<Accumulator> overall(method_count);
    std::vector<std::vector<Accumulator>> per_clip(method_count, std::vector<Accumulator>(mesh.clips.size()));
    struct Worker {
        NodeRasterizer rasterizer;
        FacingFilter facing;  // the keyframe last drawn's: the same fragments, fewer triangles
        CentredKeyframe centred;      // the keyframe last drawn's, moved to its frame's centre
        std::vector<uint32_t> ranks;  // this node's table: triangles × methods
    };
    tbb::enumerable_thread_specific<Worker> workers;
    std::vector<std::vector<float>> centroids(method_count);  // the oracles' patch centroids in the clip
    std::vector<uint64_t> visible, passed;
    auto begin = [&](size_t, const std::vector<uint32_t>& keyframes, const Framing&, size_t node_count) {
        for (size_t m = 0; m < method_count; ++m)
            if (methods[m].front_to_back)
                centroids[m] = patch_centroids(mesh, *methods[m].front_to_back, all, keyframes);
        visible.assign(node_count, 0);
        passed.assign(node_count * method_count, 0);
    };
    auto visit = [&](const Node& node) {
        Worker& w = workers.local();
        w.ranks.resize(triangles * method_count);
        const Framing& framing = *node.framing;
        for (size_t m = 0; m < method_count; ++m) {
            const MethodBuffers& method = methods[m];
            if (method.front_to_back) {
                const MeshPatches& patches = *method.front_to_back;
                const float eye[3] = {3 * framing.radius * node.direction[0], 3 * framing.radius * node.direction[1],
                                      3 * framing.radius * node.direction[2]};
                const std::vector<uint32_t> order = patch_order_to_triangle_order(
                    patches, front_to_back_patch_order(&centroids[m][node.f * patches.patch_count() * 3],
                                                       patches.patch_count(), eye));
                for (size_t i = 0; i < triangles; ++i) w.ranks[size_t(order[i]) * method_count + m] = uint32_t(i);
                continue;
            }
            const uint32_t* rank = node_ranks(method, rank_of[m], node.clip, node.f, node.keyframe, node.direction);
            for (size_t t = 0; t < triangles; ++t) w.ranks[t * method_count + m] = rank[t];
        }
        const float* centre = &all.centres[3 * node.keyframe];
        w.centred.centre(mesh.keyframe(node.keyframe), mesh.vertex_count, centre);
        const uint8_t* triangle_modes = modes.empty() ? nullptr : modes.data();
        w.facing.build_for(uint64_t(node.clip) << 32 | node.keyframe, mesh.keyframe(node.keyframe), mesh.vertex_count,
                           mesh.indices.data(), mesh.indices.size(), centre, framing.radius, settings.resolution,
                           triangle_modes);
        const FacingFilter::Candidates candidates = w.facing.candidates(node.direction);
        w.rasterizer.rasterize_validated(w.centred.vertices(node_view_projection(node.direction, framing.radius)),
                                         mesh.vertex_count, mesh.indices.data(), mesh.indices.size(),
                                         settings.resolution, triangle_modes, candidates.ids, candidates.count);
        visible[node.index] = w.rasterizer.visible_pixels();
        w.rasterizer.score(&passed[node.index * method_count], w.ranks.data(), method_count);
    };
    auto end = [&](size_t c, size_t node_count) {
        for (size_t n = 0; n < node_count; ++n)  // in node order: sums independent of the schedule
            for (size_t m = 0; m < method_count; ++m) {
                overall[m].add(passed[n * method_count + m], visible[n]);
                per_clip[m][c].add(passed[n * method_count + m], visible[n]);
            }
    };
    for_each_evaluation_node(mesh, all, settings, begin, visit, end);
    std::vector<OrderEvaluation> result(method_count);
    for (size_t m = 0; m < method_count; ++m) {
        result[m].overall = overall[m].summary();
        for (const Accumulator& a : per_clip[m]) result[m].per_clip.push_back(a.summary());
    }
    return result;
}

}  // namespace animorder
