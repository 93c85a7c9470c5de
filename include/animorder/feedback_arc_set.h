// animorder — the greedy minimum feedback-arc-set order of a weighted directed graph, and the
// arcs an order violates: Eades, Lin & Smyth, "A fast and effective heuristic for the feedback
// arc set problem" (IPL 1993), as Skiena's Algorithm Design Manual gives it, with the weighted
// rule of Nehab, Barczak & Sander (I3D 2006, §5). Shared by static-nehab06 (clusters), `measured`
// (each cluster's units) and the blend orders. Plain arrays in and out.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace animorder {

// A weighted arc: drawing `from` before `to` saves `weight` fragments.
struct Arc {
    uint32_t from = 0;
    uint32_t to = 0;
    uint64_t weight = 0;
};

// A node order from the greedy minimum feedback-arc-set heuristic of Eades, Lin & Smyth (1993;
// Skiena, The Algorithm Design Manual), with the weighted rule of Nehab et al. §5: repeatedly
// move every sink to the front of the tail and every source to the end of the head; when only
// cycles remain, remove the node with the largest |Σ out-weights − Σ in-weights| and put it on
// the winning side (head when out ≥ in, else tail); ties go to the lowest node id. Sources and
// sinks are taken first-found-first (FIFO, initial ones in id order), so an acyclic graph comes
// out in a topological order. Parallel arcs add up. Returns the nodes in drawing order.
// O((V + E) log V): the bucket queue of the unit-weight heuristic would need a bucket per
// possible weight difference, so the greedy choice uses an ordered set instead. Throws
// InvalidInput for a node id >= node_count, a self-loop or a zero weight.
std::vector<uint32_t> order_feedback_arc_set(size_t node_count, const Arc* arcs, size_t arc_count);

struct FeedbackArcs {
    size_t count = 0;     // arcs whose `to` comes before their `from` in the order
    uint64_t weight = 0;  // their total weight
};
// The arcs a node order violates. node_order must be a permutation of 0..node_count-1.
FeedbackArcs count_feedback_arcs(const uint32_t* node_order, size_t node_count, const Arc* arcs, size_t arc_count);

}  // namespace animorder
