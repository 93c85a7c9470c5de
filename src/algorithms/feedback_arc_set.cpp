// The greedy minimum feedback-arc-set heuristic: Eades, Lin & Smyth, "A fast and effective
// heuristic for the feedback arc set problem" (Information Processing Letters 47, 1993), as
// Skiena, The Algorithm Design Manual (1997), gives it, with the weighted rule of Nehab, Barczak
// & Sander, "Triangle Order Optimization for Graphics Hardware Computation Culling" (I3D 2006,
// §5): sinks to the tail, sources to the head, and when only cycles remain the node with the
// largest |Σ out-weights − Σ in-weights| to its winning side. Used by static-nehab06 for its
// clusters, by `measured` for each cluster's units (then sifted, measured_order.cpp) and by the
// blend orders.
#include "animorder/feedback_arc_set.h"

#include "greedy_feedback_order.h"

#include "animorder/invalid_input.h"
#include "animorder/triangle_order.h"

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

namespace animorder {

std::vector<uint32_t> order_feedback_arc_set(size_t node_count, const Arc* arcs, size_t arc_count) {
    if (node_count >= std::numeric_limits<uint32_t>::max()) throw InvalidInput("feedback arc set: too many nodes");
    for (size_t i = 0; i < arc_count; ++i) {
        const Arc& a = arcs[i];
        if (a.from >= node_count || a.to >= node_count)
            throw InvalidInput("feedback arc set: arc " + std::to_string(i) + " names node " +
                               std::to_string(std::max(a.from, a.to)) + ", but there are " +
                               std::to_string(node_count));
        if (a.from == a.to) throw InvalidInput("feedback arc set: arc " + std::to_string(i) + " is a self-loop");
        if (a.weight == 0) throw InvalidInput("feedback arc set: arc " + std::to_string(i) + " has weight 0");
    }
    // Out- and in-arcs per node (CSR), remaining arc counts and weights.
    std::vector<uint32_t> out_start(node_count + 1, 0), in_start(node_count + 1, 0);
    for (size_t i = 0; i < arc_count; ++i) {
        ++out_start[arcs[i].from + 1];
        ++in_start[arcs[i].to + 1];
    }
    for (size_t v = 0; v < node_count; ++v) {
        out_start[v + 1] += out_start[v];
        in_start[v + 1] += in_start[v];
    }
    std::vector<uint32_t> out_arc(arc_count), in_arc(arc_count);
    {
        std::vector<uint32_t> o(out_start.begin(), out_start.end() - 1), n(in_start.begin(), in_start.end() - 1);
        for (size_t i = 0; i < arc_count; ++i) {
            out_arc[o[arcs[i].from]++] = uint32_t(i);
            in_arc[n[arcs[i].to]++] = uint32_t(i);
        }
    }
    return greedy_feedback_order(
        node_count,
        [&](uint32_t v, auto&& f) {
            for (uint32_t i = out_start[v]; i < out_start[v + 1]; ++i) f(arcs[out_arc[i]].to, arcs[out_arc[i]].weight);
        },
        [&](uint32_t v, auto&& f) {
            for (uint32_t i = in_start[v]; i < in_start[v + 1]; ++i) f(arcs[in_arc[i]].from, arcs[in_arc[i]].weight);
        });
}

FeedbackArcs count_feedback_arcs(const uint32_t* node_order, size_t node_count, const Arc* arcs, size_t arc_count) {
    validate_triangle_order(node_order, node_count);  // a permutation check, whatever the items are
    std::vector<uint32_t> position(node_count);
    for (size_t i = 0; i < node_count; ++i) position[node_order[i]] = uint32_t(i);
    FeedbackArcs result;
    for (size_t i = 0; i < arc_count; ++i) {
        if (arcs[i].from >= node_count || arcs[i].to >= node_count)
            throw InvalidInput("count_feedback_arcs: arc " + std::to_string(i) + " names a missing node");
        if (position[arcs[i].to] < position[arcs[i].from]) {
            ++result.count;
            result.weight += arcs[i].weight;
        }
    }
    return result;
}

}  // namespace animorder
