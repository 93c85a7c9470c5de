// The single-buffer methods over a whole character: per-primitive orders that keep primitives'
// ranges and triangles' winding; the meshopt baseline reproduces meshoptimizer's own buffers.
#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
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
