// Kept fragments (kept_fragments.cpp, NodeCache in overdraw.cpp): the compact form gives exactly
// the per-triangle lists' counts for unit orders — hand-worked pixels, every unit order of small
// random scenes against the per-triangle replay, real nodes of the bundled character — and the
// memory budget changes time only: k-means returns the same buffers with everything, part or
// nothing kept (bundled character, and a clip set of Ganfaul when ../shared/data is there).
#include "animorder/clustering.h"
#include "animorder/invalid_input.h"
#include "animorder/kept_fragments.h"
#include "animorder/load.h"
#include "animorder/measured_order.h"
#include "animorder/mesh_patches.h"
#include "animorder/overdraw.h"
#include "animorder/procedural_character.h"
#include "animorder/rasterizer.h"
#include "animorder/viewpoints.h"
#include "support/require.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

using namespace animorder;

namespace {

constexpr uint32_t kTie = 0x80000000u;

struct Lists {
    std::vector<uint32_t> starts{0}, fragments;
    void pixel(const std::vector<uint32_t>& triangles) {
        fragments.insert(fragments.end(), triangles.begin(), triangles.end());
        starts.push_back(uint32_t(fragments.size()));
    }
    size_t pixels() const { return starts.size() - 1; }
    NodeFragments node(uint64_t single) const {
        NodeFragments n;
        n.single = single;
        n.visible = single + pixels();
        n.starts = starts;
        n.fragments = fragments;
        return n;
    }
};

// Units as contiguous runs of triangle ids: units {0,1}, {2}, {3,4,5} for sizes {2,1,3}; each
// unit's inner order is its ids ascending.
UnitPartition runs(const std::vector<uint32_t>& sizes) {
    std::vector<uint32_t> starts{0};
    for (uint32_t s : sizes) starts.push_back(starts.back() + s);
    std::vector<uint32_t> inner(starts.back());
    std::iota(inner.begin(), inner.end(), 0u);
    return make_unit_partition(starts.data(), sizes.size(), inner.data(), inner.size());
}

// The face order of a unit order: each unit's triangles in its inner order.
std::vector<uint32_t> face_order(const UnitPartition& p, const std::vector<uint32_t>& unit_order) {
    std::vector<uint32_t> faces;
    for (uint32_t u : unit_order) {
        std::vector<uint32_t> mine;
        for (uint32_t t = 0; t < p.unit_of_triangle.size(); ++t)
            if (p.unit_of_triangle[t] == u) mine.push_back(t);
        std::sort(mine.begin(), mine.end(),
                  [&](uint32_t a, uint32_t b) { return p.unit_position[a].second < p.unit_position[b].second; });
        faces.insert(faces.end(), mine.begin(), mine.end());
    }
    return faces;
}

// Both forms scored with the same orders must agree, the kept form in the copy the CPU runs (AVX2
// for 2 to 8 orders where it has it) and in the portable one; returns the kept form's counts.
std::vector<uint64_t> expect_same_counts(const NodeFragments& full, const KeptNode& kept, const UnitPartition& p,
                                         const std::vector<std::vector<uint32_t>>& unit_orders) {
    std::vector<std::vector<uint32_t>> faces;
    std::vector<const uint32_t*> pointers;
    for (const auto& o : unit_orders) faces.push_back(face_order(p, o));
    for (const auto& f : faces) pointers.push_back(f.data());
    const std::vector<uint32_t> ranks = make_rank_table(pointers, p.unit_of_triangle.size());
    const std::vector<uint16_t> unit_ranks = make_unit_rank_table(ranks.data(), faces.size(), p);
    std::vector<uint64_t> expected(faces.size()), got(faces.size());
    score_fragments(expected.data(), full, ranks.data(), faces.size());
    score_kept(got.data(), kept, unit_ranks.data(), ranks.data(), faces.size());
    EXPECT_EQ(got, expected);
    std::vector<uint64_t> portable(faces.size());
    score_kept_portable(portable.data(), kept, unit_ranks.data(), ranks.data(), faces.size());
    EXPECT_EQ(portable, expected);
    EXPECT_EQ(kept.visible, full.visible);
    return got;
}

KeptNode keep(const NodeFragments& n, const UnitPartition& p) {
    KeepScratch scratch;
    return keep_fragments(n.visible, n.single, n.starts.data(), n.starts.size() - 1, n.fragments.data(), p, scratch);
}

}  // namespace

TEST(KeptFragments, HandWorkedPixelsAreReducedAndShared) {
    const UnitPartition p = runs({2, 1, 3});  // units 0 {0,1}, 1 {2}, 2 {3,4,5}
    Lists l;
    l.pixel({1, 0});            // unit 0 twice, the nearer (1) drawn after 0: 0 is the unit's second entry
    l.pixel({0, 1});            // 1 behind 0, which unit 0 draws first: dropped, one fragment left
    l.pixel({2, 3});            // units 1, 2
    l.pixel({2, 4});            // units 1, 2 again: the same unit list, weight 2
    l.pixel({3, 2, 5});         // units 2, 1; 5 behind 3 of its unit (3 drawn first): dropped
    l.pixel({2, 0, 1});         // units 1, 0; 1 behind 0: dropped
    l.pixel({3, 4 | kTie, 2});  // 4 at 3's depth, drawn after 3: dropped; the tie goes with it
    l.pixel({5, 4, 3});         // unit 2 three times, each farther one drawn first: a list kept per triangle
    const KeptNode k = keep(l.node(5), p);
    EXPECT_EQ(k.single, 5u + 1u);  // the five lone pixels and the {0, 1} pixel
    EXPECT_EQ(k.triangle_lists, 1u);
    EXPECT_EQ(k.triangle_entries, 3u);
    // Unit lists (all of length 2) in order of first appearance: {0,0} (pixel 1), {1,2} (pixels
    // 3, 4), {2,1} (pixels 5, 7), {1,0}; then the triangle list, as units.
    EXPECT_EQ(k.unit_lists, 4u);
    std::vector<std::vector<uint32_t>> lists;
    std::vector<uint32_t> weights, scratch;
    for_each_unit_list(k, p.unit_of_triangle.data(), p.unit_of_triangle.size(), scratch,
                       [&](const uint32_t* u, uint32_t n, uint32_t w) {
                           lists.emplace_back(u, u + n);
                           weights.push_back(w);
                       });
    const std::vector<std::vector<uint32_t>> want_lists = {{0, 0}, {1, 2}, {2, 1}, {1, 0}, {2, 2, 2}};
    EXPECT_EQ(lists, want_lists);
    EXPECT_EQ(weights, (std::vector<uint32_t>{1, 2, 2, 1, 1}));
    // Every unit order scores as the per-triangle lists do.
    std::vector<uint32_t> order = {0, 1, 2};
    std::vector<std::vector<uint32_t>> all;
    do all.push_back(order);
    while (std::next_permutation(order.begin(), order.end()));
    expect_same_counts(l.node(5), k, p, all);
}

// A unit met three times of which the middle fragment is dropped (behind the nearest, drawn after
// it) is met twice in what is kept: a unit list with a flagged second entry, not a list kept per
// triangle; so is a unit met twice behind another one. Lists of two to four fragments take a path
// of their own (checked: counting the dropped fragment as a repeat of the unit fails this test).
TEST(KeptFragments, AUnitLeftTwiceAfterADropStaysAUnitList) {
    const UnitPartition p = runs({2, 1, 3});  // units 0 {0,1}, 1 {2}, 2 {3,4,5}
    Lists l;
    l.pixel({4, 5, 3});     // 5 behind 4 (drawn after it): dropped; 3 drawn before 4: unit 2 twice
    l.pixel({2, 4, 3});     // unit 1, then unit 2 twice (3 drawn first)
    l.pixel({4, 5, 3, 2});  // the same as the first pixel, with unit 1 behind: the general path
    const KeptNode k = keep(l.node(0), p);
    EXPECT_EQ(k.triangle_lists, 0u);
    std::vector<std::vector<uint32_t>> lists;
    std::vector<uint32_t> scratch;
    for_each_unit_list(k, p.unit_of_triangle.data(), p.unit_of_triangle.size(), scratch,
                       [&](const uint32_t* u, uint32_t n, uint32_t) { lists.emplace_back(u, u + n); });
    EXPECT_EQ(lists, (std::vector<std::vector<uint32_t>>{{2, 2}, {1, 2, 2}, {2, 2, 1}}));
    std::vector<uint32_t> order = {0, 1, 2};
    std::vector<std::vector<uint32_t>> all;
    do all.push_back(order);
    while (std::next_permutation(order.begin(), order.end()));
    expect_same_counts(l.node(0), k, p, all);
}

TEST(KeptFragments, TiesStayGroupsWhenAFragmentBetweenIsDropped) {
    const UnitPartition p = runs({2, 1});  // unit 0 {0,1}, unit 1 {2}
    Lists l;
    // 0 nearest; 1 at 0's depth (same unit, drawn after: dropped); 2 at the same depth again.
    l.pixel({0, 1 | kTie, 2 | kTie});
    // 0 nearest; 1 farther (dropped); 2 at 1's depth, farther than 0: no tie with 0.
    l.pixel({0, 1, 2 | kTie});
    const KeptNode k = keep(l.node(0), p);
    std::vector<std::vector<uint32_t>> lists;
    std::vector<uint32_t> scratch;
    for_each_unit_list(k, p.unit_of_triangle.data(), p.unit_of_triangle.size(), scratch,
                       [&](const uint32_t* u, uint32_t n, uint32_t) { lists.emplace_back(u, u + n); });
    EXPECT_EQ(lists, (std::vector<std::vector<uint32_t>>{{0, 1 | kTie}, {0, 1}}));
    // Drawn 1 then 0: the tied pixel passes one fragment (the first of the group), the other two.
    expect_same_counts(l.node(0), k, p, {{0, 1}, {1, 0}});
    uint64_t passed[1];
    const std::vector<uint32_t> faces = face_order(p, {1, 0});
    const std::vector<uint32_t> ranks = make_rank_table({faces.data()}, 3);
    score_kept(passed, k, make_unit_rank_table(ranks.data(), 1, p).data(), ranks.data(), 1);
    EXPECT_EQ(passed[0], 1u + 2u);
}

TEST(KeptFragments, RandomListsScoreAsThePerTriangleListsForEveryUnitOrder) {
    std::mt19937 rng(3);
    auto pick = [&rng](uint32_t n) { return uint32_t(rng() % n); };
    for (int scene = 0; scene < 40; ++scene) {
        const std::vector<uint32_t> sizes = {1 + pick(3), 1 + pick(3), 1 + pick(3), 1 + pick(3)};
        // Inner orders shuffled, so positions are not the ids.
        std::vector<uint32_t> starts{0};
        for (uint32_t s : sizes) starts.push_back(starts.back() + s);
        std::vector<uint32_t> inner(starts.back());
        std::iota(inner.begin(), inner.end(), 0u);
        std::shuffle(inner.begin(), inner.end(), rng);
        const UnitPartition p = make_unit_partition(starts.data(), sizes.size(), inner.data(), inner.size());
        Lists l;
        for (int px = 0; px < 60; ++px) {
            std::vector<uint32_t> t(inner.size());
            std::iota(t.begin(), t.end(), 0u);
            std::shuffle(t.begin(), t.end(), rng);
            t.resize(2 + rng() % std::min<size_t>(5, t.size() - 1));
            for (size_t j = 1; j < t.size(); ++j)
                if (rng() % 4 == 0) t[j] |= kTie;
            l.pixel(t);
        }
        std::vector<uint32_t> order = {0, 1, 2, 3};
        std::vector<std::vector<uint32_t>> all;
        do all.push_back(order);
        while (std::next_permutation(order.begin(), order.end()));
        const NodeFragments full = l.node(7);
        const KeptNode k = keep(full, p);
        for (size_t i = 0; i < all.size(); i += 8)
            expect_same_counts(full, k, p, std::vector<std::vector<uint32_t>>(all.begin() + i, all.begin() + i + 8));
        expect_same_counts(full, k, p, {all[3], all[17], all[22]});  // an odd count: the generic path
        // The measured graph reads the same pairs from both forms.
        std::vector<uint32_t> unit(p.unit_of_triangle);
        MeasuredPairCounts a(sizes.size(), unit.data(), unit.size(), nullptr),
            b(sizes.size(), unit.data(), unit.size(), nullptr);
        const NodeFragments* fp = &full;
        const KeptNode* kp = &k;
        a.add(&fp, 1, +1, 1);
        b.add(&kp, 1, +1, 1);
        const std::vector<Arc> arcs_a = a.arcs(), arcs_b = b.arcs();
        ASSERT_EQ(arcs_a.size(), arcs_b.size());
        for (size_t i = 0; i < arcs_a.size(); ++i) {
            EXPECT_EQ(arcs_a[i].from, arcs_b[i].from);
            EXPECT_EQ(arcs_a[i].to, arcs_b[i].to);
            EXPECT_EQ(arcs_a[i].weight, arcs_b[i].weight);
        }
    }
}

// Lists of every length from 2 to 14 units (scoring has a branch-free path per length up to 5
// and one for any length beyond), with and without ties, many pixels sharing a list, scored
// with 1 to 9 random unit orders: the same counts as the per-triangle replay. keep_fragments
// stores the unit lists shortest first.
TEST(KeptFragments, ListsOfEveryLengthScoreAsThePerTriangleListsForAnyOrderCount) {
    std::mt19937 rng(11);
    std::vector<uint32_t> sizes(16);
    for (uint32_t& size : sizes) size = 1 + rng() % 2;
    std::vector<uint32_t> starts{0};
    for (uint32_t size : sizes) starts.push_back(starts.back() + size);
    std::vector<uint32_t> inner(starts.back());
    std::iota(inner.begin(), inner.end(), 0u);
    std::shuffle(inner.begin(), inner.end(), rng);
    const UnitPartition p = make_unit_partition(starts.data(), sizes.size(), inner.data(), inner.size());
    Lists l;
    std::vector<std::vector<uint32_t>> drawn;
    for (int px = 0; px < 600; ++px) {
        if (!drawn.empty() && rng() % 3 == 0) {  // a pixel like an earlier one: a shared list
            l.pixel(drawn[rng() % drawn.size()]);
            continue;
        }
        std::vector<uint32_t> t(inner.size());
        std::iota(t.begin(), t.end(), 0u);
        std::shuffle(t.begin(), t.end(), rng);
        t.resize(2 + rng() % 13);
        if (px % 2)  // every other pixel: one triangle per unit, so nothing is dropped
            for (uint32_t& triangle : t) triangle = starts[triangle % sizes.size()];
        std::sort(t.begin(), t.end());
        t.erase(std::unique(t.begin(), t.end()), t.end());
        if (t.size() < 2) continue;
        std::shuffle(t.begin(), t.end(), rng);
        for (size_t j = 1; j < t.size(); ++j)
            if (rng() % 6 == 0) t[j] |= kTie;
        drawn.push_back(t);
        l.pixel(t);
    }
    const NodeFragments full = l.node(3);
    const KeptNode k = keep(full, p);
    std::vector<uint32_t> lengths, scratch;
    for_each_unit_list(k, p.unit_of_triangle.data(), p.unit_of_triangle.size(), scratch,
                       [&](const uint32_t*, uint32_t n, uint32_t) { lengths.push_back(n); });
    ASSERT_GE(lengths.size(), size_t(k.unit_lists));
    lengths.resize(k.unit_lists);  // the unit lists (the triangle lists follow)
    EXPECT_TRUE(std::is_sorted(lengths.begin(), lengths.end()));
    for (uint32_t n = 2; n <= 10; ++n)  // the data has the lengths the test is about
        EXPECT_NE(std::find(lengths.begin(), lengths.end(), n), lengths.end()) << "no list of " << n << " units";
    std::vector<uint32_t> order(sizes.size());
    std::iota(order.begin(), order.end(), 0u);
    for (size_t count = 1; count <= 9; ++count) {
        std::vector<std::vector<uint32_t>> orders;
        for (size_t o = 0; o < count; ++o) {
            std::shuffle(order.begin(), order.end(), rng);
            orders.push_back(order);
        }
        SCOPED_TRACE(std::to_string(count) + " orders");
        expect_same_counts(full, k, p, orders);
    }
}

// Weights of 2^15 and more (scoring multiplies 16-bit pass counts by 16-bit weights; a signed
// high half would make them negative) and past 65535 (a second copy of the list): 70,000 pixels
// see units 0, 1, 2 nearest first and 40,000 see units 2, 1, 0. Drawn 0, 1, 2 the first pass once
// and the second three times: 70,000 + 120,000; drawn 2, 1, 0 the other way round, 210,000 +
// 40,000; drawn 1, 0, 2, 2 · 70,000 + 2 · 40,000. Scored with 1 to 8 orders at once (one order in
// scalar code, 2 to 4 in the low half of the vector lanes, 5 to 8 in both).
TEST(KeptFragments, HeavyWeightsScoreExactly) {
    const UnitPartition p = runs({1, 1, 1});
    Lists l;
    for (int i = 0; i < 70000; ++i) l.pixel({0, 1, 2});
    for (int i = 0; i < 40000; ++i) l.pixel({2, 1, 0});
    const NodeFragments full = l.node(0);
    const KeptNode k = keep(full, p);
    EXPECT_EQ(k.unit_lists, 3u);  // 65,535 + 4,465 copies of the first list, one of the second
    const std::vector<std::vector<uint32_t>> base = {{0, 1, 2}, {2, 1, 0}, {1, 0, 2}};
    const uint64_t expected[3] = {190000, 250000, 220000};
    for (size_t count = 1; count <= 8; ++count) {
        std::vector<std::vector<uint32_t>> orders;
        for (size_t o = 0; o < count; ++o) orders.push_back(base[o % 3]);
        SCOPED_TRACE(std::to_string(count) + " orders");
        const std::vector<uint64_t> got = expect_same_counts(full, k, p, orders);
        for (size_t o = 0; o < count; ++o) EXPECT_EQ(got[o], expected[o % 3]) << "order " << o;
    }
}

// A list naming a triangle the partition does not have is refused, whichever of its entries it is
// and whatever its length (lists of two to four take a path of their own).
TEST(KeptFragments, ATriangleBeyondThePartitionIsRefused) {
    const UnitPartition p = runs({2, 1});  // triangles 0, 1, 2
    const std::vector<std::vector<uint32_t>> bad = {{0, 3}, {3, 0}, {1, 2 | kTie, 7}, {9, 0, 1}, {0, 1, 2, 3}};
    for (const auto& pixel : bad) {
        Lists l;
        l.pixel({0, 1});
        l.pixel(pixel);
        try {
            keep(l.node(0), p);
            ADD_FAILURE() << "accepted a list of " << pixel.size();
        } catch (const InvalidInput& e) {
            EXPECT_NE(std::string(e.what()).find("but the partition has 3"), std::string::npos) << e.what();
        }
    }
}

TEST(KeptFragments, AnOrderThatSplitsAUnitIsRefused) {
    const UnitPartition p = runs({2, 1});
    const std::vector<uint32_t> faces = {0, 2, 1};  // unit 0 split by unit 1
    const std::vector<uint32_t> ranks = make_rank_table({faces.data()}, 3);
    EXPECT_THROW(make_unit_rank_table(ranks.data(), 1, p), InvalidInput);
    const std::vector<uint32_t> starts = {0, 2, 3}, twice = {0, 0, 1};
    EXPECT_THROW(make_unit_partition(starts.data(), 2, twice.data(), 3), InvalidInput);
}

namespace {

// Every node of a clip subset scored by NodeCache under three budgets and by the engine without
// any cache (score_nodes): the same counts; the kept form is several times smaller.
void check_cache_budgets(const AnimatedMesh& mesh, const std::vector<uint32_t>& keyframes, size_t views,
                         unsigned resolution) {
    const Framing framing = frame_animated_mesh(mesh);
    const MeshPatches patches = build_mesh_patches(mesh, 0.85);
    const std::vector<float> dirs = icosphere_directions(icosphere_subdivisions_for(views));
    std::vector<OverdrawNode> nodes;
    for (uint32_t k : keyframes)
        for (size_t v = 0; v < dirs.size() / 3; ++v) {
            OverdrawNode n;
            n.keyframe = k;
            std::copy(&dirs[3 * v], &dirs[3 * v] + 3, n.direction);
            nodes.push_back(n);
        }
    std::mt19937 rng(5);
    std::vector<std::vector<uint32_t>> faces;
    for (int o = 0; o < 5; ++o) {
        std::vector<uint32_t> patch_order(patches.patch_count());
        std::iota(patch_order.begin(), patch_order.end(), 0u);
        std::shuffle(patch_order.begin(), patch_order.end(), rng);
        faces.push_back(patch_order_to_triangle_order(patches, patch_order));
    }
    std::vector<const uint32_t*> pointers;
    for (const auto& f : faces) pointers.push_back(f.data());
    const std::vector<uint32_t> ranks = make_rank_table(pointers, mesh.triangle_count());
    ScoreSettings settings;
    settings.resolution = resolution;
    const std::vector<uint8_t> modes = opaque_pass_modes(mesh);
    settings.triangle_modes = modes.empty() ? nullptr : modes.data();
    std::vector<uint64_t> visible(nodes.size()), passed(nodes.size() * 5);
    score_nodes(visible.data(), passed.data(), mesh.keyframe_positions.data(), mesh.vertex_count, framing,
                mesh.indices.data(), mesh.indices.size(), nodes.data(), nodes.size(), ranks.data(), 5, settings);
    const UnitPartition partition = make_unit_partition(patches.patch_starts.data(), patches.patch_count(),
                                                        patches.cache_order.data(), mesh.triangle_count());
    size_t all_bytes = 0;
    for (size_t budget : {SIZE_MAX, size_t(0), size_t(1)}) {
        if (budget == 1) budget = all_bytes / 2;
        const NodeCache cache(mesh.keyframe_positions.data(), mesh.vertex_count, framing, mesh.indices.data(),
                              mesh.indices.size(), nodes.data(), nodes.size(), partition, settings, budget);
        if (budget == SIZE_MAX) {
            EXPECT_EQ(cache.kept_count(), nodes.size());
            all_bytes = cache.kept_bytes();
        } else {
            EXPECT_LT(cache.kept_count(), nodes.size()) << budget;
            EXPECT_LE(cache.kept_bytes(), budget);
            // Nodes are rasterised to be kept only while the budget lasts: none for a budget of
            // nothing; for half, the kept ones and the chunk that found the end, whose estimate
            // comes from the nodes before it (here within half the budget again).
            EXPECT_EQ(cache.sampled_nodes() == 0, budget == 0);
            EXPECT_LT(cache.sampled_nodes(), nodes.size());
            EXPECT_LE(cache.sampled_bytes(), budget + budget / 2);
        }
        std::vector<uint64_t> v(nodes.size()), p(nodes.size() * 5);
        cache.score(v.data(), p.data(), ranks.data(), 5);
        EXPECT_EQ(v, visible) << "budget " << budget;
        EXPECT_EQ(p, passed) << "budget " << budget;
    }
    // The per-triangle form of the same nodes, for the size comparison.
    const std::vector<NodeFragments> full =
        rasterize_nodes(mesh.keyframe_positions.data(), mesh.vertex_count, framing, mesh.indices.data(),
                        mesh.indices.size(), nodes.data(), nodes.size(), settings, SIZE_MAX);
    size_t full_bytes = 0;
    for (const NodeFragments& n : full) full_bytes += n.bytes();
    EXPECT_LT(3 * all_bytes, full_bytes) << "kept " << all_bytes << " bytes, per triangle " << full_bytes;
}

// cluster_nodes with everything, half and nothing kept: the same buffers and assignment.
void check_clustering_budgets(const AnimatedMesh& mesh, const std::vector<uint32_t>& keyframes, OrderSource source) {
    const Framing framing = frame_animated_mesh(mesh);
    const MeshPatches patches = build_mesh_patches(mesh, 0.85);
    ClusteringSettings s;
    s.clusters = 3;
    s.views = 42;
    s.resolution = 64;
    s.max_iterations = 6;
    s.order = source;
    const ClusteringResult all = cluster_nodes(mesh, patches, framing, keyframes, s);
    EXPECT_EQ(all.kept_nodes, all.assignment.size());
    for (size_t budget : {all.kept_bytes / 2, size_t(0)}) {
        s.max_cache_bytes = budget;
        const ClusteringResult r = cluster_nodes(mesh, patches, framing, keyframes, s);
        EXPECT_LT(r.kept_nodes, all.kept_nodes);
        EXPECT_EQ(r.patch_orders, all.patch_orders) << "budget " << budget;
        EXPECT_EQ(r.assignment, all.assignment) << "budget " << budget;
        EXPECT_EQ(r.iterations.size(), all.iterations.size());
    }
}

std::vector<uint32_t> every(size_t step, size_t first, size_t count) {
    std::vector<uint32_t> k;
    for (size_t f = 0; f < count; f += step) k.push_back(uint32_t(first + f));
    return k;
}

}  // namespace

TEST(NodeCache, BundledCharacterScoresTheSameWhateverTheBudget) {
    const AnimatedMesh mesh = make_procedural_character();
    check_cache_budgets(mesh, every(4, 0, mesh.keyframe_count()), 42, 128);
}

TEST(NodeCache, BundledCharacterClustersTheSameWhateverTheBudget) {
    const AnimatedMesh mesh = make_procedural_character();
    check_clustering_budgets(mesh, every(3, 0, mesh.keyframe_count()), OrderSource::Distance);
    check_clustering_budgets(mesh, every(3, 0, mesh.keyframe_count()), OrderSource::Measured);
}

TEST(NodeCache, GanfaulClipSetClustersTheSameWhateverTheBudget) {
    const std::filesystem::path path = test::shared_data_path("mixamo-ganfaul/Ganfaul.gltf");
    ANIMORDER_REQUIRE_DATA(path);
    AnimatedMesh mesh = load_character(path.string());
    mesh = select_clips(mesh, {mesh.clips[0].name, mesh.clips[1].name});
    const std::vector<uint32_t> keyframes = every(6, 0, mesh.keyframe_count());
    check_cache_budgets(mesh, keyframes, 12, 256);
    check_clustering_budgets(mesh, keyframes, OrderSource::Distance);
    check_clustering_budgets(mesh, keyframes, OrderSource::Measured);
}
