// The held-out check of measured orders (held_out_choice.cpp): on the bundled character's walk,
// a cluster whose order is made bad on purpose (its distance order reversed: far patches first)
// takes the distance order offered as the alternative; a buffer that already is that order is kept (the check asks for
// strictly fewer fragments); after a change every clustering node is drawn by the buffer that
// passes the fewest of its fragments, checked node by node against a second scoring.
#include "animorder/clustering.h"
#include "animorder/held_out_choice.h"
#include "animorder/invalid_input.h"
#include "animorder/mesh_patches.h"
#include "animorder/overdraw.h"
#include "animorder/procedural_character.h"
#include "animorder/viewpoints.h"
#include "support/meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

using namespace animorder;

namespace {

struct Walk {
    AnimatedMesh mesh = make_procedural_character();
    MeshPatches patches;
    std::vector<uint32_t> keyframes;
    Framing framing;
    ClusteringResult run;
    static constexpr unsigned kResolution = 64;

    Walk() {
        patches = build_mesh_patches(mesh, 0.85);
        const Clip& walk = mesh.clips[0];
        for (size_t f = 0; f < walk.keyframe_count; f += 6) keyframes.push_back(uint32_t(walk.first_keyframe + f));
        framing = frame_subset(frame_animated_mesh(mesh), keyframes);
        ClusteringSettings s;
        s.clusters = 3;
        s.views = 42;
        s.resolution = kResolution;
        s.max_iterations = 4;
        s.threads = 2;
        run = cluster_nodes(mesh, patches, framing, keyframes, s);
    }
    // passed[n · k + c]: the fragments buffer c passes at clustering node n.
    std::vector<uint64_t> learnt_passed() const {
        const size_t views = run.directions.size() / 3, k = run.triangle_orders.size();
        std::vector<OverdrawNode> nodes(keyframes.size() * views);
        for (size_t n = 0; n < nodes.size(); ++n) {
            nodes[n].keyframe = keyframes[n / views];
            std::copy(&run.directions[3 * (n % views)], &run.directions[3 * (n % views)] + 3, nodes[n].direction);
        }
        std::vector<const uint32_t*> orders;
        for (const auto& o : run.triangle_orders) orders.push_back(o.data());
        const std::vector<uint32_t> ranks = make_rank_table(orders, mesh.triangle_count());
        const std::vector<uint8_t> modes = opaque_pass_modes(mesh);
        ScoreSettings score;
        score.resolution = kResolution;
        score.threads = 1;
        score.triangle_modes = modes.empty() ? nullptr : modes.data();
        std::vector<uint64_t> visible(nodes.size()), passed(nodes.size() * k);
        score_nodes(visible.data(), passed.data(), mesh.keyframe_positions.data(), mesh.vertex_count, framing,
                    mesh.indices.data(), mesh.indices.size(), nodes.data(), nodes.size(), ranks.data(), k, score);
        return passed;
    }
};

}  // namespace

TEST(HeldOutChoice, ViewsPerKeyframeAimAtSixHundredNodes) {
    EXPECT_EQ(held_out_views_per_keyframe(0), 0u);
    EXPECT_EQ(held_out_views_per_keyframe(1), 162u);   // 600, at most 162
    EXPECT_EQ(held_out_views_per_keyframe(10), 60u);
    EXPECT_EQ(held_out_views_per_keyframe(7), 86u);    // ceil(600 / 7)
    EXPECT_EQ(held_out_views_per_keyframe(60), 12u);
    EXPECT_EQ(held_out_views_per_keyframe(500), 12u);  // at least 12
}

TEST(HeldOutChoice, ABadOrderGivesWayToTheDistanceOrderAndTheNodesFollow) {
    Walk w;
    const size_t k = w.run.triangle_orders.size();
    ASSERT_EQ(k, 3u);
    // The distance orders themselves (the check's own candidates): a first check with the
    // clusters' orders reversed takes every one of them.
    ClusteringResult reversed = w.run;
    for (auto& o : reversed.triangle_orders) std::reverse(o.begin(), o.end());
    const HeldOutChoice first = choose_on_held_out_views(w.mesh, w.framing, Walk::kResolution, 2, reversed,
                                                         distance_cluster_orders(w.mesh, w.patches, w.framing, reversed));
    EXPECT_EQ(first.nodes, w.keyframes.size() * held_out_views_per_keyframe(w.keyframes.size()));
    ASSERT_EQ(first.taken.size(), k);
    EXPECT_LT(first.chosen_passed, first.current_passed);
    EXPECT_GE(first.chosen_passed, first.visible);  // at least one fragment a covered pixel
    // Buffers no node draws any more are dropped: the rest are the distance orders offered.
    const size_t left = reversed.triangle_orders.size();
    ASSERT_EQ(left + first.dropped, k);
    ASSERT_GE(left, 1u);
    for (size_t c = 0; c < left; ++c) {
        ASSERT_EQ(reversed.triangle_orders[c].size(), w.mesh.triangle_count());
        EXPECT_TRUE(test::is_permutation_of_iota(reversed.triangle_orders[c]));
        EXPECT_EQ(first.taken[c], 1);
    }
    // The nodes went to the buffer that passes the fewest of their fragments (ties: their own).
    Walk scored = w;
    scored.run = reversed;
    const std::vector<uint64_t> passed = scored.learnt_passed();
    for (size_t n = 0; n < reversed.assignment.size(); ++n) {
        const uint64_t* p = &passed[n * left];
        ASSERT_LT(reversed.assignment[n], left);
        for (size_t c = 0; c < left; ++c) EXPECT_LE(p[reversed.assignment[n]], p[c]) << "node " << n;
    }
    EXPECT_GT(first.reassigned, 0u);

    // The run's own clusters holding their own distance orders: checked, nothing is strictly
    // better, nothing changes (orders, assignment).
    ClusteringResult again = w.run;
    again.triangle_orders = distance_cluster_orders(w.mesh, w.patches, w.framing, w.run);
    const HeldOutChoice second = choose_on_held_out_views(w.mesh, w.framing, Walk::kResolution, 1, again,
                                                          distance_cluster_orders(w.mesh, w.patches, w.framing, again));
    for (size_t c = 0; c < k; ++c) EXPECT_EQ(second.taken[c], 0) << "cluster " << c;
    EXPECT_EQ(second.current_passed, second.chosen_passed);
    EXPECT_EQ(second.reassigned, 0u);
    EXPECT_EQ(second.dropped, 0u);
    EXPECT_EQ(again.triangle_orders, distance_cluster_orders(w.mesh, w.patches, w.framing, w.run));
    EXPECT_EQ(again.assignment, w.run.assignment);
}

TEST(HeldOutChoice, SameWhateverTheThreadCount) {
    Walk w;
    ClusteringResult a = w.run, b = w.run;
    std::reverse(a.triangle_orders[1].begin(), a.triangle_orders[1].end());
    b.triangle_orders[1] = a.triangle_orders[1];
    const HeldOutChoice one = choose_on_held_out_views(w.mesh, w.framing, Walk::kResolution, 1, a,
                                                       distance_cluster_orders(w.mesh, w.patches, w.framing, a));
    const HeldOutChoice two = choose_on_held_out_views(w.mesh, w.framing, Walk::kResolution, 2, b,
                                                       distance_cluster_orders(w.mesh, w.patches, w.framing, b));
    EXPECT_EQ(one.taken, two.taken);
    EXPECT_EQ(one.chosen_passed, two.chosen_passed);
    EXPECT_EQ(a.triangle_orders, b.triangle_orders);
    EXPECT_EQ(a.assignment, b.assignment);
    EXPECT_EQ(one.taken[1], 1);
    // The measured orders of the clusters (here over the λ patches themselves, every second node):
    // the same with one worker or two, each a permutation that keeps every patch whole.
    const auto m1 = measured_cluster_orders(w.mesh, w.patches, w.framing, w.run, Walk::kResolution, 1, 2);
    const auto m2 = measured_cluster_orders(w.mesh, w.patches, w.framing, w.run, Walk::kResolution, 2, 2);
    EXPECT_EQ(m1, m2);
    for (const auto& order : m1) {
        ASSERT_TRUE(test::is_permutation_of_iota(order));
        EXPECT_TRUE(test::keeps_units_whole(order, w.patches.patch_starts, w.patches.cache_order));
    }
    // A stride of none is refused.
    EXPECT_THROW(measured_cluster_orders(w.mesh, w.patches, w.framing, w.run, Walk::kResolution, 1, 0), InvalidInput);
}

// A buffer that no clustering node draws after the reassignment is dropped, the others renumbered
// (a lookup table never names it). Cluster 2's nodes handed to cluster 1 and its buffer made
// cluster 1's (a node moves only to a strictly better buffer, and the lower of two equal ones);
// cluster 0's order reversed (far patches first), giving way to its distance order: the nodes are
// reassigned, and cluster 2, drawn by none, goes.
TEST(HeldOutChoice, ABufferNoNodeDrawsAnyMoreIsDropped) {
    Walk w;
    ClusteringResult run = w.run;
    for (uint32_t& c : run.assignment)
        if (c == 2) c = 1;
    run.triangle_orders[2] = run.triangle_orders[1];
    std::reverse(run.triangle_orders[0].begin(), run.triangle_orders[0].end());
    std::vector<std::vector<uint32_t>> alternatives = distance_cluster_orders(w.mesh, w.patches, w.framing, run);
    ASSERT_TRUE(alternatives[2].empty());  // no node: nothing to offer
    alternatives[1].clear();
    const std::vector<uint32_t> distance = alternatives[0], second = run.triangle_orders[1];
    const HeldOutChoice choice = choose_on_held_out_views(w.mesh, w.framing, Walk::kResolution, 2, run, alternatives);
    ASSERT_EQ(choice.dropped, 1u);
    ASSERT_EQ(run.triangle_orders.size(), 2u);
    ASSERT_EQ(choice.taken, (std::vector<uint8_t>{1, 0}));
    ASSERT_EQ(run.patch_orders.size(), 2u);
    EXPECT_EQ(run.patch_orders[1], w.run.patch_orders[1]);
    EXPECT_EQ(run.triangle_orders[0], distance);
    EXPECT_EQ(run.triangle_orders[1], second);
    std::vector<size_t> drawn(2, 0);
    for (const uint32_t c : run.assignment) {
        ASSERT_LT(c, 2u);
        ++drawn[c];
    }
    EXPECT_GT(drawn[0], 0u);
    EXPECT_GT(drawn[1], 0u);
}
