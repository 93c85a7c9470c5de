// Tipsify: permutation and winding, hard boundaries where the paper's pseudo-code jumps, and
// ACMR against meshoptimizer's independent implementation of the same paper
// (meshopt_optimizeVertexCacheFifo).
#include "animorder/animated_mesh.h"
#include "animorder/gltf_loader.h"
#include "animorder/invalid_input.h"
#include "animorder/load.h"
#include "animorder/procedural_character.h"
#include "animorder/procedural_shapes.h"
#include "animorder/tipsify.h"
#include "animorder/vertex_cache.h"
#include "support/meshes.h"
#include "support/require.h"

#include <gtest/gtest.h>
#include <meshoptimizer.h>

#include <vector>

using namespace animorder;
using test::applied;

namespace {
std::vector<uint32_t> run(const std::vector<uint32_t>& ib, size_t vertices, unsigned cache = 16,
                          TipsifyResult* result = nullptr) {
    std::vector<uint32_t> order(ib.size() / 3);
    TipsifyResult r = tipsify(order.data(), ib.data(), ib.size(), vertices, cache);
    if (result) *result = r;
    return order;
}
}  // namespace

TEST(Tipsify, EmptyInputIsANoOp) {
    const TipsifyResult r = tipsify(nullptr, nullptr, 0, 0, 16);
    EXPECT_TRUE(r.hard_boundaries.empty());
}

TEST(Tipsify, FanAroundVertexZeroIsEmittedInAdjacencyOrderWithoutJumps) {
    // Four triangles around vertex 0, listed in reverse: fanning vertex 0 emits them in
    // adjacency (input) order 0,1,2,3 — the whole mesh is one fan.
    const std::vector<uint32_t> ib{0, 4, 1, 0, 3, 4, 0, 2, 3, 0, 1, 2};
    TipsifyResult r;
    EXPECT_EQ(run(ib, 5, 16, &r), (std::vector<uint32_t>{0, 1, 2, 3}));
    EXPECT_TRUE(r.hard_boundaries.empty());
}

TEST(Tipsify, HandWorkedStripFollowsTheEarliestCachedCandidate) {
    // Strip 0:(0,1,2) 1:(2,1,3) 2:(2,3,4) 3:(4,3,5). Fan vertex 0 → t0; candidates 0,1,2 then
    // have live counts 0,1,2 and cache positions 3,2,1: vertex 1 (2 + 2·1 <= 16) entered the
    // cache before 2, so it wins → t1 (3 enters). Candidates 2,1,3: 2 is the oldest live → t2;
    // candidates 2,3,4: 3 is the oldest live → t3. No dead-end.
    const std::vector<uint32_t> ib{0, 1, 2, 2, 1, 3, 2, 3, 4, 4, 3, 5};
    TipsifyResult r;
    EXPECT_EQ(run(ib, 6, 16, &r), (std::vector<uint32_t>{0, 1, 2, 3}));
    EXPECT_TRUE(r.hard_boundaries.empty());
}

TEST(Tipsify, DisconnectedPiecesAreHardBoundaries) {
    // Three separate triangles and an unreferenced vertex 9: every new piece is a dead-end jump.
    const std::vector<uint32_t> ib{6, 7, 8, 0, 1, 2, 3, 4, 5};
    TipsifyResult r;
    const std::vector<uint32_t> order = run(ib, 10, 16, &r);
    EXPECT_EQ(order, (std::vector<uint32_t>{1, 2, 0}));  // input-order sweep over vertices
    EXPECT_EQ(r.hard_boundaries, (std::vector<uint32_t>{1, 2}));
}

TEST(Tipsify, EveryComponentStartsAtAHardBoundary) {
    // 20 separate copies of a sphere: each copy beyond the first must begin after a jump.
    const AnimatedMesh sphere = make_uv_sphere(200);
    std::vector<uint32_t> ib;
    for (uint32_t copy = 0; copy < 20; ++copy)
        for (uint32_t i : sphere.indices) ib.push_back(i + copy * uint32_t(sphere.vertex_count));
    TipsifyResult r;
    const std::vector<uint32_t> order = run(ib, 20 * sphere.vertex_count, 16, &r);
    const size_t per_copy = sphere.indices.size() / 3;
    size_t component_changes = 0;
    for (size_t i = 1; i < order.size(); ++i) {
        const bool changes = order[i] / per_copy != order[i - 1] / per_copy;
        component_changes += changes;
        if (changes) {
            EXPECT_TRUE(std::binary_search(r.hard_boundaries.begin(), r.hard_boundaries.end(), uint32_t(i)))
                << "component changes at " << i << " without a hard boundary";
        }
    }
    EXPECT_EQ(component_changes, 19u);
    EXPECT_TRUE(std::is_sorted(r.hard_boundaries.begin(), r.hard_boundaries.end()));
}

TEST(Tipsify, OutputIsAPermutationKeepingWinding) {
    const AnimatedMesh mesh = make_procedural_character();
    const std::vector<uint32_t> order = run(mesh.indices, mesh.vertex_count);
    EXPECT_TRUE(test::is_permutation_of_iota(order));
    EXPECT_TRUE(test::same_triangles_same_winding(mesh.indices, applied(mesh.indices, order)));
}

TEST(Tipsify, DeterministicAndIndependentOfNothingButInput) {
    const AnimatedMesh mesh = make_torus_knot(5000);
    EXPECT_EQ(run(mesh.indices, mesh.vertex_count), run(mesh.indices, mesh.vertex_count));
}

TEST(Tipsify, RejectsBadInput) {
    const std::vector<uint32_t> ib{0, 1, 5};
    std::vector<uint32_t> order(1);
    EXPECT_THROW(tipsify(order.data(), ib.data(), ib.size(), 3, 16), InvalidInput);
    const std::vector<uint32_t> ok{0, 1, 2};
    EXPECT_THROW(tipsify(order.data(), ok.data(), ok.size(), 3, 2), InvalidInput);
}

TEST(Tipsify, DegenerateTrianglesAreEmittedOnce) {
    const std::vector<uint32_t> ib{0, 0, 1, 0, 1, 2, 2, 2, 2};
    const std::vector<uint32_t> order = run(ib, 3);
    EXPECT_TRUE(test::is_permutation_of_iota(order));
}

namespace {
double meshopt_fifo_acmr(const std::vector<uint32_t>& ib, size_t vertices, unsigned cache) {
    std::vector<uint32_t> out(ib.size());
    meshopt_optimizeVertexCacheFifo(out.data(), ib.data(), ib.size(), vertices, cache);
    return meshopt_analyzeVertexCache(out.data(), out.size(), vertices, cache, 0, 0).acmr;
}

void expect_within_two_percent_of_meshoptimizer(const AnimatedMesh& mesh) {
    SCOPED_TRACE(mesh.name + " " + std::to_string(mesh.triangle_count()) + " triangles");
    // From the generated order and from a shuffled one (a bad input order makes the cursor
    // fallback and the dead-end stack matter).
    for (uint32_t seed : {0u, 11u}) {
        const std::vector<uint32_t> ib = seed ? test::shuffled_triangles(mesh.indices, seed) : mesh.indices;
        const std::vector<uint32_t> ours = applied(ib, run(ib, mesh.vertex_count, 16));
        const double acmr = analyze_vertex_cache(ours.data(), ours.size(), mesh.vertex_count, 16).acmr;
        const double reference = meshopt_fifo_acmr(ib, mesh.vertex_count, 16);
        EXPECT_LE(acmr, reference * 1.02) << "ours " << acmr << " meshoptimizer " << reference;
        EXPECT_GE(acmr, 0.5);  // nothing beats the steady-state bound of a manifold by much
    }
}
}  // namespace

TEST(Tipsify, AcmrWithinTwoPercentOfMeshoptimizerOnSpheres) {
    for (size_t n : {10000u, 50000u, 200000u}) expect_within_two_percent_of_meshoptimizer(make_uv_sphere(n));
}

TEST(Tipsify, AcmrWithinTwoPercentOfMeshoptimizerOnTorusKnots) {
    for (size_t n : {10000u, 50000u, 200000u}) expect_within_two_percent_of_meshoptimizer(make_torus_knot(n));
}

TEST(Tipsify, AcmrWithinTwoPercentOfMeshoptimizerOnTheCharacter) {
    expect_within_two_percent_of_meshoptimizer(make_procedural_character());
}

TEST(Tipsify, AcmrWithinTwoPercentOfMeshoptimizerOnRealCharacters) {
    const char* files[] = {"mixamo-ganfaul/Ganfaul.gltf", "gltf-cesiumman/CesiumMan.glb", "glb-xbot/Xbot.glb"};
    animorder::test::DataFiles data;
    for (const char* f : files) {
        // Only an absent file may skip (at the end, naming every absent one, after the others
        // ran); a file that is there but does not load is a failure.
        const std::filesystem::path path = animorder::test::shared_data_path(f);
        if (!data.present(path)) continue;
        AnimatedMesh mesh;
        try {
            mesh = load_gltf(path.string());
        } catch (const LoadError& e) {
            FAIL() << path.string() << " is there but does not load: " << e.what();
        }
        mesh.name = f;
        expect_within_two_percent_of_meshoptimizer(mesh);
    }
    ANIMORDER_REQUIRE_ALL_DATA(data);
}

TEST(Tipsify, SmallerCacheNeverHelpsAndAllSizesBeatRandom) {
    const AnimatedMesh mesh = make_torus_knot(20000);
    const std::vector<uint32_t> shuffled = test::shuffled_triangles(mesh.indices, 3);
    const double random_acmr = analyze_vertex_cache(shuffled.data(), shuffled.size(), mesh.vertex_count, 16).acmr;
    double previous = 3.0;
    for (unsigned cache : {4u, 8u, 16u, 32u, 64u}) {
        const std::vector<uint32_t> ours = applied(shuffled, run(shuffled, mesh.vertex_count, cache));
        const double acmr = analyze_vertex_cache(ours.data(), ours.size(), mesh.vertex_count, cache).acmr;
        EXPECT_LT(acmr, previous + 1e-9) << "cache " << cache;
        EXPECT_LT(acmr, (cache >= 8 ? 0.5 : 0.75) * random_acmr) << "cache " << cache;
        previous = acmr;
    }
    EXPECT_LT(previous, 0.72);  // the paper's steady state (n+2)/(2n+2) approaches 0.5 for large k
}

TEST(Tipsify, IndexBufferVariantEqualsTheAppliedOrder) {
    const AnimatedMesh mesh = make_torus_knot(3000);
    const std::vector<uint32_t> ib = test::shuffled_triangles(mesh.indices, 5);
    std::vector<uint32_t> direct(ib.size());
    const TipsifyResult a = tipsify_index_buffer(direct.data(), ib.data(), ib.size(), mesh.vertex_count, 16);
    TipsifyResult b;
    EXPECT_EQ(direct, applied(ib, run(ib, mesh.vertex_count, 16, &b)));
    EXPECT_EQ(a.hard_boundaries, b.hard_boundaries);
    EXPECT_THROW(tipsify_index_buffer(direct.data(), direct.data(), direct.size(), mesh.vertex_count, 16),
                 InvalidInput);
}

TEST(Tipsify, ReproducesMeshoptimizersTipsifyExactly) {
    // meshoptimizer implements the same pseudo-code independently (same start vertex, priority
    // rule, dead-end stack and input-order cursor), so the index buffers must be identical.
    for (const AnimatedMesh& mesh : {make_uv_sphere(20000), make_torus_knot(20000), make_procedural_character()}) {
        SCOPED_TRACE(mesh.name);
        for (unsigned cache : {8u, 16u, 32u}) {
            const std::vector<uint32_t> ib = test::shuffled_triangles(mesh.indices, cache);
            std::vector<uint32_t> ours(ib.size()), reference(ib.size());
            tipsify_index_buffer(ours.data(), ib.data(), ib.size(), mesh.vertex_count, cache);
            meshopt_optimizeVertexCacheFifo(reference.data(), ib.data(), ib.size(), mesh.vertex_count, cache);
            EXPECT_EQ(ours, reference) << "cache " << cache;
        }
    }
}
