// The single-buffer methods over a whole character: per-primitive orders that keep primitives'
// ranges and triangles' winding; the meshopt baseline reproduces meshoptimizer's own buffers.
#include "animorder/animated_mesh.h"
#include "animorder/evaluation.h"
#include "animorder/invalid_input.h"
#include "animorder/kept_fragments.h"
#include "animorder/mesh_patches.h"
#include "animorder/meshopt_order.h"
#include "animorder/methods.h"
#include "animorder/procedural_character.h"
#include "animorder/procedural_shapes.h"
#include "support/meshes.h"

#include <gtest/gtest.h>
#include <meshoptimizer.h>

using namespace animorder;

TEST(StaticMethods, EveryMethodKeepsPrimitivesAndWinding) {
    const AnimatedMesh mesh = make_procedural_character();
    for (const char* name : {"original", "static-sander07", "meshopt"}) {
        SCOPED_TRACE(name);
        const StaticMethodResult r = run_static_method(mesh, parse_static_method(name), StaticMethodSettings{});
        EXPECT_TRUE(test::is_permutation_of_iota(r.order));
        EXPECT_TRUE(test::same_triangles_same_winding(mesh.indices, r.indices));
        EXPECT_EQ(test::applied(mesh.indices, r.order), r.indices);
        for (const Primitive& p : mesh.primitives) {  // triangles never leave their primitive
            std::vector<uint32_t> a(mesh.indices.begin() + ptrdiff_t(p.first_index),
                                    mesh.indices.begin() + ptrdiff_t(p.first_index + p.index_count));
            std::vector<uint32_t> b(r.indices.begin() + ptrdiff_t(p.first_index),
                                    r.indices.begin() + ptrdiff_t(p.first_index + p.index_count));
            EXPECT_TRUE(test::same_triangles_same_winding(a, b)) << p.name;
        }
    }
    EXPECT_THROW(parse_static_method("fastest"), InvalidInput);
}

TEST(StaticMethods, MeshoptIsExactlyMeshoptimizersBuffer) {
    const AnimatedMesh mesh = make_torus_knot(6000);
    std::vector<uint32_t> cache(mesh.indices.size()), expected(mesh.indices.size());
    meshopt_optimizeVertexCache(cache.data(), mesh.indices.data(), mesh.indices.size(), mesh.vertex_count);
    meshopt_optimizeOverdraw(expected.data(), cache.data(), cache.size(), mesh.keyframe(0), mesh.vertex_count, 12,
                             1.05f);
    const std::vector<uint32_t> order =
        meshopt_order(mesh.indices.data(), mesh.indices.size(), mesh.keyframe(0), mesh.vertex_count, 16);
    EXPECT_EQ(test::applied(mesh.indices, order), expected);
}

// Primitives from one file primitive (a glTF mesh two nodes draw) share its one index buffer: each
// later one takes the first one's order, triangle for triangle, worked out by hand; primitives of
// other sources (or generated ones, source −1) keep theirs. Orders that move triangles between
// primitives, or instances of different sizes, are refused.
TEST(Methods, InstancesOfAFilePrimitiveTakeTheFirstOnesOrder) {
    AnimatedMesh mesh;
    mesh.vertex_count = 3;
    mesh.indices = std::vector<uint32_t>(3 * 8, 0);
    mesh.primitives = {{"a", 0, 9}, {"b", 9, 6}, {"a again", 15, 9}};
    for (Primitive& p : mesh.primitives) p.source_primitive = 0;
    mesh.primitives[0].source_mesh = 0, mesh.primitives[1].source_mesh = 1, mesh.primitives[2].source_mesh = 0;
    std::vector<uint32_t> order = {2, 0, 1, 4, 3, 5, 6, 7};
    tie_instances(mesh, order);
    EXPECT_EQ(order, (std::vector<uint32_t>{2, 0, 1, 4, 3, 7, 5, 6}));
    mesh.primitives[2].source_mesh = -1;  // generated: its own order
    order = {2, 0, 1, 4, 3, 5, 6, 7};
    tie_instances(mesh, order);
    EXPECT_EQ(order, (std::vector<uint32_t>{2, 0, 1, 4, 3, 5, 6, 7}));
    mesh.primitives[2].source_mesh = 0;
    order = {3, 0, 1, 2, 4, 5, 6, 7};  // a triangle of b in a's range
    EXPECT_THROW(tie_instances(mesh, order), InvalidInput);
    mesh.primitives[1] = {"b", 9, 3};
    mesh.primitives[2] = {"a again", 12, 12};
    mesh.primitives[2].source_mesh = 0, mesh.primitives[2].source_primitive = 0;
    order = {0, 1, 2, 3, 4, 5, 6, 7};
    EXPECT_THROW(tie_instances(mesh, order), InvalidInput);
}

// Each k-means method orders its blended primitives back to front per cluster (BlendOrder::
// PerCluster), so none may mis-sort more of them than single: measured and measured-joint had
// theirs reversed a second time by the rule for single-buffer sorts (0.82 of the pairs against
// single's 0.15 at these settings). The bundled character has blended hair cards and cape.
TEST(Methods, EveryClusteredMethodMisSortsNoMoreBlendedPairsThanSingle) {
    const AnimatedMesh mesh = make_procedural_character();
    MethodSettings settings;
    settings.clustering.clusters = 3;
    settings.clustering.views = 12;
    settings.clustering.resolution = 48;
    settings.clustering.max_iterations = 4;
    settings.clustering.threads = 1;
    std::vector<Method> clustered;
    std::vector<MethodBuffers> buffers;
    for (const Method m : all_methods()) {
        if (!method_is_clustered(m)) continue;
        EXPECT_EQ(method_blend_order(m), BlendOrder::PerCluster) << method_name(m);
        clustered.push_back(m);
        buffers.push_back(run_method(mesh, m, settings).buffers);
    }
    ASSERT_GE(clustered.size(), 4u);
    ASSERT_EQ(clustered[0], Method::Single);
    EvaluationSettings eval;
    eval.views = 4;
    eval.resolution = 64;
    eval.threads = 1;
    const std::vector<BlendEvaluation> blend = evaluate_blend(mesh, buffers, eval);
    ASSERT_EQ(blend.size(), clustered.size() + 1);  // then the bound
    const double single = blend[0].overall.missorted_pair_fraction;
    EXPECT_GT(blend[0].overall.pairs, 0u);
    EXPECT_LT(single, 0.5);  // mostly back to front
    for (size_t i = 1; i < clustered.size(); ++i)
        EXPECT_LE(blend[i].overall.missorted_pair_fraction, single + 0.05)
            << method_name(clustered[i]) << " against single's " << single;
}

// measured on a flat-shaded mesh (no face shares a vertex, so every λ patch is one triangle) takes
// the surface patches in pieces of kMeasuredSurfaceUnitTriangles as its units, at λ = 0.85 and 3;
// single keeps the λ patches (its outputs do not change), and on a smooth mesh measured keeps
// them too.
// More λ patches than a kept node lists (kMaxListedUnits): measured runs `single`'s k-means over
// them, then offers each cluster the measured order of runs of them (a 20k-triangle knot at
// λ = 3: pairs): every buffer is `single`'s own, or one that keeps every pair whole.
TEST(Methods, MeasuredBeyondTheListedUnitsIsSinglesKMeansWithMeasuredOrdersOffered) {
    const AnimatedMesh knot = make_torus_knot(20000);
    MethodSettings settings;
    settings.lambda = 3;
    settings.clustering.clusters = 2;
    settings.clustering.views = 12;
    settings.clustering.resolution = 48;
    settings.clustering.max_iterations = 2;
    const MeshPatches patches = build_mesh_patches(knot, 3);
    ASSERT_GT(patches.patch_count(), kMaxListedUnits);
    ASSERT_LE(patches.patch_count(), 2 * kMaxListedUnits);
    const MeshPatches pairs = patch_pieces(patches, 2);
    EXPECT_LE(pairs.patch_count(), kMaxListedUnits);
    const MethodResult measured = run_method(knot, Method::Measured, settings);
    const MethodResult single = run_method(knot, Method::Single, settings);
    EXPECT_EQ(measured.patch_count, patches.patch_count());
    ASSERT_EQ(measured.buffers.orders.size(), single.buffers.orders.size());
    ASSERT_EQ(measured.runs.size(), 1u);
    ASSERT_EQ(measured.runs[0].held_out_distance.size(), measured.buffers.orders.size());
    for (size_t b = 0; b < measured.buffers.orders.size(); ++b) {
        const auto& order = measured.buffers.orders[b];
        EXPECT_TRUE(test::is_permutation_of_iota(order));
        if (measured.runs[0].held_out_distance[b])
            EXPECT_EQ(order, single.buffers.orders[b]) << "buffer " << b << " kept as single's";
        else
            EXPECT_TRUE(test::keeps_units_whole(order, pairs.patch_starts, pairs.cache_order)) << "buffer " << b;
    }
    EXPECT_EQ(measured.runs[0].iterations.size(), single.runs[0].iterations.size());  // the same k-means
}

TEST(Methods, MeasuredTakesSurfacePiecesAsUnitsWhereThePatchesAreSingleTriangles) {
    const AnimatedMesh smooth = make_procedural_character();
    const AnimatedMesh flat = test::flat_shaded(smooth);
    MethodSettings settings;
    settings.clustering.clusters = 3;
    settings.clustering.views = 12;
    settings.clustering.resolution = 48;
    settings.clustering.max_iterations = 3;
    const size_t pieces = build_welded_patches(flat, settings.lambda, kMeasuredSurfaceUnitTriangles).patch_count();
    EXPECT_LT(2 * pieces, build_mesh_patches(flat, settings.lambda).patch_count());
    EXPECT_EQ(run_method(flat, Method::Measured, settings).patch_count, pieces);
    MethodSettings fine = settings;
    fine.lambda = 3;
    const size_t runs = build_welded_patches(flat, 3, kMeasuredSurfaceUnitTriangles).patch_count();
    EXPECT_LT(2 * runs, flat.triangle_count());
    EXPECT_EQ(run_method(flat, Method::Measured, fine).patch_count, runs);
    EXPECT_EQ(run_method(flat, Method::Single, settings).patch_count, build_mesh_patches(flat, settings.lambda).patch_count());
    EXPECT_EQ(run_method(smooth, Method::Measured, settings).patch_count,
              build_mesh_patches(smooth, settings.lambda).patch_count());
}
