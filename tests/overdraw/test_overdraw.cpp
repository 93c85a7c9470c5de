// Scoring many nodes: deterministic whatever the thread count, and equal to node-by-node scoring.
#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/overdraw.h"
#include "animorder/procedural_character.h"
#include "animorder/procedural_shapes.h"
#include "animorder/viewpoints.h"

#include <gtest/gtest.h>

#include <vector>

using namespace animorder;

namespace {
struct ScoreRun {
    std::vector<uint64_t> visible, passed;
};

ScoreRun score_all(const AnimatedMesh& mesh, const std::vector<uint32_t>& ranks, size_t orders, unsigned threads) {
    const Framing framing = frame_animated_mesh(mesh);
    const std::vector<float> dirs = icosphere_directions(1);
    std::vector<OverdrawNode> nodes;
    for (uint32_t k = 0; k < mesh.keyframe_count(); k += 7)
        for (size_t v = 0; v < 42; v += 3) {
            OverdrawNode n;
            n.keyframe = k;
            std::copy(&dirs[3 * v], &dirs[3 * v] + 3, n.direction);
            nodes.push_back(n);
        }
    ScoreRun run;
    run.visible.resize(nodes.size());
    run.passed.resize(nodes.size() * orders);
    ScoreSettings settings;
    settings.resolution = 96;
    settings.threads = threads;
    size_t last_progress = 0;
    settings.progress = [&](size_t done, size_t total) {
        EXPECT_EQ(total, nodes.size());
        EXPECT_GT(done, last_progress);
        last_progress = done;
    };
    score_nodes(run.visible.data(), run.passed.data(), mesh.keyframe_positions.data(), mesh.vertex_count, framing,
                mesh.indices.data(), mesh.indices.size(), nodes.data(), nodes.size(), ranks.data(), orders, settings);
    EXPECT_EQ(last_progress, nodes.size());
    return run;
}
}  // namespace

TEST(ScoreNodes, IdenticalWithOneOrTwoThreads) {
    const AnimatedMesh mesh = make_procedural_character();
    const size_t n = mesh.triangle_count();
    std::vector<uint32_t> forward(n), backward(n);
    for (size_t i = 0; i < n; ++i) forward[i] = uint32_t(i), backward[i] = uint32_t(n - 1 - i);
    const std::vector<uint32_t> ranks = make_rank_table({forward.data(), backward.data()}, n);
    const ScoreRun one = score_all(mesh, ranks, 2, 1);
    const ScoreRun two = score_all(mesh, ranks, 2, 2);
    EXPECT_EQ(one.visible, two.visible);
    EXPECT_EQ(one.passed, two.passed);
    for (size_t i = 0; i < one.visible.size(); ++i) {
        EXPECT_GT(one.visible[i], 0u);
        EXPECT_GE(one.passed[2 * i], one.visible[i]);
        EXPECT_GE(one.passed[2 * i + 1], one.visible[i]);
    }
}

// A sphere of one keyframe, framed, with the rank table of its stored order.
struct FramedSphere {
    AnimatedMesh mesh = make_uv_sphere(500);
    Framing framing = frame_keyframes(mesh.keyframe(0), 1, mesh.vertex_count, mesh.indices.data(), mesh.indices.size());
    std::vector<uint32_t> order, ranks;
    FramedSphere() : order(mesh.triangle_count()) {
        for (size_t i = 0; i < order.size(); ++i) order[i] = uint32_t(i);
        ranks = make_rank_table({order.data()}, order.size());
    }
};

TEST(ScoreNodes, RejectsAKeyframeOutOfRange) {
    const FramedSphere s;
    OverdrawNode node;
    node.keyframe = 3;
    uint64_t visible = 0, passed = 0;
    EXPECT_THROW(
        score_nodes(&visible, &passed, s.mesh.keyframe(0), s.mesh.vertex_count, s.framing, s.mesh.indices.data(),
                    s.mesh.indices.size(), &node, 1, s.ranks.data(), 1, ScoreSettings{}),
        InvalidInput);
}

// The per-node loops rasterise with NodeRasterizer::rasterize_validated (indices checked once per
// mesh): each entry point checks the indices itself, so an index past the vertices is InvalidInput
// before any node is drawn, never a read out of bounds.
TEST(ScoreNodes, EveryEntryPointRejectsAnIndexPastTheVertices) {
    const FramedSphere s;
    const AnimatedMesh& mesh = s.mesh;
    std::vector<uint32_t> bad = mesh.indices;
    bad[bad.size() / 2] = uint32_t(mesh.vertex_count);  // one past the last vertex
    OverdrawNode node;
    node.keyframe = 0;
    uint64_t visible = 0, passed = 0;
    EXPECT_THROW(score_nodes(&visible, &passed, mesh.keyframe(0), mesh.vertex_count, s.framing, bad.data(), bad.size(),
                             &node, 1, s.ranks.data(), 1, ScoreSettings{}),
                 InvalidInput);
    EXPECT_THROW(rasterize_nodes(mesh.keyframe(0), mesh.vertex_count, s.framing, bad.data(), bad.size(), &node, 1,
                                 ScoreSettings{}, size_t(1) << 30),
                 InvalidInput);
    const uint32_t starts[2] = {0, uint32_t(s.order.size())};
    const UnitPartition one_unit = make_unit_partition(starts, 1, s.order.data(), s.order.size());
    EXPECT_THROW(NodeCache(mesh.keyframe(0), mesh.vertex_count, s.framing, bad.data(), bad.size(), &node, 1, one_unit,
                           ScoreSettings{}, size_t(1) << 30),
                 InvalidInput);
    // The same calls with the good indices draw the node.
    NodeCache good(mesh.keyframe(0), mesh.vertex_count, s.framing, mesh.indices.data(), mesh.indices.size(), &node, 1,
                   one_unit, ScoreSettings{}, size_t(1) << 30);
    good.score(&visible, &passed, s.ranks.data(), 1);
    EXPECT_GT(visible, 1000u);
}
