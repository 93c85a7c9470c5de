// Blend error of methods over DESIGN.md's evaluation nodes (issue 18: blended hair and cloth).
//
// Blended primitives are drawn after the opaque scene with the depth test on and depth writes
// off; the result is only right when each pixel's blended fragments arrive back to front. Each
// node is rasterised once with every triangle (double-sided ones without culling); the blended
// fragments in front of the opaque depth are kept per pixel (NodeRasterizer::
// export_blend_fragments) and each method's buffer for that node is scored from them, as
// evaluate_methods scores overdraw.
#include "animorder/evaluation.h"

#include "evaluation_nodes.h"

#include "animorder/animated_mesh.h"
#include "animorder/camera.h"
#include "animorder/invalid_input.h"
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
#include <mutex>
#include <numeric>

namespace animorder {
namespace {

struct BlendAccumulator {
    BlendSummary s;
    void add(const BlendCounts& c) {
        s.pairs += c.pairs;
        s.missorted_pairs += c.missorted_pairs;
        s.covered += c.covered;
        s.missorted_pixels += c.missorted_pixels;
        ++s.nodes;
    }
    BlendSummary summary() const {
        BlendSummary out = s;
        out.missorted_pair_fraction = s.pairs ? double(s.missorted_pairs) / double(s.pairs) : 0.0;
        out.missorted_pixel_fraction = s.covered ? double(s.missorted_pixels) / double(s.covered) : 0.0;
        return out;
    }
};

}  // namespace

std::vector<uint32_t> back_to_front_blended_order(const AnimatedMesh& mesh, const float* positions,
                                                  const float centre[3], const float eye[3]) {
    std::vector<uint32_t> order(mesh.triangle_count());
    std::iota(order.begin(), order.end(), 0u);
    for (const Primitive& p : mesh.primitives) {
        if (p.alpha_mode != AlphaMode::Blend) continue;
        const size_t first = p.first_index / 3, last = (p.first_index + p.index_count) / 3;
        std::vector<double> distance(last - first);
        for (size_t t = first; t < last; ++t) {
            double d2 = 0;
            for (int d = 0; d < 3; ++d) {
                const double c =
                    (double(positions[3 * mesh.indices[3 * t] + d]) + positions[3 * mesh.indices[3 * t + 1] + d] +
                     positions[3 * mesh.indices[3 * t + 2] + d]) /
                        3.0 -
                    centre[d];
                d2 += (c - eye[d]) * (c - eye[d]);
            }
            distance[t - first] = d2;
        }
        std::sort(order.begin() + ptrdiff_t(first), order.begin() + ptrdiff_t(last), [&](uint32_t a, uint32_t b) {
            const double da = distance[a - first], db = distance[b - first];
            return da != db ? da > db : a < b;
        });
    }
    return order;
}

std::vector<BlendEvaluation> evaluate_blend(const AnimatedMesh& mesh, const std::vector<MethodBuffers>& methods,
                                            const EvaluationSettings& settings) {
    validate_animated_mesh(mesh);
    validate_indices(mesh.indices.data(), mesh.indices.size(), mesh.vertex_count);  // once, not once a node
    if (!has_blended_primitives(mesh)) throw InvalidInput("the mesh has no blended primitive (alphaMode BLEND)");
    if (settings.views == 0) throw InvalidInput("evaluation needs at least one viewpoint");
    if (settings.resolution == 0) throw InvalidInput("evaluation needs a resolution of at least one pixel");
    using namespace evaluation_detail;
    const size_t triangles = mesh.triangle_count();
    const size_t method_count = methods.size(), order_count = method_count + 1;  // + the bound
    for (const MethodBuffers& m : methods)
        if (!m.front_to_back) check_method(mesh, m);  // the oracle has no buffers: it is left out here
    const RankTables rank_of = rank_tables(methods, triangles);
    const std::vector<uint8_t> blended = blended_triangles(mesh);
    const std::vector<uint8_t> modes = full_pass_modes(mesh);
    const Framing all = frame_animated_mesh(mesh);

    std::vector<BlendAccumulator> overall(order_count);
    std::vector<std::vector<BlendAccumulator>> per_clip(order_count, std::vector<BlendAccumulator>(mesh.clips.size()));
    struct Worker {
        NodeRasterizer rasterizer;
        CentredKeyframe centred;  // the keyframe last drawn's
        std::vector<uint32_t> ranks;
    };
    tbb::enumerable_thread_specific<Worker> workers;
    std::vector<BlendCounts> counts;
    auto begin = [&](size_t, const std::vector<uint32_t>&, const Framing&, size_t node_count) {
        counts.assign(node_count * order_count, BlendCounts{});
    };
    auto visit = [&](const Node& node) {
        Worker& w = workers.local();
        w.ranks.assign(triangles * order_count, 0);
        const Framing& framing = *node.framing;
        for (size_t m = 0; m < method_count; ++m) {
            if (methods[m].front_to_back) continue;  // no buffers: scored with rank 0 everywhere, ignored
            const uint32_t* rank = node_ranks(methods[m], rank_of[m], node.clip, node.f, node.keyframe, node.direction);
            for (size_t t = 0; t < triangles; ++t) w.ranks[t * order_count + m] = rank[t];
        }
        const float eye[3] = {3 * framing.radius * node.direction[0], 3 * framing.radius * node.direction[1],
                              3 * framing.radius * node.direction[2]};
        const std::vector<uint32_t> bound =
            back_to_front_blended_order(mesh, mesh.keyframe(node.keyframe), &all.centres[3 * node.keyframe], eye);
        for (size_t i = 0; i < triangles; ++i) w.ranks[size_t(bound[i]) * order_count + method_count] = uint32_t(i);
        w.centred.centre(mesh.keyframe(node.keyframe), mesh.vertex_count, &all.centres[3 * node.keyframe]);
        w.rasterizer.rasterize_validated(w.centred.vertices(node_view_projection(node.direction, framing.radius)),
                                         mesh.vertex_count, mesh.indices.data(), mesh.indices.size(),
                                         settings.resolution, modes.empty() ? nullptr : modes.data());
        score_blend(&counts[node.index * order_count], w.rasterizer.export_blend_fragments(blended.data()),
                    w.ranks.data(), order_count);
    };
    auto end = [&](size_t c, size_t node_count) {
        for (size_t n = 0; n < node_count; ++n)
            for (size_t o = 0; o < order_count; ++o) {
                if (o < method_count && methods[o].front_to_back) continue;
                overall[o].add(counts[n * order_count + o]);
                per_clip[o][c].add(counts[n * order_count + o]);
            }
    };
    for_each_evaluation_node(mesh, all, settings, begin, visit, end);
    std::vector<BlendEvaluation> result(order_count);
    for (size_t o = 0; o < order_count; ++o) {
        result[o].overall = overall[o].summary();
        for (const BlendAccumulator& a : per_clip[o]) result[o].per_clip.push_back(a.summary());
    }
    return result;
}

}  // namespace animorder
