// Blend error of methods over DESIGN.md's evaluation nodes (issue 18: blended hair and cloth).
//
// Blended primitives are drawn after the opaque scene with the depth test on and depth writes
// off; the result is only right when each pixel's blended fragments arrive back to front. Each
// node is rasterised once with every triangle (double-sided ones without culling); the blended
// fragments in front of the opaque depth are kept per pixel (NodeRasterizer::
// export_blend_fragments) and each method's buffer for that node is scored from them, as
// evaluate_methods scores overdraw.
#include "animorder/evaluation.h"

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
    if (!has_blended_primitives(mesh)) throw InvalidInput("the mesh has no blended primitive (alphaMode BLEND)");
    if (settings.views == 0) throw InvalidInput("evaluation needs at least one viewpoint");
    if (settings.resolution == 0) throw InvalidInput("evaluation needs a resolution of at least one pixel");
    const size_t triangles = mesh.triangle_count();
    const size_t method_count = methods.size(), order_count = method_count + 1;  // + the bound
    for (const MethodBuffers& m : methods) {
        for (const auto& order : m.orders) {
            if (order.size() != triangles) throw InvalidInput("an order does not cover the mesh's triangles");
            validate_triangle_order(order.data(), triangles);
        }
        if (!m.front_to_back && m.orders.empty()) throw InvalidInput("a method has no buffer");
        if (!m.keyframe_buffer.empty() && m.keyframe_buffer.size() != mesh.keyframe_count())
            throw InvalidInput("a per-keyframe method needs one buffer per keyframe");
        if (!m.tables.empty() && (m.tables.size() != mesh.clips.size() || m.table_base.size() != mesh.clips.size()))
            throw InvalidInput("a method with lookup tables needs one table per clip");
    }
    std::vector<std::vector<std::vector<uint32_t>>> rank_of(method_count);
    for (size_t m = 0; m < method_count; ++m)
        for (const auto& order : methods[m].orders) {
            std::vector<uint32_t> rank(triangles);
            for (size_t i = 0; i < triangles; ++i) rank[order[i]] = uint32_t(i);
            rank_of[m].push_back(std::move(rank));
        }
    std::vector<uint8_t> blended(triangles, 0);
    for (const Primitive& p : mesh.primitives)
        if (p.alpha_mode == AlphaMode::Blend)
            std::fill(blended.begin() + ptrdiff_t(p.first_index / 3),
                      blended.begin() + ptrdiff_t((p.first_index + p.index_count) / 3), 1);
    const std::vector<uint8_t> modes = full_pass_modes(mesh);

    const Framing all = frame_animated_mesh(mesh);
    const std::vector<float> directions = random_sphere_directions(settings.views, settings.seed);
    size_t total_nodes = 0, done_before = 0;
    for (const Clip& c : mesh.clips) total_nodes += c.keyframe_count * settings.views;
    std::vector<BlendAccumulator> overall(order_count);
    std::vector<std::vector<BlendAccumulator>> per_clip(order_count, std::vector<BlendAccumulator>(mesh.clips.size()));
    struct Worker {
        NodeRasterizer rasterizer;
        std::vector<float> clip;
        std::vector<uint32_t> ranks;
    };
    tbb::enumerable_thread_specific<Worker> workers;
    const int threads = settings.threads ? int(settings.threads) : tbb::this_task_arena::max_concurrency();
    tbb::task_arena arena(threads);
    std::mutex progress_mutex;

    for (size_t c = 0; c < mesh.clips.size(); ++c) {
        const Clip& clip = mesh.clips[c];
        std::vector<uint32_t> keyframes(clip.keyframe_count);
        std::iota(keyframes.begin(), keyframes.end(), uint32_t(clip.first_keyframe));
        const Framing framing = frame_subset(all, keyframes);
        const size_t node_count = keyframes.size() * settings.views;
        std::vector<BlendCounts> counts(node_count * order_count);
        std::atomic<size_t> done{0};
        const size_t report_every = std::max<size_t>(1, total_nodes / 200);
        auto body = [&](const tbb::blocked_range<size_t>& range) {
            Worker& w = workers.local();
            w.clip.resize(mesh.vertex_count * 4);
            w.ranks.assign(triangles * order_count, 0);
            for (size_t n = range.begin(); n != range.end(); ++n) {
                const size_t f = n / settings.views, keyframe = keyframes[f];
                const float* direction = &directions[3 * (n % settings.views)];
                for (size_t m = 0; m < method_count; ++m) {
                    const MethodBuffers& method = methods[m];
                    if (method.front_to_back) continue;  // no buffers: scored with rank 0 everywhere, ignored
                    size_t buffer = 0;
                    if (!method.keyframe_buffer.empty())
                        buffer = method.keyframe_buffer[keyframe];
                    else if (!method.tables.empty())
                        buffer = method.table_base[c] + select_buffer(method.tables[c], f, direction);
                    if (buffer >= rank_of[m].size()) throw InvalidInput("a lookup table names a missing buffer");
                    const uint32_t* rank = rank_of[m][buffer].data();
                    for (size_t t = 0; t < triangles; ++t) w.ranks[t * order_count + m] = rank[t];
                }
                const float eye[3] = {3 * framing.radius * direction[0], 3 * framing.radius * direction[1],
                                      3 * framing.radius * direction[2]};
                const std::vector<uint32_t> bound =
                    back_to_front_blended_order(mesh, mesh.keyframe(keyframe), &all.centres[3 * keyframe], eye);
                for (size_t i = 0; i < triangles; ++i)
                    w.ranks[size_t(bound[i]) * order_count + method_count] = uint32_t(i);
                transform_to_clip(w.clip.data(), mesh.keyframe(keyframe), mesh.vertex_count, &all.centres[3 * keyframe],
                                  node_view_projection(direction, framing.radius));
                w.rasterizer.rasterize(w.clip.data(), mesh.vertex_count, mesh.indices.data(), mesh.indices.size(),
                                       settings.resolution, modes.empty() ? nullptr : modes.data());
                score_blend(&counts[n * order_count], w.rasterizer.export_blend_fragments(blended.data()),
                            w.ranks.data(), order_count);
                const size_t finished = ++done;
                if (settings.progress && (finished % report_every == 0 || finished == node_count)) {
                    std::lock_guard<std::mutex> lock(progress_mutex);
                    settings.progress(done_before + finished, total_nodes);
                }
            }
        };
        arena.execute([&] { tbb::parallel_for(tbb::blocked_range<size_t>(0, node_count, 1), body); });
        done_before += node_count;
        for (size_t n = 0; n < node_count; ++n)
            for (size_t o = 0; o < order_count; ++o) {
                if (o < method_count && methods[o].front_to_back) continue;
                overall[o].add(counts[n * order_count + o]);
                per_clip[o][c].add(counts[n * order_count + o]);
            }
    }
    std::vector<BlendEvaluation> result(order_count);
    for (size_t o = 0; o < order_count; ++o) {
        result[o].overall = overall[o].summary();
        for (const BlendAccumulator& a : per_clip[o]) result[o].per_clip.push_back(a.summary());
    }
    return result;
}

}  // namespace animorder
