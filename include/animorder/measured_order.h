// animorder — measured cluster orders (measured_order.cpp): a k-means update step that orders a
// cluster's units (patches) by the overdraw graph measured over that cluster's own nodes, then
// minimises the weight of its backward arcs. Not in Han & Sander 2017 (their update sorts by
// integrated distance); the graph and the greedy order are Nehab, Barczak & Sander 2006 §4–5
// (nehab06.h, feedback_arc_set.h), here measured per cluster from the fragments k-means already keeps. No file I/O.
#pragma once

#include "animorder/kept_fragments.h"
#include "animorder/feedback_arc_set.h"
#include "animorder/rasterizer.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace animorder {

// The measured overdraw graph of units over a set of nodes. In every pixel with several fragments
// (NodeFragments, nearest first), each unit is represented by its nearest fragment; for two units
// a in front of b (a strictly nearer: a tie bit joins a fragment to the previous one's depth),
// drawing b before a lets b's fragment pass and then a covers it: one fragment on w(a→b). Summed
// over the nodes, each pair (a, b) gives one arc with the net weight |w(a→b) − w(b→a)|, from the
// unit that should come first (none when equal): the same net convention as Nehab's graph
// (Arc: drawing `from` before `to` saves `weight`). Arcs between units of different groups are
// dropped (group may be nullptr: one group). Arcs come sorted by (min(a,b), max(a,b)); integer
// sums, so the result is the same whatever the thread count (0: all hardware threads).
// unit_of_triangle[t] for every triangle id that appears in the fragments (< triangle_count).
// Throws InvalidInput for a triangle id >= triangle_count or a unit id >= unit_count.
std::vector<Arc> measured_overdraw_graph(const NodeFragments* const* nodes, size_t node_count,
                                         const uint32_t* unit_of_triangle, size_t triangle_count, size_t unit_count,
                                         const uint32_t* group, unsigned threads = 0);

// The counts behind measured_overdraw_graph for a set of nodes that grows and shrinks: k-means
// moves a few nodes between clusters each iteration, and a cluster's graph follows them without
// measuring its other nodes again. Each pair keeps its net count (pixels with the lower unit in
// front minus pixels with the higher in front): few units (<= kDenseMeasuredUnits) in a dense
// triangle of unit_count · (unit_count − 1) / 2 counts, more counted in a hash table of the pairs
// met and then settled into an array of the pairs with a net count, sorted by pair.
// Integer counts: the arcs are the same whatever the order of the updates and the thread count.
constexpr size_t kDenseMeasuredUnits = 1024;

struct MeasuredOrderStats;

class MeasuredPairCounts {
public:
    // unit_of_triangle: triangle_count entries, each < unit_count; group as measured_overdraw_graph.
    // front_levels: each unit is paired with the units of that many nearest depth levels in front
    // of it, 0 with every unit in front (measured_overdraw_graph's graph). A level counts where a
    // unit of its group has its nearest fragment (each unit is at its nearest fragment only).
    MeasuredPairCounts(size_t unit_count, const uint32_t* unit_of_triangle, size_t triangle_count,
                       const uint32_t* group, uint32_t front_levels = 0);
    ~MeasuredPairCounts();
    MeasuredPairCounts(MeasuredPairCounts&&) noexcept;
    MeasuredPairCounts& operator=(MeasuredPairCounts&&) noexcept;

    // Adds (sign +1) or removes (sign −1, nodes added before) the nodes' pixels.
    void add(const NodeFragments* const* nodes, size_t node_count, int sign, unsigned threads = 0);
    // The same from kept nodes (kept_fragments.h) over the same units: the same counts.
    void add(const KeptNode* const* nodes, size_t node_count, int sign, unsigned threads = 0);
    // Folds the counts added since the last call into the pairs kept between updates (sorted, one
    // entry per pair met with a net count other than 0), giving back the counting table's memory.
    // arcs() settles too; settling early keeps several graphs' peak memory low.
    void settle();
    // The netted arcs, as measured_overdraw_graph returns them.
    std::vector<Arc> arcs();

    struct State;

private:
    std::unique_ptr<State> state_;
    friend std::vector<uint32_t> measured_unit_order(MeasuredPairCounts&, const uint32_t*, MeasuredOrderStats*, bool);
};

// Local search on a linear order of units under the arcs: sifting (Chanas & Kobylański 1996;
// also "insertion" in the feedback-arc-set literature): each unit in turn is moved to the
// position that lowers the backward-arc weight the most, only when it lowers it strictly, and
// only inside its group's block (group nullptr: one block; the order must already keep each
// group contiguous). Passes repeat until one changes nothing or max_passes. The backward weight
// (count_feedback_arcs) never rises. Returns the final backward weight.
constexpr size_t kSiftMaxPasses = 32;
uint64_t sift_order(uint32_t* order, size_t unit_count, const Arc* arcs, size_t arc_count, const uint32_t* group,
                    size_t max_passes = kSiftMaxPasses);

struct MeasuredOrderStats {
    uint64_t start_weight = 0;   // backward weight of the start the search took
    uint64_t greedy_weight = 0;  // of the greedy Eades–Lin–Smyth order
    uint64_t final_weight = 0;   // after sifting
    size_t arc_count = 0;        // the graph's arcs
    bool from_previous = false;  // the previous order was the better start
};

// The measured order of units: per group (groups in ascending id order, as primitives in file
// order), the greedy feedback-arc-set order (order_feedback_arc_set) or `previous` (may be
// nullptr; a permutation keeping groups in ascending order) when its backward weight is lower,
// then sift_order. try_greedy false (with a previous order): start from `previous` without
// computing the greedy order (k-means does so once its buffer is a measured order; greedy_weight
// is then 0). Throws InvalidInput for an arc naming a unit >= unit_count or a previous
// order that is no permutation.
std::vector<uint32_t> measured_unit_order(size_t unit_count, const Arc* arcs, size_t arc_count, const uint32_t* group,
                                          const uint32_t* previous, MeasuredOrderStats* stats = nullptr,
                                          bool try_greedy = true);

// The same order from the counts themselves, over their units and groups: the same order and
// stats as measured_unit_order of counts.arcs(), in less memory (no array of arcs: the greedy
// order and sifting read one signed adjacency built straight from the settled counts).
std::vector<uint32_t> measured_unit_order(MeasuredPairCounts& counts, const uint32_t* previous,
                                          MeasuredOrderStats* stats = nullptr, bool try_greedy = true);

}  // namespace animorder
