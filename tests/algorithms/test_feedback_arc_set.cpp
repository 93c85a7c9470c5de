// The greedy feedback-arc-set order (Eades, Lin & Smyth 1993, with Nehab et al. 2006's weighted
// rule) on hand-worked graphs and random DAGs, and the arcs an order violates.
#include "animorder/feedback_arc_set.h"
#include "animorder/invalid_input.h"
#include "support/feedback_arcs.h"
#include "support/meshes.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

using namespace animorder;
using test::fas;
using test::feedback;

// ---------------------------------------------------------------------------------------------
// Feedback arc set

TEST(FeedbackArcSet, HandWorkedDagComesOutInTopologicalOrder) {
    // Sinks first: 4; then 1 and 0 become sinks, then 3, then 2. Tail 4,1,0,3,2 reversed.
    const std::vector<Arc> arcs = {{3, 1, 7}, {1, 4, 2}, {3, 0, 1}, {0, 4, 9}, {2, 3, 4}};
    const std::vector<uint32_t> order = fas(5, arcs);
    EXPECT_EQ(order, (std::vector<uint32_t>{2, 3, 0, 1, 4}));
    EXPECT_EQ(feedback(order, arcs).count, 0u);
}

TEST(FeedbackArcSet, RandomDagsHaveNoFeedbackArc) {
    std::mt19937 rng(7);
    for (int trial = 0; trial < 50; ++trial) {
        const size_t n = 1 + rng() % 40;
        std::vector<uint32_t> hidden(n);
        for (size_t i = 0; i < n; ++i) hidden[i] = uint32_t(i);
        for (size_t i = n; i > 1; --i) std::swap(hidden[i - 1], hidden[rng() % i]);
        std::vector<Arc> arcs;
        for (size_t i = 0; i < n; ++i)
            for (size_t j = i + 1; j < n; ++j)
                if (rng() % 4 == 0) arcs.push_back({hidden[i], hidden[j], 1 + rng() % 1000});
        const std::vector<uint32_t> order = fas(n, arcs);
        ASSERT_TRUE(test::is_permutation_of_iota(order));
        EXPECT_EQ(feedback(order, arcs).count, 0u) << "trial " << trial;
    }
}

TEST(FeedbackArcSet, WeightedThreeCycleDropsTheLightestArc) {
    // δ = out − in: node 0: 5 − 1 = 4, node 1: 3 − 5 = −2, node 2: 1 − 3 = −2. Node 0 goes first;
    // then 2 is a sink, 1 a source: 0, 1, 2, violating only 2→0 (weight 1).
    std::vector<Arc> arcs = {{0, 1, 5}, {1, 2, 3}, {2, 0, 1}};
    std::vector<uint32_t> order = fas(3, arcs);
    EXPECT_EQ(order, (std::vector<uint32_t>{0, 1, 2}));
    EXPECT_EQ(feedback(order, arcs).count, 1u);
    EXPECT_EQ(feedback(order, arcs).weight, 1u);
    // The same cycle with the lightest arc elsewhere: 0→1 is dropped, order 1, 2, 0.
    arcs = {{0, 1, 1}, {1, 2, 5}, {2, 0, 3}};
    order = fas(3, arcs);
    EXPECT_EQ(order, (std::vector<uint32_t>{1, 2, 0}));
    EXPECT_EQ(feedback(order, arcs).weight, 1u);
}

TEST(FeedbackArcSet, LosingNodeGoesToTheTail) {
    // A 2-cycle: δ(0) = 1 − 5 = −4, δ(1) = +4. Tie on |δ| → node 0, which loses: tail. Then 1 is a
    // sink too. Order 1, 0: the violated arc is 0→1, the lighter one.
    const std::vector<Arc> arcs = {{0, 1, 1}, {1, 0, 5}};
    const std::vector<uint32_t> order = fas(2, arcs);
    EXPECT_EQ(order, (std::vector<uint32_t>{1, 0}));
    EXPECT_EQ(feedback(order, arcs).weight, 1u);
}

TEST(FeedbackArcSet, ParallelArcsAddUpAndEmptyGraphs) {
    // 0→1 twice (2 + 2) outweighs 1→0 (3): 0 first.
    EXPECT_EQ(fas(2, {{0, 1, 2}, {1, 0, 3}, {0, 1, 2}}), (std::vector<uint32_t>{0, 1}));
    EXPECT_TRUE(fas(0, {}).empty());
    EXPECT_EQ(fas(3, {}).size(), 3u);
}

TEST(FeedbackArcSet, BadInputThrows) {
    EXPECT_THROW(fas(2, {{0, 2, 1}}), InvalidInput);
    EXPECT_THROW(fas(2, {{1, 1, 1}}), InvalidInput);
    EXPECT_THROW(fas(2, {{0, 1, 0}}), InvalidInput);
    const std::vector<uint32_t> not_permutation = {0, 0};
    const std::vector<Arc> arcs = {{0, 1, 1}};
    EXPECT_THROW(count_feedback_arcs(not_permutation.data(), 2, arcs.data(), arcs.size()), InvalidInput);
}
