// Measured cluster orders: a k-means update step from measured occlusion, not distance.
//
// This follows: Nehab, Barczak & Sander, "Triangle Order Optimization for Graphics Hardware
// Computation Culling", I3D 2006, §4 (a graph of the overdraw every pair of units causes, summed
// over many views) and §5 (the greedy minimum feedback-arc-set order of Eades, Lin & Smyth 1993),
// and Han & Sander, JCGT 2017, Algorithm 1 (k-means over (keyframe, view) nodes).
//
// What is new here: the graph is measured per k-means cluster, over that cluster's own nodes only
// (the views and poses its buffer will be drawn at), from the per-pixel fragment lists k-means
// already keeps (NodeFragments) instead of a second rasterisation; and the greedy order is
// improved by a local search — sifting (Chanas & Kobylański, "A new heuristic algorithm solving
// the linear ordering problem", 1996): every unit moved to its best position while that strictly
// lowers the weight of backward arcs — which never raises the measured cost. The units are the
// λ patches of the k-means, so the vertex cache cost stays the patches' (Tipsify-level).
#include "animorder/measured_order.h"

#include "../overdraw/fragment_encoding.h"

#include "animorder/invalid_input.h"
#include "animorder/feedback_arc_set.h"
#include "../support/worker_threads.h"
#include "greedy_feedback_order.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <string>

namespace animorder {
namespace {

// Open-addressing table of Slot {key, net}: key → pixels with the key's lower unit in front minus
// pixels with its higher one in front (signed: nodes are also removed; only the net makes an arc).
// Linear probing, grown at three-quarter load.
template <typename Key, typename Net>
struct OpenTable {
    static constexpr Key kEmpty = std::numeric_limits<Key>::max();
    struct Slot {
        Key key = kEmpty;
        Net net = 0;
    };
    std::vector<Slot> slots = std::vector<Slot>(1024);
    size_t used = 0;

    static size_t hash(uint64_t key) {
        key ^= key >> 33;
        key *= 0xff51afd7ed558ccdULL;
        key ^= key >> 33;
        return size_t(key);
    }
    Slot& find(Key key) {
        const size_t mask = slots.size() - 1;
        for (size_t i = hash(key) & mask;; i = (i + 1) & mask)
            if (slots[i].key == key || slots[i].key == kEmpty) return slots[i];
    }
    // The slot of key, made when new.
    Slot& at(Key key) {
        if (4 * (used + 1) > 3 * slots.size()) grow();
        Slot& s = find(key);
        if (s.key == kEmpty) {
            s.key = key;
            ++used;
        }
        return s;
    }
    void grow() {
        std::vector<Slot> old(slots.size() * 2);
        old.swap(slots);
        for (const Slot& s : old)
            if (s.key != kEmpty) find(s.key) = s;
    }
};

// The pairs' net counts: counted into an open-addressing table, then settled into an array sorted
// by pair with the zero nets left out (the counts kept between k-means iterations: one entry per
// pair, where the table holds one to two and a half slots per pair). Entries are 8 bytes (16-bit
// unit ids, 32-bit nets) while every unit id fits in 16 bits and every net in 32 (half the memory
// of the wide entries, and twice the entries a cache line holds), else — from the first count that
// does not fit, all moved over — 16 bytes.
struct PairTable {
    template <typename Key, typename Net>
    struct Entry {
        Key key;
        Net net;
    };
    OpenTable<uint32_t, int32_t> narrow;
    OpenTable<uint64_t, int64_t> wide;
    std::vector<Entry<uint32_t, int32_t>> settled_narrow;  // ascending keys, nets ≠ 0
    std::vector<Entry<uint64_t, int64_t>> settled_wide;
    size_t units = 0;
    bool is_wide = false;

    explicit PairTable(size_t unit_count) : units(unit_count), is_wide(unit_count > 0x10000) {
        if (is_wide) narrow.slots.clear(); else wide.slots.clear();
    }
    static uint64_t wide_key(uint32_t narrow_key) { return uint64_t(narrow_key >> 16) << 32 | (narrow_key & 0xffff); }
    void add(uint32_t lo, uint32_t hi, int64_t net) {
        if (!is_wide) {
            auto& s = narrow.at(lo << 16 | hi);
            const int64_t sum = int64_t(s.net) + net;
            if (fits_in<int32_t>(sum)) {
                s.net = int32_t(sum);
                return;
            }
            widen();
        }
        wide.at(uint64_t(lo) << 32 | hi).net += net;
    }
    template <typename Net>
    static bool fits_in(int64_t net) {
        return net >= std::numeric_limits<Net>::min() && net <= std::numeric_limits<Net>::max();
    }
    void widen() {
        wide.slots.assign(std::max<size_t>(1024, narrow.slots.size()), {});
        for (const auto& s : narrow.slots)
            if (s.key != narrow.kEmpty) wide.at(wide_key(s.key)).net = s.net;
        narrow.slots = {};
        narrow.used = 0;
        settled_wide.reserve(settled_narrow.size());
        for (const auto& e : settled_narrow) settled_wide.push_back({wide_key(e.key), e.net});  // the same order
        settled_narrow = {};
        is_wide = true;
    }
    // The table's counts into the settled array; the table emptied (its memory given back).
    void settle() {
        if (!is_wide) {
            if (narrow.used == 0) return;
            const std::vector<Entry<uint32_t, int32_t>> counted = take_sorted(narrow);
            if (merge_into(settled_narrow, counted)) return;
            // A sum beyond 32 bits: everything moved to wide entries (the same order), then merged.
            std::vector<Entry<uint64_t, int64_t>> wide_counted;
            wide_counted.reserve(counted.size());
            for (const auto& e : counted) wide_counted.push_back({wide_key(e.key), e.net});
            widen();
            merge_into(settled_wide, wide_counted);
            return;
        }
        if (wide.used != 0) merge_into(settled_wide, take_sorted(wide));
    }
    // The table's entries with a net count, sorted by key; the table emptied. Bucketed by the
    // lower unit (the key's high part) first, then each bucket (a unit's pairs: a few hundred at
    // most) sorted: linear in the entries but for the small sorts.
    template <typename Key, typename Net>
    std::vector<Entry<Key, Net>> take_sorted(OpenTable<Key, Net>& table) const {
        constexpr int kShift = sizeof(Key) * 4;  // 16 for narrow keys, 32 for wide ones
        std::vector<size_t> first(units + 1, 0);
        for (const auto& s : table.slots)
            if (s.key != table.kEmpty && s.net != 0) ++first[size_t(s.key >> kShift) + 1];
        std::partial_sum(first.begin(), first.end(), first.begin());
        std::vector<Entry<Key, Net>> counted(first[units]);
        for (const auto& s : table.slots)
            if (s.key != table.kEmpty && s.net != 0) counted[first[size_t(s.key >> kShift)]++] = {s.key, s.net};
        table = {};
        for (size_t lo = 0, begin = 0; lo < units; begin = first[lo++])
            std::sort(counted.begin() + long(begin), counted.begin() + long(first[lo]),
                      [](const auto& a, const auto& b) { return a.key < b.key; });
        return counted;
    }
    // Sorted counts into the settled array, zero sums left out; false (nothing changed) when a sum
    // does not fit in Net.
    template <typename Key, typename Net>
    static bool merge_into(std::vector<Entry<Key, Net>>& settled, const std::vector<Entry<Key, Net>>& counted) {
        // Two walks over the sorted runs: the merged size (and whether every sum fits), then the
        // merge into an array of exactly that size.
        const auto merge = [&](auto&& out) {
            size_t i = 0, j = 0;
            while (i < settled.size() || j < counted.size()) {
                if (j == counted.size() || (i < settled.size() && settled[i].key < counted[j].key)) {
                    out(settled[i++]);
                } else if (i == settled.size() || counted[j].key < settled[i].key) {
                    out(counted[j++]);
                } else {
                    const int64_t sum = int64_t(settled[i].net) + int64_t(counted[j].net);
                    if (!fits_in<Net>(sum)) return false;
                    if (sum != 0) out(Entry<Key, Net>{settled[i].key, Net(sum)});
                    ++i, ++j;
                }
            }
            return true;
        };
        size_t size = 0;
        if (!merge([&](const Entry<Key, Net>&) { ++size; })) return false;
        std::vector<Entry<Key, Net>> merged;
        merged.reserve(size);
        merge([&](const Entry<Key, Net>& e) { merged.push_back(e); });
        settled = std::move(merged);
        return true;
    }
    // f(lo, hi, net) for every pair met (net may be 0) not yet settled, in the table's own order.
    template <typename F>
    void for_each_unsettled(F&& f) const {
        if (is_wide) {
            for (const auto& s : wide.slots)
                if (s.key != wide.kEmpty) f(uint32_t(s.key >> 32), uint32_t(s.key), int64_t(s.net));
        } else {
            for (const auto& s : narrow.slots)
                if (s.key != narrow.kEmpty) f(s.key >> 16, s.key & 0xffff, int64_t(s.net));
        }
    }
    // f(lo, hi, net) for every settled pair (net ≠ 0), in ascending (lo, hi).
    template <typename F>
    void for_each_settled(F&& f) const {
        if (is_wide) {
            for (const auto& e : settled_wide) f(uint32_t(e.key >> 32), uint32_t(e.key), int64_t(e.net));
        } else {
            for (const auto& e : settled_narrow) f(e.key >> 16, e.key & 0xffff, int64_t(e.net));
        }
    }
};

// Per pair of units (lo < hi), pixels where lo is strictly in front of hi minus pixels where hi
// is in front of lo: a dense triangle or a table.
struct PairCounts {
    size_t units = 0;
    std::vector<int64_t> dense;  // [hi · (hi − 1) / 2 + lo], when units <= kDenseMeasuredUnits
    PairTable sparse;
    explicit PairCounts(size_t unit_count) : units(unit_count), sparse(unit_count) {
        if (units <= kDenseMeasuredUnits) dense.assign(units * (units - (units > 0)) / 2, 0);
    }
    static size_t slot(uint32_t lo, uint32_t hi) { return size_t(hi) * (hi - 1) / 2 + lo; }
    void add(uint32_t front, uint32_t back, int64_t sign) {
        const uint32_t lo = std::min(front, back), hi = std::max(front, back);
        const int64_t net = front == lo ? sign : -sign;
        if (units <= kDenseMeasuredUnits)
            dense[slot(lo, hi)] += net;
        else
            sparse.add(lo, hi, net);
    }
    void merge(const PairCounts& other) {
        for (size_t i = 0; i < dense.size(); ++i) dense[i] += other.dense[i];
        other.sparse.for_each_unsettled([&](uint32_t lo, uint32_t hi, int64_t net) { sparse.add(lo, hi, net); });
    }
};

// One list of units nearest first (unit | kTieBit at the previous entry's depth) into the counts,
// `amount` times: each unit by its nearest entry, one count per pair at different depths, each
// unit paired with the units of the `front_levels` nearest depth levels in front of it (0: every
// level). The levels are those of the units in front, each at its nearest entry, of the unit's
// group: a level that holds only a repeat of a nearer unit, or other groups' units, is not one.
void accumulate_list(PairCounts& table, const uint32_t* units, uint32_t n, size_t unit_count, const uint32_t* group,
                     uint32_t front_levels, int64_t amount, std::vector<std::pair<uint32_t, uint32_t>>& seen) {
    seen.clear();  // (unit, depth level) of each unit's nearest entry, nearest first
    uint32_t level = 0;
    for (uint32_t i = 0; i < n; ++i) {
        if (i != 0 && !(units[i] & kTieBit)) ++level;
        const uint32_t unit = units[i] & ~kTieBit;
        if (unit >= unit_count)
            throw InvalidInput("measured graph: unit " + std::to_string(unit) + ", but there are " +
                               std::to_string(unit_count));
        bool known = false;
        for (const auto& s : seen) known |= s.first == unit;
        if (known) continue;
        uint32_t levels = 0, last = UINT32_MAX;  // the front levels met, nearest first
        for (size_t q = seen.size(); q-- > 0;) {
            const auto& s = seen[q];
            if (s.second == level || (group && group[s.first] != group[unit])) continue;
            if (s.second != last) {
                if (levels == front_levels && front_levels != 0) break;
                ++levels;
                last = s.second;
            }
            table.add(s.first, unit, amount);
        }
        seen.emplace_back(unit, level);
    }
}

// One node's pixels into the counts, each pixel's triangles mapped to their units.
void accumulate_node(PairCounts& table, const NodeFragments& node, const uint32_t* unit_of_triangle,
                     size_t triangle_count, size_t unit_count, const uint32_t* group, uint32_t front_levels,
                     int64_t sign, std::vector<std::pair<uint32_t, uint32_t>>& seen, std::vector<uint32_t>& units) {
    for (size_t p = 0; p + 1 < node.starts.size(); ++p) {
        units.clear();
        for (uint32_t i = node.starts[p]; i < node.starts[p + 1]; ++i) {
            const uint32_t f = node.fragments[i];
            const uint32_t triangle = f & ~kTieBit;
            if (triangle >= triangle_count)
                throw InvalidInput("measured graph: fragment of triangle " + std::to_string(triangle) +
                                   ", but there are " + std::to_string(triangle_count));
            units.push_back(unit_of_triangle[triangle] | (f & kTieBit));
        }
        accumulate_list(table, units.data(), uint32_t(units.size()), unit_count, group, front_levels, sign, seen);
    }
}

// f(from, to, weight) for every arc of the counts (weight > 0), in ascending (min, max) pairs:
// the arcs measured_overdraw_graph returns. The sparse counts must be settled.
template <typename F>
void for_each_arc(const PairCounts& c, F&& f) {
    auto net = [&](uint32_t lo, uint32_t hi, int64_t n) {
        if (n > 0)
            f(lo, hi, uint64_t(n));
        else if (n < 0)
            f(hi, lo, uint64_t(-n));
    };
    if (c.units <= kDenseMeasuredUnits) {
        for (uint32_t lo = 0; lo < c.units; ++lo)
            for (uint32_t hi = lo + 1; hi < c.units; ++hi) net(lo, hi, c.dense[PairCounts::slot(lo, hi)]);
    } else {
        c.sparse.for_each_settled(net);
    }
}

// One entry of a unit's signed adjacency in sift_order: s > 0 when the unit should come first.
// Weight: int32_t (8-byte entries) when every arc's weight fits, else int64_t.
template <typename Weight>
struct Neighbour {
    uint32_t unit;
    Weight s;
};

// What sifting searches: each unit's neighbours, both ends of every arc, unit u's at
// [start[u], start[u + 1]).
template <typename Weight>
struct SiftGraph {
    std::vector<size_t> start;
    std::vector<Neighbour<Weight>> adjacency;
    bool by_position = false;  // each list already sorted by position in the order sifting starts from
};

template <typename Weight>
void sift_with(uint32_t* order, size_t unit_count, const uint32_t* group, size_t max_passes, SiftGraph<Weight>& graph);

// The weight of the arcs pointing backwards in the order (each arc counted at its `from` end).
template <typename Weight>
uint64_t backward_weight(const uint32_t* order, size_t unit_count, const SiftGraph<Weight>& graph) {
    std::vector<uint32_t> position(unit_count);
    for (size_t i = 0; i < unit_count; ++i) position[order[i]] = uint32_t(i);
    uint64_t weight = 0;
    for (size_t u = 0; u < unit_count; ++u)
        for (size_t e = graph.start[u]; e < graph.start[u + 1]; ++e) {
            const Neighbour<Weight>& n = graph.adjacency[e];
            if (n.s > 0 && position[n.unit] < position[u]) weight += uint64_t(n.s);
        }
    return weight;
}

// The greedy feedback-arc-set order of each group's units (groups in ascending id, as
// start_order's), over the graph's lists while they are in ascending neighbour id.
template <typename Weight>
std::vector<uint32_t> greedy_order(size_t unit_count, const uint32_t* group, const SiftGraph<Weight>& graph) {
    std::vector<uint32_t> units(unit_count);
    std::iota(units.begin(), units.end(), 0u);
    if (group)
        std::stable_sort(units.begin(), units.end(), [&](uint32_t a, uint32_t b) { return group[a] < group[b]; });
    std::vector<uint32_t> local(unit_count), order;
    order.reserve(unit_count);
    for (size_t i = 0; i < unit_count;) {
        size_t j = i;
        while (j < unit_count && (!group || group[units[j]] == group[units[i]])) ++j;
        for (size_t x = i; x < j; ++x) local[units[x]] = uint32_t(x - i);
        // The neighbours of the group's v-th unit with the sign that makes them out- or in-arcs.
        const auto arcs = [&](uint32_t v, int sign, auto&& f) {
            const uint32_t u = units[i + v];
            for (size_t e = graph.start[u]; e < graph.start[u + 1]; ++e) {
                const Neighbour<Weight>& n = graph.adjacency[e];
                if (sign * n.s > 0) f(local[n.unit], uint64_t(sign * int64_t(n.s)));
            }
        };
        for (const uint32_t x : greedy_feedback_order(
                 j - i, [&](uint32_t v, auto&& f) { arcs(v, +1, f); }, [&](uint32_t v, auto&& f) { arcs(v, -1, f); }))
            order.push_back(units[i + x]);
        i = j;
    }
    return order;
}

// A start order for sifting: per group, the greedy feedback-arc-set order, or `previous` when its
// backward weight is lower (measured_unit_order's first step; stats' start and greedy weights).
std::vector<uint32_t> start_order(size_t unit_count, const Arc* arcs, size_t arc_count, const uint32_t* group,
                                  const uint32_t* previous, MeasuredOrderStats& s);

void check_unit_order_input(size_t unit_count, const Arc* arcs, size_t arc_count, const uint32_t* previous);

}  // namespace

struct MeasuredPairCounts::State {
    std::vector<uint32_t> unit_of_triangle, group;
    uint32_t front_levels = 0;
    PairCounts counts;
    explicit State(size_t units) : counts(units) {}
    struct Scratch {
        std::vector<std::pair<uint32_t, uint32_t>> seen;
        std::vector<uint32_t> units;
    };
    // Every node into per-worker tables (accumulate(table, node, scratch)), then summed.
    template <typename Node, typename Accumulate>
    void add_nodes(const Node* const* nodes, size_t node_count, unsigned threads, Accumulate&& accumulate);
};

MeasuredPairCounts::MeasuredPairCounts(size_t unit_count, const uint32_t* unit_of_triangle, size_t triangle_count,
                                       const uint32_t* group, uint32_t front_levels) {
    if (unit_count >= UINT32_MAX) throw InvalidInput("measured graph: too many units");
    state_ = std::make_unique<State>(unit_count);
    state_->unit_of_triangle.assign(unit_of_triangle, unit_of_triangle + triangle_count);
    state_->front_levels = front_levels;
    if (group) state_->group.assign(group, group + unit_count);
}
MeasuredPairCounts::~MeasuredPairCounts() = default;
MeasuredPairCounts::MeasuredPairCounts(MeasuredPairCounts&&) noexcept = default;
MeasuredPairCounts& MeasuredPairCounts::operator=(MeasuredPairCounts&&) noexcept = default;

template <typename Node, typename Accumulate>
void MeasuredPairCounts::State::add_nodes(const Node* const* nodes, size_t node_count, unsigned threads,
                                          Accumulate&& accumulate) {
    if (worker_threads(threads) == 1) {  // straight into the counts: no table per worker to merge
        Scratch s;
        for (size_t n = 0; n < node_count; ++n) accumulate(counts, *nodes[n], s);
        return;
    }
    const size_t units = counts.units;
    tbb::enumerable_thread_specific<PairCounts> tables([units] { return PairCounts(units); });
    tbb::enumerable_thread_specific<Scratch> scratch;
    tbb::task_arena arena(worker_threads(threads));
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, node_count, 4), [&](const tbb::blocked_range<size_t>& r) {
            PairCounts& table = tables.local();
            Scratch& s = scratch.local();
            for (size_t n = r.begin(); n != r.end(); ++n) accumulate(table, *nodes[n], s);
        });
    });
    // Integer sums: the same whatever the worker that counted a node.
    for (const PairCounts& t : tables) counts.merge(t);
}

void MeasuredPairCounts::add(const NodeFragments* const* nodes, size_t node_count, int sign, unsigned threads) {
    State& s = *state_;
    const uint32_t* group = s.group.empty() ? nullptr : s.group.data();
    s.add_nodes(nodes, node_count, threads, [&](PairCounts& table, const NodeFragments& node, State::Scratch& w) {
        accumulate_node(table, node, s.unit_of_triangle.data(), s.unit_of_triangle.size(), s.counts.units, group,
                        s.front_levels, sign < 0 ? -1 : 1, w.seen, w.units);
    });
}

void MeasuredPairCounts::add(const KeptNode* const* nodes, size_t node_count, int sign, unsigned threads) {
    State& s = *state_;
    const uint32_t* group = s.group.empty() ? nullptr : s.group.data();
    s.add_nodes(nodes, node_count, threads, [&](PairCounts& table, const KeptNode& node, State::Scratch& w) {
        for_each_unit_list(node, s.unit_of_triangle.data(), s.unit_of_triangle.size(), w.units,
                           [&](const uint32_t* units, uint32_t n, uint32_t weight) {
                               accumulate_list(table, units, n, s.counts.units, group, s.front_levels,
                                               (sign < 0 ? -1 : 1) * int64_t(weight), w.seen);
                           });
    });
}

void MeasuredPairCounts::settle() { state_->counts.sparse.settle(); }

std::vector<Arc> MeasuredPairCounts::arcs() {
    PairCounts& c = state_->counts;
    c.sparse.settle();
    std::vector<Arc> arcs;
    if (c.units <= kDenseMeasuredUnits)
        arcs.reserve(size_t(c.dense.size() - size_t(std::count(c.dense.begin(), c.dense.end(), 0))));
    else
        arcs.reserve(c.sparse.is_wide ? c.sparse.settled_wide.size() : c.sparse.settled_narrow.size());
    for_each_arc(c, [&](uint32_t from, uint32_t to, uint64_t weight) { arcs.push_back({from, to, weight}); });
    return arcs;
}

std::vector<Arc> measured_overdraw_graph(const NodeFragments* const* nodes, size_t node_count,
                                         const uint32_t* unit_of_triangle, size_t triangle_count, size_t unit_count,
                                         const uint32_t* group, unsigned threads) {
    MeasuredPairCounts counts(unit_count, unit_of_triangle, triangle_count, group);
    counts.add(nodes, node_count, +1, threads);
    return counts.arcs();
}

uint64_t sift_order(uint32_t* order, size_t unit_count, const Arc* arcs, size_t arc_count, const uint32_t* group,
                    size_t max_passes) {
    // Signed adjacency: s(u, v) > 0 when u should come first (the arc u→v's weight).
    std::vector<size_t> start(unit_count + 1, 0);
    bool narrow = true;
    for (size_t i = 0; i < arc_count; ++i) {
        const Arc& a = arcs[i];
        if (a.from >= unit_count || a.to >= unit_count)
            throw InvalidInput("sifting: arc " + std::to_string(i) + " names a unit outside 0.." +
                               std::to_string(unit_count));
        if (a.from == a.to || (group && group[a.from] != group[a.to])) continue;
        narrow = narrow && a.weight <= uint64_t(std::numeric_limits<int32_t>::max());
        ++start[a.from + 1];
        ++start[a.to + 1];
    }
    std::partial_sum(start.begin(), start.end(), start.begin());
    if (arc_count > UINT32_MAX) throw InvalidInput("sifting: " + std::to_string(arc_count) + " arcs, more than 2^32");
    // Each unit's arcs (their indices), then handed to the other ends in order of the unit's
    // position: every list comes out sorted by position, in linear time.
    const auto sift = [&](auto graph) {
        using Weight = decltype(graph.adjacency[0].s);
        graph.adjacency.resize(start[unit_count]);
        {
            std::vector<uint32_t> arcs_of_unit(start[unit_count]);
            std::vector<size_t> fill(start.begin(), start.end() - 1);
            for (size_t i = 0; i < arc_count; ++i) {
                const Arc& a = arcs[i];
                if (a.from == a.to || (group && group[a.from] != group[a.to])) continue;
                arcs_of_unit[fill[a.from]++] = uint32_t(i);
                arcs_of_unit[fill[a.to]++] = uint32_t(i);
            }
            fill.assign(start.begin(), start.end() - 1);
            for (size_t x = 0; x < unit_count; ++x) {
                const uint32_t v = order[x];
                for (size_t e = start[v]; e < start[v + 1]; ++e) {
                    const Arc& a = arcs[arcs_of_unit[e]];  // the other end's entry s(other, v)
                    const bool other_first = a.to == v;
                    graph.adjacency[fill[other_first ? a.from : a.to]++] = {
                        v, other_first ? Weight(a.weight) : Weight(-int64_t(a.weight))};
                }
            }
        }
        graph.start = std::move(start);
        graph.by_position = true;
        sift_with(order, unit_count, group, max_passes, graph);
    };
    if (narrow)
        sift(SiftGraph<int32_t>());
    else
        sift(SiftGraph<int64_t>());
    return count_feedback_arcs(order, unit_count, arcs, arc_count).weight;
}

namespace {

// sift_order's search over the graph's adjacency.
template <typename Weight>
void sift_with(uint32_t* order, size_t unit_count, const uint32_t* group, size_t max_passes, SiftGraph<Weight>& graph) {
    using Neighbour = animorder::Neighbour<Weight>;
    const std::vector<size_t>& start = graph.start;
    std::vector<Neighbour>& adjacency = graph.adjacency;
    std::vector<uint32_t> position(unit_count);
    for (size_t i = 0; i < unit_count; ++i) position[order[i]] = uint32_t(i);
    // Each unit's neighbours, sorted by their current position when the unit is visited. Moving
    // one unit keeps the relative order of all others, so a list goes stale only when one of its
    // own neighbours moves: it is sorted again then, by insertion when few moved.
    const auto before = [&](const Neighbour& a, const Neighbour& b) {
        return position[a.unit] < position[b.unit] || (a.unit == b.unit && a.s < b.s);
    };
    std::vector<uint32_t> stale(unit_count, 0);  // neighbours moved since the list was sorted
    const auto sort_neighbours = [&](uint32_t u) {
        const auto begin = adjacency.begin() + start[u], end = adjacency.begin() + start[u + 1];
        if (size_t(stale[u]) * 16 >= size_t(end - begin)) {
            std::sort(begin, end, before);
        } else {
            for (auto n = begin + (begin != end); n < end; ++n)
                for (auto m = n; m != begin && before(*m, *(m - 1)); --m) std::iter_swap(m, m - 1);
        }
        stale[u] = 0;
    };
    // Lists built by position hold only a pair given twice out of place; others are sorted whole.
    for (uint32_t u = 0; u < unit_count; ++u) {
        stale[u] = graph.by_position ? 0 : UINT32_MAX / 16;
        sort_neighbours(u);
    }
    // Each group's block [first, last] in the order.
    std::vector<uint32_t> block_first(unit_count), block_last(unit_count);
    for (size_t i = 0; i < unit_count;) {
        size_t j = i;
        while (j < unit_count && (!group || group[order[j]] == group[order[i]])) ++j;
        for (size_t x = i; x < j; ++x) block_first[x] = uint32_t(i), block_last[x] = uint32_t(j - 1);
        i = j;
    }

    for (size_t pass = 0; pass < max_passes; ++pass) {
        bool moved = false;
        for (uint32_t u = 0; u < unit_count; ++u) {
            const uint32_t i = position[u];
            if (stale[u]) sort_neighbours(u);
            const auto begin = adjacency.begin() + start[u], end = adjacency.begin() + start[u + 1];
            const auto split =
                std::partition_point(begin, end, [&](const Neighbour& n) { return position[n.unit] < i; });
            // Moving u left past v changes the cost by −s(u, v), right past v by +s(u, v); the
            // best target is just before (left) or after (right) some neighbour.
            int64_t best = 0;
            uint32_t target = i;
            int64_t delta = 0;
            // (A neighbour's position is read only for a new best: the walks are plain sums.)
            for (auto n = split; n != begin;) {
                --n;
                delta -= n->s;
                if (delta < best && position[n->unit] >= block_first[i]) best = delta, target = position[n->unit];
            }
            delta = 0;
            for (auto n = split; n != end; ++n) {
                delta += n->s;
                if (delta < best && position[n->unit] <= block_last[i]) best = delta, target = position[n->unit];
            }
            if (target == i) continue;
            for (auto n = begin; n != end; ++n) ++stale[n->unit];
            if (target < i) {
                for (uint32_t x = i; x > target; --x) order[x] = order[x - 1], position[order[x]] = x;
            } else {
                for (uint32_t x = i; x < target; ++x) order[x] = order[x + 1], position[order[x]] = x;
            }
            order[target] = u;
            position[u] = target;
            moved = true;
        }
        if (!moved) break;
    }
}

void check_unit_order_input(size_t unit_count, const Arc* arcs, size_t arc_count, const uint32_t* previous) {
    if (previous) {
        std::vector<uint8_t> seen(unit_count, 0);
        for (size_t i = 0; i < unit_count; ++i) {
            if (previous[i] >= unit_count || seen[previous[i]])
                throw InvalidInput("measured order: the previous order is no permutation of " +
                                   std::to_string(unit_count) + " units");
            seen[previous[i]] = 1;
        }
    }
    for (size_t a = 0; a < arc_count; ++a)
        if (arcs[a].from >= unit_count || arcs[a].to >= unit_count)
            throw InvalidInput("measured order: arc " + std::to_string(a) + " names a unit outside 0.." +
                               std::to_string(unit_count));
}

std::vector<uint32_t> start_order(size_t unit_count, const Arc* arcs, size_t arc_count, const uint32_t* group,
                                  const uint32_t* previous, MeasuredOrderStats& s) {
    // Units of each group (ascending group id, units ascending), and the arcs inside each group.
    std::vector<uint32_t> units(unit_count);
    std::iota(units.begin(), units.end(), 0u);
    if (group)
        std::stable_sort(units.begin(), units.end(), [&](uint32_t a, uint32_t b) { return group[a] < group[b]; });
    std::vector<uint32_t> block_of_unit(unit_count, 0);  // the rank of the unit's group among the groups
    size_t blocks = 0;
    for (size_t i = 0; i < unit_count; ++i) {
        const bool first = i == 0 || (group && group[units[i]] != group[units[i - 1]]);
        block_of_unit[units[i]] = first ? uint32_t(blocks++) : block_of_unit[units[i - 1]];
    }
    std::vector<uint32_t> greedy;
    if (blocks <= 1) {  // one group: its units in id order, every arc inside it (no copy of the arcs)
        greedy = order_feedback_arc_set(unit_count, arcs, arc_count);
    } else {
        greedy.reserve(unit_count);
        std::vector<uint32_t> local(unit_count);
        // Each group's arcs, in the given order: one pass over the arcs, not one per group.
        std::vector<std::vector<size_t>> arcs_of_block(blocks);
        for (size_t a = 0; a < arc_count; ++a)
            if (group[arcs[a].from] == group[arcs[a].to]) arcs_of_block[block_of_unit[arcs[a].from]].push_back(a);
        for (size_t i = 0; i < unit_count;) {
            size_t j = i;
            while (j < unit_count && group[units[j]] == group[units[i]]) ++j;
            for (size_t x = i; x < j; ++x) local[units[x]] = uint32_t(x - i);
            std::vector<Arc> inside;
            const std::vector<size_t>& block_arcs = arcs_of_block[block_of_unit[units[i]]];
            inside.reserve(block_arcs.size());
            for (const size_t a : block_arcs) inside.push_back({local[arcs[a].from], local[arcs[a].to], arcs[a].weight});
            for (uint32_t x : order_feedback_arc_set(j - i, inside.data(), inside.size())) greedy.push_back(units[i + x]);
            i = j;
        }
    }
    s.greedy_weight = count_feedback_arcs(greedy.data(), unit_count, arcs, arc_count).weight;
    s.start_weight = s.greedy_weight;
    if (previous) {
        const uint64_t w = count_feedback_arcs(previous, unit_count, arcs, arc_count).weight;
        if (w < s.greedy_weight) {
            s.start_weight = w;
            s.from_previous = true;
            return std::vector<uint32_t>(previous, previous + unit_count);
        }
    }
    return greedy;
}

}  // namespace

std::vector<uint32_t> measured_unit_order(size_t unit_count, const Arc* arcs, size_t arc_count, const uint32_t* group,
                                          const uint32_t* previous, MeasuredOrderStats* stats, bool try_greedy) {
    check_unit_order_input(unit_count, arcs, arc_count, previous);
    MeasuredOrderStats s;
    std::vector<uint32_t> order;
    if (previous && !try_greedy) {
        order.assign(previous, previous + unit_count);
        s.start_weight = count_feedback_arcs(previous, unit_count, arcs, arc_count).weight;
        s.from_previous = true;
    } else {
        order = start_order(unit_count, arcs, arc_count, group, previous, s);
    }
    s.final_weight = sift_order(order.data(), unit_count, arcs, arc_count, group);
    s.arc_count = arc_count;
    if (stats) *stats = s;
    return order;
}

std::vector<uint32_t> measured_unit_order(MeasuredPairCounts& counts, const uint32_t* previous,
                                          MeasuredOrderStats* stats, bool try_greedy) {
    PairCounts& c = counts.state_->counts;
    const uint32_t* group = counts.state_->group.empty() ? nullptr : counts.state_->group.data();
    c.sparse.settle();
    const size_t unit_count = c.units;
    check_unit_order_input(unit_count, nullptr, 0, previous);
    // The signed adjacency straight from the counts (no array of arcs beside it): each list comes
    // out in ascending neighbour id, the order order_feedback_arc_set meets the arcs in.
    MeasuredOrderStats s;
    std::vector<size_t> start(unit_count + 1, 0);
    bool narrow = true;
    size_t arc_count = 0;
    const auto inside = [&](uint32_t from, uint32_t to) { return !group || group[from] == group[to]; };
    for_each_arc(c, [&](uint32_t from, uint32_t to, uint64_t weight) {
        ++s.arc_count;
        if (!inside(from, to)) return;
        narrow = narrow && weight <= uint64_t(std::numeric_limits<int32_t>::max());
        ++start[from + 1];
        ++start[to + 1];
        ++arc_count;
    });
    std::partial_sum(start.begin(), start.end(), start.begin());
    if (arc_count > UINT32_MAX) throw InvalidInput("sifting: " + std::to_string(arc_count) + " arcs, more than 2^32");
    std::vector<uint32_t> order;
    const auto search = [&](auto graph) {
        using Weight = decltype(graph.adjacency[0].s);
        graph.adjacency.resize(start[unit_count]);
        {
            std::vector<size_t> fill(start.begin(), start.end() - 1);
            for_each_arc(c, [&](uint32_t from, uint32_t to, uint64_t weight) {
                if (!inside(from, to)) return;
                graph.adjacency[fill[from]++] = {to, Weight(weight)};
                graph.adjacency[fill[to]++] = {from, Weight(-int64_t(weight))};
            });
        }
        graph.start = std::move(start);
        if (previous && !try_greedy) {
            order.assign(previous, previous + unit_count);
            s.start_weight = backward_weight(order.data(), unit_count, graph);
            s.from_previous = true;
        } else {
            order = greedy_order(unit_count, group, graph);
            s.greedy_weight = s.start_weight = backward_weight(order.data(), unit_count, graph);
            if (previous) {
                const uint64_t w = backward_weight(previous, unit_count, graph);
                if (w < s.greedy_weight) {
                    order.assign(previous, previous + unit_count);
                    s.start_weight = w;
                    s.from_previous = true;
                }
            }
        }
        sift_with(order.data(), unit_count, group, kSiftMaxPasses, graph);
        s.final_weight = backward_weight(order.data(), unit_count, graph);
    };
    if (narrow)
        search(SiftGraph<int32_t>());
    else
        search(SiftGraph<int64_t>());
    if (stats) *stats = s;
    return order;
}

}  // namespace animorder
