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

std::vector<OrderEvaluation> evaluate_single_orders(const AnimatedMesh& mesh,
                                                    const std::vector<std::vector<uint32_t>>& orders,
                                                    const EvaluationSettings& settings) {
    validate_animated_mesh(mesh);
    if (settings.views == 0) throw InvalidInput("evaluation needs at least one viewpoint");
    const size_t k = orders.size();
    std::vector<const uint32_t*> pointers;
    for (const auto& order : orders) {
        if (order.size() != mesh.triangle_count())
            throw InvalidInput("an order has " + std::to_string(order.size()) + " triangles, the mesh " +
                               std::to_string(mesh.triangle_count()));
        pointers.push_back(order.data());
    }
    const std::vector<uint32_t> ranks = make_rank_table(pointers, mesh.triangle_count());
    const Framing framing = frame_keyframes(mesh.keyframe_positions.data(), mesh.keyframe_count(), mesh.vertex_count,
                                            mesh.indices.data(), mesh.indices.size());
    const std::vector<float> directions = random_sphere_directions(settings.views, settings.seed);

    std::vector<OverdrawNode> nodes;
    std::vector<size_t> node_clip;
    for (size_t c = 0; c < mesh.clips.size(); ++c)
        for (size_t f = 0; f < mesh.clips[c].keyframe_count; ++f)
            for (size_t v = 0; v < settings.views; ++v) {
                OverdrawNode node;
                node.keyframe = uint32_t(mesh.clips[c].first_keyframe + f);
                std::copy(&directions[3 * v], &directions[3 * v] + 3, node.direction);
                nodes.push_back(node);
                node_clip.push_back(c);
            }

    std::vector<uint64_t> visible(nodes.size()), passed(nodes.size() * k);
    ScoreSettings score;
    score.resolution = settings.resolution;
    score.threads = settings.threads;
    score.progress = settings.progress;
    score_nodes(visible.data(), passed.data(), mesh.keyframe_positions.data(), mesh.vertex_count, framing,
                mesh.indices.data(), mesh.indices.size(), nodes.data(), nodes.size(), ranks.data(), k, score);

    std::vector<OrderEvaluation> result(k);
    for (size_t o = 0; o < k; ++o) {
        Accumulator overall;
        std::vector<Accumulator> clips(mesh.clips.size());
        for (size_t n = 0; n < nodes.size(); ++n) {
            overall.add(passed[n * k + o], visible[n]);
            clips[node_clip[n]].add(passed[n * k + o], visible[n]);
        }
        result[o].overall = overall.summary();
        for (const Accumulator& a : clips) result[o].per_clip.push_back(a.summary());
    }
    return result;
}

}  // namespace animorder
