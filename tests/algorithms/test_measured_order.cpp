// Measured cluster orders (measured_order.cpp): the overdraw graph from kept fragments on
// hand-built scenes whose answer is known, the order it gives, and the local search against
// brute force on small random graphs (every permutation of up to 8 units) and on graphs worked by hand.
#include "animorder/invalid_input.h"
#include "animorder/kept_fragments.h"
#include "animorder/measured_order.h"
#include "animorder/nehab06.h"
#include "animorder/overdraw.h"
#include "animorder/rasterizer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <random>
#include <vector>

using namespace animorder;

namespace {

constexpr uint32_t kTie = 0x80000000u;

// NodeFragments from explicit pixels: each pixel's triangles nearest first (kTie marks a depth
// equal to the previous fragment's).
NodeFragments pixels(const std::vector<std::vector<uint32_t>>& list) {
    NodeFragments n;
    n.starts.push_back(0);
    for (const auto& p : list) {
        n.fragments.insert(n.fragments.end(), p.begin(), p.end());
        n.starts.push_back(uint32_t(n.fragments.size()));
    }
    n.visible = list.size();
    return n;
}

std::vector<Arc> graph_of(const std::vector<NodeFragments>& nodes, const std::vector<uint32_t>& unit_of_triangle,
                          size_t units, const uint32_t* group = nullptr, unsigned threads = 1) {
    std::vector<const NodeFragments*> p;
    for (const auto& n : nodes) p.push_back(&n);
    return measured_overdraw_graph(p.data(), p.size(), unit_of_triangle.data(), unit_of_triangle.size(), units, group,
                                   threads);
}

// A scene in clip space with w = 1 (orthographic): x, y, z are NDC; smaller z is nearer.
struct Scene {
    std::vector<float> clip;
    std::vector<uint32_t> ib;
    uint32_t vertex(float x, float y, float z) {
        clip.insert(clip.end(), {x, y, z, 1.0f});
        return uint32_t(clip.size() / 4 - 1);
    }
    void triangle(uint32_t a, uint32_t b, uint32_t c) { ib.insert(ib.end(), {a, b, c}); }
    NodeFragments rasterize(unsigned resolution) const {
        NodeRasterizer r;
        r.rasterize(clip.data(), clip.size() / 4, ib.data(), ib.size(), resolution);
        return r.export_fragments();
    }
};

// Passed fragments of a face order on a node (the overdraw engine's own count).
uint64_t passed(const NodeFragments& node, const std::vector<uint32_t>& order) {
    const std::vector<uint32_t> ranks = make_rank_table({order.data()}, order.size());
    uint64_t out = 0;
    score_fragments(&out, node, ranks.data(), 1);
    return out;
}

uint64_t cost(const std::vector<uint32_t>& order, const std::vector<Arc>& arcs) {
    return count_feedback_arcs(order.data(), order.size(), arcs.data(), arcs.size()).weight;
}

TEST(MeasuredGraph, CountsEachUnitsNearestFragmentAgainstEveryUnitInFront) {
    // Triangles 0,1 → unit 0; 2 → unit 1; 3 → unit 2.
    const std::vector<uint32_t> unit = {0, 0, 1, 2};
    // Pixel a: units 0,1,2 front to back → 0→1, 0→2, 1→2. Pixel b: 2 in front of 0 (0's two
    // fragments count once) → 2→0. Pixel c: 1 and 0 at equal depth (tie) → nothing.
    const NodeFragments n = pixels({{0, 2, 3}, {3, 0, 1}, {2, 1 | kTie}});
    const std::vector<Arc> arcs = graph_of({n}, unit, 3);
    // Net: (0,1): 1 − 0 → 0→1 (1); (0,2): 1 − 1 → none; (1,2): 1 → 1→2 (1).
    ASSERT_EQ(arcs.size(), 2u);
    EXPECT_EQ(arcs[0].from, 0u);
    EXPECT_EQ(arcs[0].to, 1u);
    EXPECT_EQ(arcs[0].weight, 1u);
    EXPECT_EQ(arcs[1].from, 1u);
    EXPECT_EQ(arcs[1].to, 2u);
    EXPECT_EQ(arcs[1].weight, 1u);
}

TEST(MeasuredGraph, SameWhateverTheThreadCountAndDropsArcsBetweenGroups) {
    std::mt19937 rng(7);
    std::vector<NodeFragments> nodes;
    for (int n = 0; n < 40; ++n) {
        std::vector<std::vector<uint32_t>> list;
        for (int p = 0; p < 200; ++p) {
            std::vector<uint32_t> px;
            for (int f = 0, count = 2 + int(rng() % 5); f < count; ++f) px.push_back(rng() % 30);
            list.push_back(px);
        }
        nodes.push_back(pixels(list));
    }
    std::vector<uint32_t> unit(30), group(10);
    for (uint32_t t = 0; t < 30; ++t) unit[t] = t / 3;
    for (uint32_t u = 0; u < 10; ++u) group[u] = u < 5 ? 0 : 1;
    const std::vector<Arc> one = graph_of(nodes, unit, 10, group.data(), 1);
    const std::vector<Arc> two = graph_of(nodes, unit, 10, group.data(), 2);
    ASSERT_EQ(one.size(), two.size());
    ASSERT_FALSE(one.empty());
    for (size_t i = 0; i < one.size(); ++i) {
        EXPECT_EQ(one[i].from, two[i].from);
        EXPECT_EQ(one[i].to, two[i].to);
        EXPECT_EQ(one[i].weight, two[i].weight);
        EXPECT_EQ(group[one[i].from], group[one[i].to]);
    }
}

TEST(MeasuredGraph, FrontLevelsPairEachUnitWithTheNearestDepthLevelsInFrontOnly) {
    // One pixel, units 0..4 front to back, 1 and 2 at one depth (a tie): levels 0, 1, 1, 2, 3.
    const std::vector<uint32_t> unit = {0, 1, 2, 3, 4};
    const NodeFragments n = pixels({{0, 1, 2 | kTie, 3, 4}});
    const NodeFragments* nodes[] = {&n};
    const auto pairs = [&](uint32_t front_levels) {
        MeasuredPairCounts counts(5, unit.data(), unit.size(), nullptr, front_levels);
        counts.add(nodes, 1, +1, 1);
        std::vector<std::pair<uint32_t, uint32_t>> out;
        for (const Arc& a : counts.arcs()) out.emplace_back(a.from, a.to);
        return out;
    };
    using P = std::vector<std::pair<uint32_t, uint32_t>>;
    // Every level: every pair at different depths.
    EXPECT_EQ(pairs(0), (P{{0, 1}, {0, 2}, {0, 3}, {0, 4}, {1, 3}, {1, 4}, {2, 3}, {2, 4}, {3, 4}}));
    // One level: the tied 1 and 2 are one level, both in front of 3; 4 sees 3 only.
    EXPECT_EQ(pairs(1), (P{{0, 1}, {0, 2}, {1, 3}, {2, 3}, {3, 4}}));
    // Two levels: 3 reaches back to 0, 4 to 1 and 2 but not 0.
    EXPECT_EQ(pairs(2), (P{{0, 1}, {0, 2}, {0, 3}, {1, 3}, {1, 4}, {2, 3}, {2, 4}, {3, 4}}));

    // Levels are counted within a unit's group: units 0, 2, 3 in group 0 and 1 in group 1, front to
    // back 0, 1, 2, 3. One level: 2's nearest level of its group is 0's (1's is another group's).
    const std::vector<uint32_t> group = {0, 1, 0, 0, 0};
    const NodeFragments g = pixels({{0, 1, 2, 3}});
    const NodeFragments* grouped[] = {&g};
    MeasuredPairCounts counts(5, unit.data(), unit.size(), group.data(), 1);
    counts.add(grouped, 1, +1, 1);
    P got;
    for (const Arc& a : counts.arcs()) got.emplace_back(a.from, a.to);
    EXPECT_EQ(got, (P{{0, 2}, {2, 3}}));
}

// A second implementation of the graph's definition (a map of pair counts), against the library
// on random pixels, with few units (the dense matrix) and many (the hash table), over every level
// in front and over the nearest one and two (MeasuredPairCounts' front_levels).
TEST(MeasuredGraph, MatchesASecondImplementationDenseAndSparse) {
    // 20: the dense triangle; 1700: 8-byte table slots; 70000: more than 16-bit unit ids, 16-byte slots.
    for (const size_t units : {size_t(20), size_t(1700), size_t(70000)}) {
        std::mt19937 rng{uint32_t(units)};
        const size_t triangles = 2 * units;
        std::vector<uint32_t> unit(triangles);
        for (size_t t = 0; t < triangles; ++t) unit[t] = uint32_t(rng() % units);
        std::vector<NodeFragments> nodes;
        // (a, b): pixels with a strictly in front of b, per front_levels 0, 1, 2
        std::map<std::pair<uint32_t, uint32_t>, int64_t> front_of[3];
        for (int n = 0; n < 5; ++n) {
            std::vector<std::vector<uint32_t>> list;
            for (int p = 0; p < 400; ++p) {
                std::vector<uint32_t> px;
                std::vector<std::pair<uint32_t, int>> first;  // unit, depth level of its nearest fragment
                int level = 0;
                for (int f = 0, count = 2 + int(rng() % 6); f < count; ++f) {
                    const uint32_t t = uint32_t(rng() % (units < 100 ? triangles : 400));  // overlap often
                    const bool tie = f > 0 && rng() % 5 == 0;
                    px.push_back(t | (tie ? kTie : 0));
                    if (f > 0 && !tie) ++level;
                    bool known = false;
                    for (auto& x : first) known |= x.first == unit[t];
                    if (!known) first.emplace_back(unit[t], level);
                }
                for (auto& b : first) {
                    std::vector<int> levels;  // the distinct levels in front of b, nearest first
                    for (auto& a : first)
                        if (a.second < b.second) levels.push_back(a.second);
                    std::sort(levels.rbegin(), levels.rend());
                    levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
                    for (auto& a : first) {
                        if (a.second >= b.second) continue;
                        const long rank = std::find(levels.begin(), levels.end(), a.second) - levels.begin();
                        for (int front_levels = 0; front_levels < 3; ++front_levels)
                            if (front_levels == 0 || rank < front_levels) ++front_of[front_levels][{a.first, b.first}];
                    }
                }
                list.push_back(px);
            }
            nodes.push_back(pixels(list));
        }
        std::vector<const NodeFragments*> pointers;
        for (const NodeFragments& n : nodes) pointers.push_back(&n);
        for (uint32_t front_levels = 0; front_levels < 3; ++front_levels) {
            std::map<std::pair<uint32_t, uint32_t>, uint64_t> expected;
            for (const auto& [pair, count] : front_of[front_levels]) {
                const auto reverse = front_of[front_levels].find({pair.second, pair.first});
                const int64_t net = count - (reverse == front_of[front_levels].end() ? 0 : reverse->second);
                if (net > 0) expected[pair] = uint64_t(net);
            }
            MeasuredPairCounts counts(units, unit.data(), unit.size(), nullptr, front_levels);
            counts.add(pointers.data(), pointers.size(), +1, 2);
            std::map<std::pair<uint32_t, uint32_t>, uint64_t> got;
            for (const Arc& a : counts.arcs()) got[{a.from, a.to}] = a.weight;
            EXPECT_FALSE(expected.empty());
            EXPECT_EQ(got, expected) << units << " units, " << front_levels << " front levels";
            if (front_levels == 0) {
                std::map<std::pair<uint32_t, uint32_t>, uint64_t> graph;
                for (const Arc& a : graph_of(nodes, unit, units, nullptr, 2)) graph[{a.from, a.to}] = a.weight;
                EXPECT_EQ(graph, expected) << units << " units, measured_overdraw_graph";
            }
        }
    }
}

// k-means moves nodes between clusters: counting A and B, then removing A, must give B's graph.
TEST(MeasuredGraph, RemovingNodesGivesTheGraphOfTheRest) {
    for (const size_t units : {size_t(6), size_t(1100)}) {  // dense and hashed counts
        std::vector<uint32_t> unit(units);
        std::iota(unit.begin(), unit.end(), 0u);
        const NodeFragments a = pixels({{0, 1}, {1, 2}, {3, 4, 5}, {5, 0}});
        const NodeFragments b = pixels({{1, 0}, {1, 0}, {2, 1}, {4, 3}});
        const NodeFragments* both[] = {&a, &b};
        const NodeFragments* only_a[] = {&a};
        MeasuredPairCounts counts(units, unit.data(), units, nullptr);
        counts.add(both, 2, +1, 1);
        counts.add(only_a, 1, -1, 1);
        const std::vector<Arc> got = counts.arcs();
        // b alone: 1→0 (2), 2→1 (1), 4→3 (1).
        ASSERT_EQ(got.size(), 3u) << units;
        EXPECT_EQ(got[0].from, 1u);
        EXPECT_EQ(got[0].to, 0u);
        EXPECT_EQ(got[0].weight, 2u);
        EXPECT_EQ(got[1].from, 2u);
        EXPECT_EQ(got[1].to, 1u);
        EXPECT_EQ(got[1].weight, 1u);
        EXPECT_EQ(got[2].from, 4u);
        EXPECT_EQ(got[2].to, 3u);
        EXPECT_EQ(got[2].weight, 1u);
    }
}

// A pair's net count beyond 32 bits (the compact entries' limit) moves the counts to 64-bit
// entries with nothing lost, and removing nodes after that still gives the rest's graph: 40,000
// nodes of 65,535 pixels where unit 5 covers unit 7 (2,621,400,000 pixels, above 2^31 − 1), then
// all but one removed. Counted at once (the sum overflows while counting) and in two halves
// settled one after the other (the sum overflows when the second half is settled). The order from
// the counts is the order of their arcs (64-bit weights in sifting).
TEST(MeasuredGraph, NetCountsBeyond32BitsAreKeptExactly) {
    const size_t units = 1100;
    std::vector<uint32_t> unit(units), starts(units + 1);
    std::iota(unit.begin(), unit.end(), 0u);
    std::iota(starts.begin(), starts.end(), 0u);
    const UnitPartition partition = make_unit_partition(starts.data(), units, unit.data(), units);
    KeepScratch scratch;
    const auto kept = [&](const std::vector<std::vector<uint32_t>>& list) {
        const NodeFragments n = pixels(list);
        return keep_fragments(n.visible, n.single, n.starts.data(), n.starts.size() - 1, n.fragments.data(),
                              partition, scratch);
    };
    const KeptNode big = kept(std::vector<std::vector<uint32_t>>(65535, {5, 7}));
    const KeptNode small = kept({{9, 3}, {9, 3}, {2, 4}, {7, 5}});
    const std::vector<const KeptNode*> many(40000, &big);
    const KeptNode* const other = &small;
    const auto weight = [](const std::vector<Arc>& arcs, uint32_t from, uint32_t to) {
        for (const Arc& a : arcs)
            if (a.from == from && a.to == to) return a.weight;
        return uint64_t(0);
    };
    for (const bool halves : {false, true}) {
        MeasuredPairCounts counts(units, unit.data(), units, nullptr);
        counts.add(&other, 1, +1, 1);
        if (halves) {
            counts.add(many.data(), many.size() / 2, +1, 2);
            counts.settle();
            counts.add(many.data(), many.size() - many.size() / 2, +1, 1);
            counts.settle();
        } else {
            counts.add(many.data(), many.size(), +1, 2);
        }
        std::vector<Arc> arcs = counts.arcs();
        ASSERT_EQ(arcs.size(), 3u) << halves;
        EXPECT_EQ(weight(arcs, 5, 7), uint64_t(40000) * 65535 - 1) << halves;
        EXPECT_EQ(weight(arcs, 9, 3), 2u) << halves;
        EXPECT_EQ(weight(arcs, 2, 4), 1u) << halves;
        MeasuredOrderStats from_counts, from_arcs;
        EXPECT_EQ(measured_unit_order(counts, nullptr, &from_counts),
                  measured_unit_order(units, arcs.data(), arcs.size(), nullptr, nullptr, &from_arcs));
        EXPECT_EQ(from_counts.final_weight, from_arcs.final_weight);
        if (halves) {
            counts.add(many.data(), many.size() / 2, -1, 1);
            counts.settle();
            counts.add(many.data(), many.size() - many.size() / 2 - 1, -1, 1);
        } else {
            counts.add(many.data(), many.size() - 1, -1, 1);
        }
        arcs = counts.arcs();
        ASSERT_EQ(arcs.size(), 3u) << halves;
        EXPECT_EQ(weight(arcs, 5, 7), 65534u) << halves;
        EXPECT_EQ(weight(arcs, 9, 3), 2u) << halves;
        // A pair whose counts cancel leaves no arc: 7 over 5 once more, settled.
        const KeptNode again = kept(std::vector<std::vector<uint32_t>>(65534, {7, 5}));
        const KeptNode* const cancel = &again;
        counts.add(&cancel, 1, +1, 1);
        counts.settle();
        arcs = counts.arcs();
        ASSERT_EQ(arcs.size(), 2u) << halves;
        EXPECT_EQ(weight(arcs, 5, 7), 0u) << halves;
    }
}

// The order from the counts themselves (sifting's adjacency read from the settled pairs, the greedy
// order over it) against the order of their arcs: the same order and the same statistics, with and
// without groups, with no previous order, a previous order tried against the greedy one, and a
// previous order taken as the start; dense counts, 8-byte entries and 16-byte entries.
TEST(MeasuredOrder, FromTheCountsIsTheOrderOfTheirArcs) {
    int took_previous = 0;  // cases where the previous order beat the greedy one (both paths taken)
    for (const size_t units : {size_t(20), size_t(1700), size_t(70000)}) {
        std::mt19937 rng{uint32_t(units) + 7};
        const size_t triangles = 2 * units;
        std::vector<uint32_t> unit(triangles);
        for (size_t t = 0; t < triangles; ++t) unit[t] = uint32_t(rng() % units);
        std::vector<NodeFragments> nodes;
        for (int n = 0; n < 4; ++n) {
            std::vector<std::vector<uint32_t>> list;
            for (int p = 0; p < 600; ++p) {
                std::vector<uint32_t> px;
                for (int f = 0, count = 2 + int(rng() % 5); f < count; ++f)
                    px.push_back(uint32_t(rng() % (units < 100 ? triangles : 500)) | (f > 0 && rng() % 5 == 0 ? kTie : 0));
                list.push_back(px);
            }
            nodes.push_back(pixels(list));
        }
        std::vector<const NodeFragments*> pointers;
        for (const NodeFragments& n : nodes) pointers.push_back(&n);
        for (const uint32_t groups : {1u, 3u}) {
            std::vector<uint32_t> group(units);
            for (auto& g : group) g = uint32_t(rng() % groups);
            // Two copies of the same counts: one left with counts it has not settled (the order
            // settles them), the other giving the arcs.
            const auto counted = [&] {
                MeasuredPairCounts c(units, unit.data(), unit.size(), groups > 1 ? group.data() : nullptr, 2);
                c.add(pointers.data(), 3, +1, 2);
                c.settle();
                c.add(pointers.data() + 3, 1, +1, 1);
                return c;
            };
            MeasuredPairCounts counts = counted(), for_arcs = counted();
            const std::vector<Arc> arcs = for_arcs.arcs();
            ASSERT_FALSE(arcs.empty());
            // A previous order that beats the greedy one: the sifted order itself, a little
            // shuffled inside each group (start 1 then takes it).
            std::vector<uint32_t> previous;
            for (int start = 0; start < 3; ++start) {
                const uint32_t* prev = start == 0 ? nullptr : previous.data();
                const bool try_greedy = start != 2;
                MeasuredOrderStats a, b;
                const std::vector<uint32_t> got =
                    start == 0 ? measured_unit_order(counts, prev, &a, try_greedy)
                               : measured_unit_order(for_arcs, prev, &a, try_greedy);
                const std::vector<uint32_t> expected = measured_unit_order(
                    units, arcs.data(), arcs.size(), groups > 1 ? group.data() : nullptr, prev, &b, try_greedy);
                const std::string where =
                    std::to_string(units) + " units, " + std::to_string(groups) + " groups, start " + std::to_string(start);
                ASSERT_EQ(got, expected) << where;
                EXPECT_EQ(a.greedy_weight, b.greedy_weight) << where;
                EXPECT_EQ(a.start_weight, b.start_weight) << where;
                EXPECT_EQ(a.final_weight, b.final_weight) << where;
                EXPECT_EQ(a.from_previous, b.from_previous) << where;
                EXPECT_EQ(a.arc_count, arcs.size()) << where;
                EXPECT_EQ(b.arc_count, arcs.size()) << where;
                EXPECT_EQ(a.final_weight, cost(got, arcs)) << where;
                took_previous += start == 1 && a.from_previous;
                if (start == 0) {
                    previous = got;
                    for (size_t i = 0; i + 1 < units; i += 7)  // a few neighbours swapped inside a group
                        if (groups == 1 || group[previous[i]] == group[previous[i + 1]])
                            std::swap(previous[i], previous[i + 1]);
                }
            }
        }
    }
    EXPECT_GE(took_previous, 2);
}

TEST(MeasuredGraph, RejectsTrianglesAndUnitsOutOfRange) {
    const NodeFragments n = pixels({{0, 5}});
    EXPECT_THROW(graph_of({n}, {0, 1}, 2), InvalidInput);
    EXPECT_THROW(graph_of({n}, {0, 1, 2, 3, 4, 9}, 6), InvalidInput);
}

// Nested shells: an outer plate (unit 0) and an inner plate (unit 1), each two-sided (a triangle
// of each winding). Seen from outside (the outer plate nearer) and from inside the outer shell,
// looking out past the inner one (the inner plate nearer; the view is mirrored, so the other
// winding faces the camera). Two clusters of nodes, one per side: each cluster's measured order
// must draw its own occluder first, and must pass fewer fragments than the other order.
TEST(MeasuredOrder, NestedShellsEachClusterPutsItsOwnOccluderFirst) {
    auto plate_scene = [](float outer_z, float inner_z, float mirror) {
        Scene s;
        auto plate = [&](float half, float z) {
            const uint32_t a = s.vertex(-half * mirror, -half, z), b = s.vertex(half * mirror, -half, z),
                           c = s.vertex(half * mirror, half, z), d = s.vertex(-half * mirror, half, z);
            s.triangle(a, b, c);  // one winding
            s.triangle(a, c, b);  // the other (two-sided)
            s.triangle(a, c, d);
            s.triangle(a, d, c);
        };
        plate(0.8f, outer_z);  // triangles 0–3: outer shell
        plate(0.5f, inner_z);  // triangles 4–7: inner shell
        return s.rasterize(32);
    };
    const std::vector<uint32_t> unit = {0, 0, 0, 0, 1, 1, 1, 1};
    // Outside: outer plate nearer (z −0.5) than the inner one (0). Inside, mirrored: inner nearer.
    const std::vector<NodeFragments> outside = {plate_scene(-0.5f, 0.0f, 1.0f), plate_scene(-0.6f, 0.1f, 1.0f)};
    const std::vector<NodeFragments> inside = {plate_scene(0.5f, 0.0f, -1.0f), plate_scene(0.6f, -0.1f, -1.0f)};
    // Inner plate: pixel centres inside ±0.5 NDC of a 32² view: 16 × 16 = 256 pixels, each
    // covered by one front-facing triangle of each plate.
    const std::vector<Arc> out_arcs = graph_of(outside, unit, 2), in_arcs = graph_of(inside, unit, 2);
    ASSERT_EQ(out_arcs.size(), 1u);
    EXPECT_EQ(out_arcs[0].from, 0u);
    EXPECT_EQ(out_arcs[0].to, 1u);
    EXPECT_EQ(out_arcs[0].weight, 2u * 256u);
    ASSERT_EQ(in_arcs.size(), 1u);
    EXPECT_EQ(in_arcs[0].from, 1u);
    EXPECT_EQ(in_arcs[0].to, 0u);
    EXPECT_EQ(in_arcs[0].weight, 2u * 256u);

    const std::vector<uint32_t> out_order = measured_unit_order(2, out_arcs.data(), out_arcs.size(), nullptr, nullptr);
    const std::vector<uint32_t> in_order = measured_unit_order(2, in_arcs.data(), in_arcs.size(), nullptr, nullptr);
    EXPECT_EQ(out_order, (std::vector<uint32_t>{0, 1}));
    EXPECT_EQ(in_order, (std::vector<uint32_t>{1, 0}));
    // On the fragments themselves: outer-first passes the 256 inner pixels fewer from outside.
    const std::vector<uint32_t> outer_first = {0, 1, 2, 3, 4, 5, 6, 7}, inner_first = {4, 5, 6, 7, 0, 1, 2, 3};
    EXPECT_EQ(passed(outside[0], inner_first) - passed(outside[0], outer_first), 256u);
    EXPECT_EQ(passed(inside[0], outer_first) - passed(inside[0], inner_first), 256u);
}

// A cycle 0→1 (5), 1→2 (4), 2→0 (1) measured from pixels: some arc must be violated, and the
// order must keep the two heavier ones (drop 2→0: order 0, 1, 2, backward weight 1).
TEST(MeasuredOrder, CyclicOcclusionKeepsTheHeavierArcs) {
    std::vector<std::vector<uint32_t>> list;
    for (int i = 0; i < 5; ++i) list.push_back({0, 1});
    for (int i = 0; i < 4; ++i) list.push_back({1, 2});
    list.push_back({2, 0});
    const std::vector<Arc> arcs = graph_of({pixels(list)}, {0, 1, 2}, 3);
    ASSERT_EQ(arcs.size(), 3u);
    MeasuredOrderStats stats;
    // Start from the worst rotation: the search must still reach the best order.
    const std::vector<uint32_t> previous = {2, 0, 1};
    const std::vector<uint32_t> order =
        measured_unit_order(3, arcs.data(), arcs.size(), nullptr, previous.data(), &stats);
    EXPECT_EQ(order, (std::vector<uint32_t>{0, 1, 2}));
    EXPECT_EQ(stats.final_weight, 1u);
    EXPECT_EQ(cost(order, arcs), 1u);
}

// Two long thin patches crossing in depth, seen along −z (orthographic): A runs along x from
// near (z −0.8 at x −0.9) to far (z 0.8 at x 0.9), its centroid at depth 0; B runs along y at
// x ≈ 0.7, at constant depth 0.3 — farther than A's centroid, so any sort by centroid distance
// draws A first. Where they cross (x ≈ 0.7) A is at depth ≈ 0.62, behind B: drawing A first
// overdraws there. The measured graph says B before A, and that order passes fewer fragments.
TEST(MeasuredOrder, CrossingPatchesGraphBeatsDistance) {
    Scene s;
    {
        const uint32_t a = s.vertex(-0.9f, -0.1f, -0.8f), b = s.vertex(0.9f, -0.1f, 0.8f),
                       c = s.vertex(0.9f, 0.1f, 0.8f), d = s.vertex(-0.9f, 0.1f, -0.8f);
        s.triangle(a, b, c);
        s.triangle(a, c, d);
        const uint32_t e = s.vertex(0.6f, -0.9f, 0.3f), f = s.vertex(0.8f, -0.9f, 0.3f), g = s.vertex(0.8f, 0.9f, 0.3f),
                       h = s.vertex(0.6f, 0.9f, 0.3f);
        s.triangle(e, f, g);
        s.triangle(e, g, h);
    }
    const NodeFragments node = s.rasterize(64);
    // Premise: centroid depths (the distance sort's key from this eye) A = 0 < B = 0.3.
    const float a_depth = (-0.8f + 0.8f + 0.8f + -0.8f) / 4, b_depth = 0.3f;
    ASSERT_LT(a_depth, b_depth);
    const std::vector<Arc> arcs = graph_of({node}, {0, 0, 1, 1}, 2);
    ASSERT_EQ(arcs.size(), 1u);
    EXPECT_EQ(arcs[0].from, 1u);
    EXPECT_EQ(arcs[0].to, 0u);
    const std::vector<uint32_t> order = measured_unit_order(2, arcs.data(), arcs.size(), nullptr, nullptr);
    EXPECT_EQ(order, (std::vector<uint32_t>{1, 0}));
    // The overlap: x in (0.6, 0.8) × y in (−0.1, 0.1) of a 64² view: about 6.4 × 6.4 pixels.
    const uint64_t distance_order = passed(node, {0, 1, 2, 3}), graph_order = passed(node, {2, 3, 0, 1});
    EXPECT_EQ(distance_order - graph_order, arcs[0].weight);
    EXPECT_GE(arcs[0].weight, 25u);
    EXPECT_LE(arcs[0].weight, 49u);
}

// Brute force: the least backward weight over every permutation.
uint64_t best_cost(size_t n, const std::vector<Arc>& arcs) {
    std::vector<uint32_t> p(n);
    std::iota(p.begin(), p.end(), 0u);
    uint64_t best = UINT64_MAX;
    do best = std::min(best, cost(p, arcs));
    while (std::next_permutation(p.begin(), p.end()));
    return best;
}

std::vector<Arc> random_graph(std::mt19937& rng, size_t n) {
    std::vector<Arc> arcs;
    for (uint32_t a = 0; a < n; ++a)
        for (uint32_t b = a + 1; b < n; ++b) {
            if (rng() % 3 == 0) continue;
            const uint64_t w = 1 + rng() % 20;
            if (rng() % 2)
                arcs.push_back({a, b, w});
            else
                arcs.push_back({b, a, w});
        }
    return arcs;
}

// Whether no single move (remove a unit, insert it anywhere else) lowers `order`'s cost below
// `weight`, by brute force over every move: what sifting guarantees once a pass moves nothing.
::testing::AssertionResult no_single_move_lowers(const std::vector<uint32_t>& order, const std::vector<Arc>& arcs,
                                                 uint64_t weight) {
    const size_t n = order.size();
    for (size_t from = 0; from < n; ++from)
        for (size_t to = 0; to < n; ++to) {
            std::vector<uint32_t> moved = order;
            const uint32_t u = moved[from];
            moved.erase(moved.begin() + long(from));
            moved.insert(moved.begin() + long(to), u);
            if (cost(moved, arcs) < weight)
                return ::testing::AssertionFailure()
                       << "moving unit " << u << " from " << from << " to " << to << " lowers the cost from " << weight
                       << " to " << cost(moved, arcs);
        }
    return ::testing::AssertionSuccess();
}

// What sift_order guarantees (measured_order.h): the cost never rises, the weight it returns is
// count_feedback_arcs of the order it leaves, and, once a pass moves nothing (well inside
// max_passes at these sizes), no single move lowers the cost: a local optimum. A local optimum is
// not always the optimum (the hand-worked DAG below), but for n <= 3 it is: with units x y z in
// that order, the moves give w(yx) <= w(xy) (swap x, y) and w(zx) + w(zy) <= w(xz) + w(yz) (z to
// the front); their sum is cost(x y z) <= cost(z y x), and z y x is the only order of three no
// single move reaches. So there the result must equal the brute-force optimum over every order.
TEST(Sifting, NeverRaisesTheCostAndEndsAtALocalOptimumAgainstBruteForce) {
    std::mt19937 rng(20170501);
    size_t exact = 0;
    for (int trial = 0; trial < 300; ++trial) {
        const size_t n = 2 + trial % 7;  // 2..8 units
        const std::vector<Arc> arcs = random_graph(rng, n);
        std::vector<uint32_t> order(n);
        std::iota(order.begin(), order.end(), 0u);
        std::shuffle(order.begin(), order.end(), rng);
        const uint64_t before = cost(order, arcs);
        const uint64_t after = sift_order(order.data(), n, arcs.data(), arcs.size(), nullptr);
        std::vector<uint32_t> sorted = order;
        std::sort(sorted.begin(), sorted.end());
        for (size_t i = 0; i < n; ++i) ASSERT_EQ(sorted[i], i);  // still a permutation
        ASSERT_EQ(after, count_feedback_arcs(order.data(), n, arcs.data(), arcs.size()).weight) << "trial " << trial;
        ASSERT_EQ(after, cost(order, arcs));
        ASSERT_LE(after, before);
        const uint64_t best = best_cost(n, arcs);
        ASSERT_GE(after, best);
        if (n <= 3) {
            ASSERT_EQ(after, best) << "trial " << trial << ": a local optimum of " << n << " units is the optimum";
            ++exact;
        }
        // No single move (remove a unit, insert it anywhere) lowers the cost any more.
        ASSERT_TRUE(no_single_move_lowers(order, arcs, after)) << "trial " << trial;
        // The whole step is never worse than the greedy order nor than its start.
        MeasuredOrderStats stats;
        measured_unit_order(n, arcs.data(), arcs.size(), nullptr, order.data(), &stats);
        ASSERT_LE(stats.final_weight, stats.greedy_weight);
        ASSERT_LE(stats.final_weight, after);
    }
    EXPECT_EQ(exact, 86u);  // 43 trials of 2 units and 43 of 3, each compared with the optimum
}

// Sifting on graphs worked by hand: the order it leaves, its weight, and the brute-force optimum.
TEST(Sifting, HandWorkedGraphsEndWhereTheStatementSays) {
    // A 3-cycle 0→1 (3), 1→2 (2), 2→0 (1) from its worst order 2 1 0 (weight 5). Pass 1: unit 0
    // moves left past 1 (−3; past 2 as well would be −2): 2 0 1, weight 2; unit 1 gains nothing;
    // unit 2 moves right past 0 and 1 (+1 − 2 = −1): 0 1 2, weight 1, the lightest arc backward.
    // Pass 2 moves nothing. The optimum (n = 3, as above).
    {
        const std::vector<Arc> arcs = {{0, 1, 3}, {1, 2, 2}, {2, 0, 1}};
        std::vector<uint32_t> order = {2, 1, 0};
        ASSERT_EQ(cost(order, arcs), 5u);
        EXPECT_EQ(sift_order(order.data(), 3, arcs.data(), arcs.size(), nullptr), 1u);
        EXPECT_EQ(order, (std::vector<uint32_t>{0, 1, 2}));
        EXPECT_EQ(best_cost(3, arcs), 1u);
    }
    // A unit moves only when the cost drops strictly. The cycle 0→1→3→0 (weights 1) and 2→3 (1)
    // in the optimal order 0 1 2 3 (weight 1, 3→0 backward): moving 0 to the end, past 1 and 3,
    // ties (+1 − 1) and no move gains, so nothing moves. (Moving on ties, the cycle's units would
    // go round it pass after pass and end elsewhere: 2 0 1 3.)
    {
        const std::vector<Arc> arcs = {{0, 1, 1}, {1, 3, 1}, {3, 0, 1}, {2, 3, 1}};
        std::vector<uint32_t> order = {0, 1, 2, 3};
        EXPECT_EQ(sift_order(order.data(), 4, arcs.data(), arcs.size(), nullptr), 1u);
        EXPECT_EQ(order, (std::vector<uint32_t>{0, 1, 2, 3}));
        EXPECT_EQ(best_cost(4, arcs), 1u);
    }
    // Local, not global: the acyclic 2→3 (10), 3→0 (1), 0→1 (10) in the order 0 1 2 3 has one
    // backward arc, 3→0 (weight 1). Fixing it by one move drags a heavy arc backward with it (0
    // after 1, or 3 before 2: +10 − 1), and moving 1 or 2 alone changes nothing, so sifting
    // stays there although 2 3 0 1 has no backward arc.
    {
        const std::vector<Arc> arcs = {{2, 3, 10}, {3, 0, 1}, {0, 1, 10}};
        std::vector<uint32_t> order = {0, 1, 2, 3};
        EXPECT_EQ(sift_order(order.data(), 4, arcs.data(), arcs.size(), nullptr), 1u);
        EXPECT_EQ(order, (std::vector<uint32_t>{0, 1, 2, 3}));
        EXPECT_TRUE(no_single_move_lowers(order, arcs, 1));
        EXPECT_EQ(best_cost(4, arcs), 0u);
        const std::vector<uint32_t> best = {2, 3, 0, 1};
        EXPECT_EQ(cost(best, arcs), 0u);
    }
}

TEST(Sifting, KeepsEveryGroupInItsBlock) {
    std::mt19937 rng(3);
    for (int trial = 0; trial < 50; ++trial) {
        const size_t n = 8;
        std::vector<Arc> arcs = random_graph(rng, n);
        const std::vector<uint32_t> group = {0, 0, 0, 1, 1, 1, 1, 2};
        std::vector<uint32_t> previous = {2, 0, 1, 6, 3, 5, 4, 7};
        MeasuredOrderStats stats;
        const std::vector<uint32_t> order =
            measured_unit_order(n, arcs.data(), arcs.size(), group.data(), previous.data(), &stats);
        for (size_t i = 0; i < n; ++i) ASSERT_EQ(group[order[i]], group[i]) << "trial " << trial;
        // Within groups the result is optimal or at least no worse than both starts.
        ASSERT_LE(stats.final_weight, stats.greedy_weight);
        ASSERT_LE(stats.final_weight, cost(previous, arcs));
    }
}

// The plain statement of sifting, as sift_order first did it: per unit, its neighbours sorted
// by position on each side (no lists kept sorted between moves). A second method for
// sift_order's bookkeeping: both must move the same units to the same places.
std::vector<uint32_t> plain_sift(std::vector<uint32_t> order, const std::vector<Arc>& arcs,
                                 const std::vector<uint32_t>& group) {
    const size_t n = order.size();
    std::vector<std::vector<std::pair<uint32_t, int64_t>>> adjacency(n);
    for (const Arc& a : arcs) {
        if (group[a.from] != group[a.to]) continue;
        adjacency[a.from].emplace_back(a.to, int64_t(a.weight));
        adjacency[a.to].emplace_back(a.from, -int64_t(a.weight));
    }
    std::vector<uint32_t> position(n);
    for (size_t i = 0; i < n; ++i) position[order[i]] = uint32_t(i);
    for (size_t pass = 0; pass < 32; ++pass) {
        bool moved = false;
        for (uint32_t u = 0; u < n; ++u) {
            const uint32_t i = position[u];
            uint32_t first = i, last = i;  // u's group block
            while (first > 0 && group[order[first - 1]] == group[u]) --first;
            while (last + 1 < n && group[order[last + 1]] == group[u]) ++last;
            std::vector<std::pair<uint32_t, int64_t>> left, right;
            for (const auto& [v, s] : adjacency[u]) (position[v] < i ? left : right).emplace_back(position[v], s);
            std::sort(left.rbegin(), left.rend());
            std::sort(right.begin(), right.end());
            int64_t best = 0, delta = 0;
            uint32_t target = i;
            for (const auto& [p, s] : left)
                if ((delta -= s) < best && p >= first) best = delta, target = p;
            delta = 0;
            for (const auto& [p, s] : right)
                if ((delta += s) < best && p <= last) best = delta, target = p;
            if (target == i) continue;
            order.erase(order.begin() + i);
            order.insert(order.begin() + target, u);
            for (size_t x = 0; x < n; ++x) position[order[x]] = uint32_t(x);
            moved = true;
        }
        if (!moved) break;
    }
    return order;
}

TEST(Sifting, MovesTheSameUnitsAsThePlainStatementOnLargerGraphs) {
    std::mt19937 rng(15);
    for (int trial = 0; trial < 40; ++trial) {
        const size_t n = 20 + rng() % 180;
        std::vector<Arc> arcs;
        for (uint32_t a = 0; a < n; ++a)
            for (uint32_t b = a + 1; b < n; ++b) {
                if (rng() % 4 != 0) continue;  // sparse, as measured graphs are
                // Odd trials: weights beyond 32 bits (sift_order's 64-bit adjacency).
                const uint64_t w = (1 + rng() % 1000) << (trial % 2 ? 33 : 0);
                arcs.push_back(rng() % 2 ? Arc{a, b, w} : Arc{b, a, w});
            }
        std::vector<uint32_t> group(n, 0);
        const uint32_t groups = 1 + trial % 3;
        for (size_t u = 0; u < n; ++u) group[u] = uint32_t(u * groups / n);  // contiguous blocks
        std::vector<uint32_t> order(n);
        std::iota(order.begin(), order.end(), 0u);
        for (size_t i = 0; i < n;) {  // shuffle inside each block
            size_t j = i;
            while (j < n && group[j] == group[i]) ++j;
            std::shuffle(order.begin() + long(i), order.begin() + long(j), rng);
            i = j;
        }
        const std::vector<uint32_t> expected = plain_sift(order, arcs, group);
        const uint64_t weight = sift_order(order.data(), n, arcs.data(), arcs.size(), group.data());
        ASSERT_EQ(order, expected) << "trial " << trial;
        ASSERT_EQ(weight, cost(order, arcs));
    }
}

TEST(MeasuredOrder, RejectsAPreviousOrderThatIsNoPermutation) {
    const std::vector<Arc> arcs = {{0, 1, 1}};
    const std::vector<uint32_t> bad = {0, 0};
    EXPECT_THROW(measured_unit_order(2, arcs.data(), arcs.size(), nullptr, bad.data()), InvalidInput);
    const std::vector<Arc> outside = {{0, 5, 1}};
    EXPECT_THROW(measured_unit_order(2, outside.data(), outside.size(), nullptr, nullptr), InvalidInput);
}

}  // namespace
