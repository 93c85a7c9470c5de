// Overdraw ratios of single-buffer orders over DESIGN.md's evaluation nodes.
//
// Han & Sander 2017 §4 evaluate every method on every keyframe from random viewpoints and report
// the mean overdraw ratio; we also keep the pooled ratio (total passed over total visible), which
// weights a node by its pixel count. All orders are scored from the same rasterisation of each
// node (NodeRasterizer), so methods are compared on exactly the same fragments.
#include "animorder/evaluation.h"

#include "animorder/animorder.h"

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

std::vector<OrderEvaluation> evaluate_methods(const AnimatedMesh& mesh, const std::vector<MethodBuffers>& methods,
                                              const EvaluationSettings& settings) {
    validate_animated_mesh(mesh);
    if (settings.views == 0) throw InvalidInput("evaluation needs at least one viewpoint");
    // All buffers of all methods in one rank table: one rasterisation scores them all.
    std::vector<const uint32_t*> pointers;
    std::vector<size_t> first_buffer;
    for (const MethodBuffers& m : methods) {
        if (m.orders.empty()) throw InvalidInput("a method has no buffer");
        if (!m.tables.empty() && (m.tables.size() != mesh.clips.size() || m.table_base.size() != mesh.clips.size()))
            throw InvalidInput("a method with lookup tables needs one table per clip");
        first_buffer.push_back(pointers.size());
        for (const auto& order : m.orders) {
            if (order.size() != mesh.triangle_count())
                throw InvalidInput("an order has " + std::to_string(order.size()) + " triangles, the mesh " +
                                   std::to_string(mesh.triangle_count()));
            pointers.push_back(order.data());
        }
    }
    const size_t buffers = pointers.size();
    const std::vector<uint32_t> ranks = make_rank_table(pointers, mesh.triangle_count());
    const Framing all = frame_keyframes(mesh.keyframe_positions.data(), mesh.keyframe_count(), mesh.vertex_count,
                                        mesh.indices.data(), mesh.indices.size());
    const std::vector<float> directions = random_sphere_directions(settings.views, settings.seed);

    size_t total_nodes = 0, done_before = 0;
    for (const Clip& c : mesh.clips) total_nodes += c.keyframe_count * settings.views;
    std::vector<Accumulator> overall(methods.size());
    std::vector<std::vector<Accumulator>> per_clip(methods.size(), std::vector<Accumulator>(mesh.clips.size()));
    for (size_t c = 0; c < mesh.clips.size(); ++c) {
        const Clip& clip = mesh.clips[c];
        std::vector<uint32_t> keyframes;
        for (size_t f = 0; f < clip.keyframe_count; ++f) keyframes.push_back(uint32_t(clip.first_keyframe + f));
        const Framing framing = frame_subset(all, keyframes);  // R of this animation
        std::vector<OverdrawNode> nodes;
        for (uint32_t k : keyframes)
            for (size_t v = 0; v < settings.views; ++v) {
                OverdrawNode node;
                node.keyframe = k;
                std::copy(&directions[3 * v], &directions[3 * v] + 3, node.direction);
                nodes.push_back(node);
            }
        std::vector<uint64_t> visible(nodes.size()), passed(nodes.size() * buffers);
        ScoreSettings score;
        score.resolution = settings.resolution;
        score.threads = settings.threads;
        if (settings.progress)
            score.progress = [&](size_t done, size_t) { settings.progress(done_before + done, total_nodes); };
        score_nodes(visible.data(), passed.data(), mesh.keyframe_positions.data(), mesh.vertex_count, framing,
                    mesh.indices.data(), mesh.indices.size(), nodes.data(), nodes.size(), ranks.data(), buffers, score);
        done_before += nodes.size();

        for (size_t m = 0; m < methods.size(); ++m)
            for (size_t n = 0; n < nodes.size(); ++n) {
                size_t buffer = first_buffer[m];
                if (!methods[m].tables.empty()) {
                    const size_t chosen =
                        methods[m].table_base[c] + select_buffer(methods[m].tables[c], n / settings.views, nodes[n].direction);
                    if (chosen >= methods[m].orders.size()) throw InvalidInput("a lookup table names a missing buffer");
                    buffer += chosen;
                }
                overall[m].add(passed[n * buffers + buffer], visible[n]);
                per_clip[m][c].add(passed[n * buffers + buffer], visible[n]);
            }
    }
    std::vector<OrderEvaluation> result(methods.size());
    for (size_t m = 0; m < methods.size(); ++m) {
        result[m].overall = overall[m].summary();
        for (const Accumulator& a : per_clip[m]) result[m].per_clip.push_back(a.summary());
    }
    return result;
}

}  // namespace animorder
