// ACMR/ATVR: hand-worked FIFO cases, then equality with meshoptimizer's analyser (an independent
// implementation; its vertex-cache analyser is sound, unlike its 0.18 overdraw analyser).
#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/procedural_character.h"
#include "animorder/procedural_shapes.h"
#include "animorder/vertex_cache.h"
#include "support/meshes.h"

#include <gtest/gtest.h>
#include <meshoptimizer.h>

#include <vector>

using namespace animorder;

namespace {
VertexCacheStats stats(const std::vector<uint32_t>& ib, size_t vertices, unsigned cache) {
    return analyze_vertex_cache(ib.data(), ib.size(), vertices, cache);
}
}  // namespace

TEST(VertexCache, SingleTriangleMissesEveryCorner) {
    const VertexCacheStats s = stats({0, 1, 2}, 3, 16);
    EXPECT_EQ(s.misses, 3u);
    EXPECT_DOUBLE_EQ(s.acmr, 3.0);
    EXPECT_DOUBLE_EQ(s.atvr, 1.0);
}

TEST(VertexCache, QuadSharesAnEdge) {
    const VertexCacheStats s = stats({0, 1, 2, 2, 1, 3}, 4, 16);
    EXPECT_EQ(s.misses, 4u);
    EXPECT_DOUBLE_EQ(s.acmr, 2.0);
}

TEST(VertexCache, RevisitDependsOnCacheSize) {
    // (0,1,2) (3,4,5) (0,1,2): with 3..5 entries the revisit misses everything (9 misses);
    // with 6 entries it hits everything (6 misses).
    const std::vector<uint32_t> ib{0, 1, 2, 3, 4, 5, 0, 1, 2};
    EXPECT_EQ(stats(ib, 6, 3).misses, 9u);
    EXPECT_EQ(stats(ib, 6, 4).misses, 9u);
    EXPECT_EQ(stats(ib, 6, 5).misses, 9u);
    EXPECT_EQ(stats(ib, 6, 6).misses, 6u);
    EXPECT_DOUBLE_EQ(stats(ib, 6, 6).acmr, 2.0);
    EXPECT_DOUBLE_EQ(stats(ib, 6, 6).atvr, 1.0);
    EXPECT_DOUBLE_EQ(stats(ib, 6, 3).atvr, 1.5);
}

TEST(VertexCache, IsFifoNotLru) {
    // Cache 3: (0,1,2) fills it; (0,3,4): 0 hits but is not refreshed, so 3 evicts 0 and 4 evicts 1;
    // (0,2,5): 0 misses (evicts 2), 2 misses (evicts 3), 5 misses. FIFO: 3+2+3 = 8; LRU would give 7.
    EXPECT_EQ(stats({0, 1, 2, 0, 3, 4, 0, 2, 5}, 6, 3).misses, 8u);
}

TEST(VertexCache, DegenerateTriangleLooksUpCornersInTurn) { EXPECT_EQ(stats({0, 0, 1}, 2, 16).misses, 2u); }

TEST(VertexCache, UnreferencedVerticesDoNotCountInAtvr) {
    const VertexCacheStats s = stats({5, 6, 7}, 100, 16);
    EXPECT_EQ(s.referenced_vertices, 3u);
    EXPECT_DOUBLE_EQ(s.atvr, 1.0);
}

TEST(VertexCache, EmptyIsZero) {
    const VertexCacheStats s = analyze_vertex_cache(nullptr, 0, 0, 16);
    EXPECT_EQ(s.misses, 0u);
    EXPECT_EQ(s.acmr, 0.0);
}

TEST(VertexCache, RejectsBadInput) {
    const std::vector<uint32_t> ib{0, 1, 3};
    EXPECT_THROW(stats(ib, 3, 16), InvalidInput);
    EXPECT_THROW(stats({0, 1, 2}, 3, 0), InvalidInput);
}

namespace {
void expect_equal_to_meshoptimizer(const std::vector<uint32_t>& ib, size_t vertices, unsigned cache) {
    const meshopt_VertexCacheStatistics reference =
        meshopt_analyzeVertexCache(ib.data(), ib.size(), vertices, cache, 0, 0);
    const VertexCacheStats ours = analyze_vertex_cache(ib.data(), ib.size(), vertices, cache);
    EXPECT_EQ(ours.misses, reference.vertices_transformed) << "cache " << cache;
    EXPECT_FLOAT_EQ(float(ours.acmr), reference.acmr) << "cache " << cache;
}
}  // namespace

TEST(VertexCache, EqualsMeshoptimizerOnProceduralMeshes) {
    const AnimatedMesh meshes[] = {make_uv_sphere(10000), make_torus_knot(10000), make_procedural_character()};
    for (const AnimatedMesh& mesh : meshes) {
        SCOPED_TRACE(mesh.name);
        for (unsigned cache : {3u, 8u, 16u, 32u}) {
            expect_equal_to_meshoptimizer(mesh.indices, mesh.vertex_count, cache);
            expect_equal_to_meshoptimizer(test::shuffled_triangles(mesh.indices, 7), mesh.vertex_count, cache);
        }
    }
}
