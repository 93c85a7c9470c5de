// static-nehab06 (Nehab, Barczak & Sander 2006): normal clusters on shapes whose answer is known, the overdraw graph against the engine
// drawing both cluster orders (exact integers), crafted scenes with a known right order, and the
// whole method on the bundled character against static-sander07 and Tipsify.
#include "animorder/animated_mesh.h"
#include "animorder/evaluation.h"
#include "animorder/invalid_input.h"
#include "animorder/methods.h"
#include "animorder/nehab06.h"
#include "animorder/overdraw.h"
#include "animorder/planar_clusters.h"
#include "animorder/procedural_character.h"
#include "animorder/procedural_shapes.h"
#include "animorder/tipsify.h"
#include "animorder/vertex_cache.h"
#include "animorder/viewpoints.h"
#include "support/feedback_arcs.h"
#include "support/meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <set>
#include <vector>

using namespace animorder;
using test::fas;
using test::feedback;

namespace {

// A closed surface appended to a mesh: positions scaled about the origin and shifted.
struct Soup {
    std::vector<float> positions;
    std::vector<uint32_t> indices;
    void add(const AnimatedMesh& m, float scale, float dx = 0, float dy = 0, float dz = 0) {
        const uint32_t base = uint32_t(positions.size() / 3);
        for (size_t v = 0; v < m.vertex_count; ++v) {
            positions.push_back(m.keyframe(0)[3 * v] * scale + dx);
            positions.push_back(m.keyframe(0)[3 * v + 1] * scale + dy);
            positions.push_back(m.keyframe(0)[3 * v + 2] * scale + dz);
        }
        for (uint32_t i : m.indices) indices.push_back(base + i);
    }
    // A planar quad a, b, c, d counter-clockwise seen from its front.
    void quad(const float a[3], const float b[3], const float c[3], const float d[3]) {
        const uint32_t base = uint32_t(positions.size() / 3);
        for (const float* p : {a, b, c, d}) positions.insert(positions.end(), p, p + 3);
        indices.insert(indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
    size_t vertex_count() const { return positions.size() / 3; }
    size_t triangles() const { return indices.size() / 3; }
};

// A cube of 12 triangles (two per face), CCW outward.
Soup cube(float dx = 0) {
    Soup s;
    const float p[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    for (const auto& v : p) s.positions.insert(s.positions.end(), {v[0] + dx, v[1], v[2]});
    s.indices = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                 2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3};
    return s;
}

// Σ over nodes of the fragments passing when `order` is drawn, for the triangles `order` lists
// (a sub-buffer), framed as `framing` says (the whole mesh's framing).
uint64_t passed_sum(const Soup& s, const std::vector<uint32_t>& triangles_drawn,
                    const std::vector<uint32_t>& order_in_sub, const Framing& framing,
                    const std::vector<OverdrawNode>& nodes, unsigned resolution, const float* keyframes_positions) {
    std::vector<uint32_t> sub;
    for (uint32_t t : triangles_drawn) sub.insert(sub.end(), s.indices.begin() + 3 * t, s.indices.begin() + 3 * t + 3);
    const std::vector<uint32_t> ranks = make_rank_table({order_in_sub.data()}, triangles_drawn.size());
    std::vector<uint64_t> visible(nodes.size()), passed(nodes.size());
    ScoreSettings settings;
    settings.resolution = resolution;
    score_nodes(visible.data(), passed.data(), keyframes_positions, s.vertex_count(), framing, sub.data(), sub.size(),
                nodes.data(), nodes.size(), ranks.data(), 1, settings);
    uint64_t total = 0;
    for (uint64_t p : passed) total += p;
    return total;
}

std::vector<OverdrawNode> icosphere_nodes(const std::vector<uint32_t>& keyframes, unsigned subdivisions) {
    const std::vector<float> d = icosphere_directions(subdivisions);
    std::vector<OverdrawNode> nodes;
    for (uint32_t k : keyframes)
        for (size_t v = 0; v < d.size() / 3; ++v) {
            OverdrawNode n;
            n.keyframe = k;
            for (int i = 0; i < 3; ++i) n.direction[i] = d[3 * v + size_t(i)];
            nodes.push_back(n);
        }
    return nodes;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Planar clusters

TEST(PlanarClusters, CubeFacesAreTheSixClusters) {
    const Soup s = cube();
    const std::vector<uint32_t> c =
        cluster_by_normals(s.indices.data(), s.indices.size(), s.positions.data(), s.vertex_count(), 6);
    ASSERT_EQ(c.size(), 12u);
    for (size_t face = 0; face < 6; ++face) EXPECT_EQ(c[2 * face], c[2 * face + 1]) << "face " << face;
    EXPECT_EQ(std::set<uint32_t>(c.begin(), c.end()).size(), 6u);
    EXPECT_EQ(*std::max_element(c.begin(), c.end()), 5u);
}

TEST(PlanarClusters, OneClusterPerTriangleAtMostAndOneCluster) {
    const Soup s = cube();
    std::vector<uint32_t> c =
        cluster_by_normals(s.indices.data(), s.indices.size(), s.positions.data(), s.vertex_count(), 100);
    EXPECT_EQ(std::set<uint32_t>(c.begin(), c.end()).size(), 12u);
    c = cluster_by_normals(s.indices.data(), s.indices.size(), s.positions.data(), s.vertex_count(), 1);
    EXPECT_EQ(c, std::vector<uint32_t>(12, 0));
}

TEST(PlanarClusters, EveryComponentGetsASeedWhileSeedsLast) {
    Soup s = cube();
    const Soup second = cube(5);
    const uint32_t base = uint32_t(s.vertex_count());
    s.positions.insert(s.positions.end(), second.positions.begin(), second.positions.end());
    for (uint32_t i : second.indices) s.indices.push_back(base + i);
    const std::vector<uint32_t> c =
        cluster_by_normals(s.indices.data(), s.indices.size(), s.positions.data(), s.vertex_count(), 2);
    for (size_t t = 0; t < 12; ++t) {
        EXPECT_EQ(c[t], c[0]);
        EXPECT_EQ(c[12 + t], c[12]);
    }
    EXPECT_NE(c[0], c[12]);
}

// Two small triangles facing −z, then an open unit box whose five faces have their own vertices
// (seams on every edge: five components by index, one surface by position), then a third small
// triangle facing −z. With two clusters the box, one component across its seams and the largest,
// gets a seed of its own; the small triangles share the other cluster (the others join whole, by
// their normal). Seeding the lowest triangle first, the two seeds would go to the small triangles
// and the box would end up split or with one of them.
TEST(PlanarClusters, SeamsDoNotCutAndTheLargestComponentIsSeededFirst) {
    Soup s;
    auto small = [&s](float x) {
        const uint32_t base = uint32_t(s.vertex_count());
        s.positions.insert(s.positions.end(), {x, 10, 0, x + 0.5f, 10, 0, x, 10.5f, 0});
        s.indices.insert(s.indices.end(), {base, base + 2, base + 1});  // clockwise from +z: faces −z
    };
    small(0);
    small(2);
    const uint32_t box = uint32_t(s.triangles());
    const float p[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    // An open box (no −z face) with split vertices along every edge: one surface only once the
    // seams are welded, its area-weighted mean normal +z.
    const int faces[5][4] = {{4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};
    for (const auto& f : faces) s.quad(p[f[0]], p[f[1]], p[f[2]], p[f[3]]);
    const uint32_t box_end = uint32_t(s.triangles());
    small(4);
    // Without update steps the seeding alone must get it right; with them it must stay right.
    for (unsigned iterations : {0u, 8u}) {
        const std::vector<uint32_t> c =
            cluster_by_normals(s.indices.data(), s.indices.size(), s.positions.data(), s.vertex_count(), 2, iterations);
        for (uint32_t t = box; t < box_end; ++t) EXPECT_EQ(c[t], c[box]) << t << " after " << iterations;
        EXPECT_EQ(c[1], c[0]) << iterations;
        EXPECT_EQ(c[box_end], c[0]) << iterations;
        EXPECT_NE(c[0], c[box]) << iterations;
    }
}

TEST(PlanarClusters, ClustersAreFlatterThanChanceOnATorusKnot) {
    // The normal spread inside clusters (mean 1 − n̄c·nf) must fall as clusters are added, and be
    // far below the whole mesh's (a sanity bound from the definition, not a tuned number).
    const AnimatedMesh knot = make_torus_knot(4000);
    auto spread = [&](size_t k) {
        const std::vector<uint32_t> c =
            cluster_by_normals(knot.indices.data(), knot.indices.size(), knot.keyframe(0), knot.vertex_count, k);
        std::vector<std::array<double, 3>> sum(k, {0, 0, 0}), normal(knot.triangle_count());
        for (size_t t = 0; t < knot.triangle_count(); ++t) {
            const float *a = knot.keyframe(0) + 3 * knot.indices[3 * t],
                        *b = knot.keyframe(0) + 3 * knot.indices[3 * t + 1],
                        *d = knot.keyframe(0) + 3 * knot.indices[3 * t + 2];
            const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
            std::array<double, 3> n = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
            for (int i = 0; i < 3; ++i) sum[c[t]][size_t(i)] += n[size_t(i)];
            const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            for (double& x : n) x /= l;
            normal[t] = n;
        }
        double total = 0;
        for (size_t t = 0; t < knot.triangle_count(); ++t) {
            const auto& s = sum[c[t]];
            const double l = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
            total += 1 - (s[0] * normal[t][0] + s[1] * normal[t][1] + s[2] * normal[t][2]) / l;
        }
        return total / double(knot.triangle_count());
    };
    const double s1 = spread(1), s8 = spread(8), s64 = spread(64);
    EXPECT_GT(s1, 0.9);  // a closed surface: normals everywhere, mean ≈ 1
    EXPECT_LT(s8, 0.5 * s1);
    EXPECT_LT(s64, 0.5 * s8);
}

TEST(PlanarClusters, TipsifyInsideClusters) {
    const AnimatedMesh knot = make_torus_knot(3000);
    const size_t n = knot.triangle_count();
    const std::vector<uint32_t> c =
        cluster_by_normals(knot.indices.data(), knot.indices.size(), knot.keyframe(0), knot.vertex_count, 16);
    std::vector<uint32_t> order(n);
    const std::vector<uint32_t> starts =
        tipsify_clusters(order.data(), knot.indices.data(), knot.indices.size(), knot.vertex_count, c.data(), 16);
    ASSERT_EQ(starts.size(), 17u);
    EXPECT_EQ(starts.back(), n);
    EXPECT_TRUE(test::is_permutation_of_iota(order));
    for (size_t k = 0; k < 16; ++k)
        for (uint32_t i = starts[k]; i < starts[k + 1]; ++i) EXPECT_EQ(c[order[i]], k);
    // One cluster: exactly Tipsify of the whole mesh (the local renumbering keeps first-use order
    // of the vertices, which is what Tipsify's tie-breaks see… so compare cache behaviour instead
    // of indices when the numbering differs): ACMR equal.
    const std::vector<uint32_t> zeros(n, 0);
    tipsify_clusters(order.data(), knot.indices.data(), knot.indices.size(), knot.vertex_count, zeros.data(), 1);
    std::vector<uint32_t> whole(n);
    tipsify(whole.data(), knot.indices.data(), knot.indices.size(), knot.vertex_count);
    const auto a = analyze_vertex_cache(test::applied(knot.indices, order).data(), 3 * n, knot.vertex_count);
    const auto b = analyze_vertex_cache(test::applied(knot.indices, whole).data(), 3 * n, knot.vertex_count);
    EXPECT_NEAR(a.acmr, b.acmr, 0.02);
}

TEST(PlanarClusters, BadInputThrows) {
    const Soup s = cube();
    EXPECT_THROW(cluster_by_normals(s.indices.data(), s.indices.size(), s.positions.data(), s.vertex_count(), 0),
                 InvalidInput);
    EXPECT_THROW(cluster_by_normals(s.indices.data(), s.indices.size(), s.positions.data(), 7, 2), InvalidInput);
    std::vector<float> nan = s.positions;
    nan[4] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(cluster_by_normals(s.indices.data(), s.indices.size(), nan.data(), s.vertex_count(), 2), InvalidInput);
    const std::vector<uint32_t> bad_cluster(12, 3);
    std::vector<uint32_t> order(12);
    EXPECT_THROW(
        tipsify_clusters(order.data(), s.indices.data(), s.indices.size(), s.vertex_count(), bad_cluster.data(), 3),
        InvalidInput);
}

// ---------------------------------------------------------------------------------------------
// The overdraw graph against the engine

TEST(OverdrawGraph, EveryArcIsTheEnginesDifferenceOfTheTwoPairOrders) {
    // Three normal clusters of a torus knot over two keyframes (the second one squashed and
    // turned). For every pair, drawing only the pair's triangles as (a then b) and (b then a),
    // each in its Tipsify order, over the same nodes and framing: the arc must be exactly the
    // difference of the passed-fragment sums, with the right direction, and absent at zero.
    const AnimatedMesh knot = make_torus_knot(2500);
    Soup s;
    s.add(knot, 1);
    std::vector<float> positions = s.positions;
    for (size_t v = 0; v < s.vertex_count(); ++v) {
        const float x = s.positions[3 * v], y = s.positions[3 * v + 1], z = s.positions[3 * v + 2];
        positions.insert(positions.end(), {0.8f * z + 0.1f, 0.6f * y, -x});
    }
    const size_t n = s.triangles(), clusters = 3;
    const std::vector<uint32_t> cluster_of =
        cluster_by_normals(s.indices.data(), s.indices.size(), s.positions.data(), s.vertex_count(), clusters);
    std::vector<uint32_t> grouped(n);
    const std::vector<uint32_t> starts = tipsify_clusters(grouped.data(), s.indices.data(), s.indices.size(),
                                                          s.vertex_count(), cluster_of.data(), clusters);
    const std::vector<uint32_t> keyframes = {0, 1};
    OverdrawGraphSettings settings;
    settings.views = 42;
    settings.resolution = 96;
    const std::vector<Arc> arcs =
        build_overdraw_graph(s.indices.data(), s.indices.size(), positions.data(), 2, s.vertex_count(),
                             keyframes.data(), keyframes.size(), cluster_of.data(), clusters, grouped.data(), settings);

    const Framing framing = frame_subset(
        frame_keyframes(positions.data(), 2, s.vertex_count(), s.indices.data(), s.indices.size()), keyframes);
    const std::vector<OverdrawNode> nodes = icosphere_nodes(keyframes, 1);
    size_t nonzero = 0;
    for (uint32_t a = 0; a < clusters; ++a)
        for (uint32_t b = a + 1; b < clusters; ++b) {
            // The pair's triangles: a's in Tipsify order, then b's.
            std::vector<uint32_t> drawn(grouped.begin() + starts[a], grouped.begin() + starts[a + 1]);
            const size_t na = drawn.size();
            drawn.insert(drawn.end(), grouped.begin() + starts[b], grouped.begin() + starts[b + 1]);
            std::vector<uint32_t> ab(drawn.size()), ba;
            for (size_t i = 0; i < drawn.size(); ++i) ab[i] = uint32_t(i);
            for (size_t i = na; i < drawn.size(); ++i) ba.push_back(uint32_t(i));
            for (size_t i = 0; i < na; ++i) ba.push_back(uint32_t(i));
            const int64_t passed_ab = int64_t(passed_sum(s, drawn, ab, framing, nodes, 96, positions.data()));
            const int64_t passed_ba = int64_t(passed_sum(s, drawn, ba, framing, nodes, 96, positions.data()));
            const int64_t saving = passed_ba - passed_ab;  // of a before b
            int64_t measured = 0;
            for (const Arc& arc : arcs) {
                if (arc.from == a && arc.to == b) measured += int64_t(arc.weight);
                if (arc.from == b && arc.to == a) measured -= int64_t(arc.weight);
            }
            EXPECT_EQ(measured, saving) << "pair " << a << ", " << b;
            nonzero += saving != 0;
        }
    EXPECT_EQ(arcs.size(), nonzero);
    EXPECT_GT(nonzero, 0u);  // the knot occludes itself
}

TEST(OverdrawGraph, IdenticalWithOneOrTwoThreads) {
    const AnimatedMesh knot = make_torus_knot(3000);
    const size_t n = knot.triangle_count(), clusters = 12;
    const std::vector<uint32_t> c =
        cluster_by_normals(knot.indices.data(), knot.indices.size(), knot.keyframe(0), knot.vertex_count, clusters);
    std::vector<uint32_t> grouped(n);
    tipsify_clusters(grouped.data(), knot.indices.data(), knot.indices.size(), knot.vertex_count, c.data(), clusters);
    OverdrawGraphSettings one, two;
    one.views = two.views = 42;
    one.resolution = two.resolution = 128;
    one.threads = 1;
    two.threads = 2;
    const auto a = build_overdraw_graph(knot.indices.data(), knot.indices.size(), knot.keyframe(0), 1,
                                        knot.vertex_count, nullptr, 0, c.data(), clusters, grouped.data(), one);
    const auto b = build_overdraw_graph(knot.indices.data(), knot.indices.size(), knot.keyframe(0), 1,
                                        knot.vertex_count, nullptr, 0, c.data(), clusters, grouped.data(), two);
    ASSERT_EQ(a.size(), b.size());
    ASSERT_GT(a.size(), 0u);
    for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].from, b[i].from);
        EXPECT_EQ(a[i].to, b[i].to);
        EXPECT_EQ(a[i].weight, b[i].weight);
    }
}

// ---------------------------------------------------------------------------------------------
// Crafted scenes with a known right order

TEST(StaticNehab06, NestedShellsDrawTheOuterShellFirst) {
    // A sphere inside a sphere: from outside, the outer shell hides the inner one completely, so
    // the outer one must come first, and then every pixel is shaded once (OVR exactly 1).
    const AnimatedMesh sphere = make_uv_sphere(800);
    Soup s;
    s.add(sphere, 0.5f);  // inner: triangles [0, inner)
    const size_t inner = s.triangles();
    s.add(sphere, 1.0f);
    const size_t n = s.triangles();

    std::vector<uint32_t> shell(n, 1);
    std::fill(shell.begin(), shell.begin() + long(inner), 0u);
    std::vector<uint32_t> grouped(n);
    tipsify_clusters(grouped.data(), s.indices.data(), s.indices.size(), s.vertex_count(), shell.data(), 2);
    OverdrawGraphSettings graph;
    graph.views = 42;
    graph.resolution = 128;
    const std::vector<Arc> arcs =
        build_overdraw_graph(s.indices.data(), s.indices.size(), s.positions.data(), 1, s.vertex_count(), nullptr, 0,
                             shell.data(), 2, grouped.data(), graph);
    ASSERT_EQ(arcs.size(), 1u);
    EXPECT_EQ(arcs[0].from, 1u);  // outer before inner
    EXPECT_EQ(arcs[0].to, 0u);

    // The whole method with two clusters finds the shells (two components) and orders them.
    Nehab06Settings settings;
    settings.clusters = 2;
    settings.views = 42;
    settings.resolution = 128;
    std::vector<uint32_t> order(n);
    const Nehab06Result r = order_static_nehab06(order.data(), s.indices.data(), s.indices.size(), s.positions.data(),
                                                 1, s.vertex_count(), nullptr, 0, settings);
    EXPECT_EQ(r.cluster_count, 2u);
    EXPECT_EQ(r.arc_count, 1u);
    EXPECT_EQ(r.feedback_arc_count, 0u);
    for (size_t i = 0; i < n; ++i) EXPECT_EQ(order[i] >= inner, i < n - inner) << "position " << i;

    const Framing framing =
        frame_keyframes(s.positions.data(), 1, s.vertex_count(), s.indices.data(), s.indices.size());
    const std::vector<OverdrawNode> nodes = icosphere_nodes({0}, 2);
    const std::vector<uint32_t> ranks = make_rank_table({order.data()}, n);
    std::vector<uint64_t> visible(nodes.size()), passed(nodes.size());
    ScoreSettings score;
    score.resolution = 128;
    score_nodes(visible.data(), passed.data(), s.positions.data(), s.vertex_count(), framing, s.indices.data(),
                s.indices.size(), nodes.data(), nodes.size(), ranks.data(), 1, score);
    for (size_t i = 0; i < nodes.size(); ++i) EXPECT_EQ(passed[i], visible[i]) << "node " << i;
}

TEST(StaticNehab06, RowOfOccludersIsDrawnFrontToBackAlongTheRow) {
    // Six unit squares facing +x at x = 0, 0.4, …, 2: from every view on the +x side the square
    // with the larger x hides part of the ones behind it (from −x all are culled). Every arc must
    // go from the larger x to the smaller, and the order must be the row from +x to −x.
    Soup s;
    const size_t squares = 6;
    for (size_t i = 0; i < squares; ++i) {
        const float x = 0.4f * float(i);
        const float a[3] = {x, -0.5f, -0.5f}, b[3] = {x, 0.5f, -0.5f}, c[3] = {x, 0.5f, 0.5f}, d[3] = {x, -0.5f, 0.5f};
        s.quad(a, b, c, d);  // CCW seen from +x
    }
    std::vector<uint32_t> square(2 * squares);
    for (size_t t = 0; t < square.size(); ++t) square[t] = uint32_t(t / 2);
    std::vector<uint32_t> grouped(square.size());
    tipsify_clusters(grouped.data(), s.indices.data(), s.indices.size(), s.vertex_count(), square.data(), squares);
    OverdrawGraphSettings graph;
    graph.resolution = 128;
    const std::vector<Arc> arcs =
        build_overdraw_graph(s.indices.data(), s.indices.size(), s.positions.data(), 1, s.vertex_count(), nullptr, 0,
                             square.data(), squares, grouped.data(), graph);
    EXPECT_EQ(arcs.size(), squares * (squares - 1) / 2);  // every pair overlaps from some view
    for (const Arc& arc : arcs) EXPECT_GT(arc.from, arc.to);
    const std::vector<uint32_t> order = fas(squares, arcs);
    EXPECT_EQ(order, (std::vector<uint32_t>{5, 4, 3, 2, 1, 0}));

    // The whole method: the six squares are six components, so six clusters are the squares.
    Nehab06Settings settings;
    settings.clusters = squares;
    settings.resolution = 128;
    std::vector<uint32_t> faces(2 * squares);
    order_static_nehab06(faces.data(), s.indices.data(), s.indices.size(), s.positions.data(), 1, s.vertex_count(),
                         nullptr, 0, settings);
    for (size_t i = 0; i < faces.size(); ++i) EXPECT_EQ(faces[i] / 2, squares - 1 - i / 2) << "position " << i;
}

TEST(StaticNehab06, CyclicOverlapKeepsTheHeavierArcs) {
    // Three tilted sticks around a triangle, each rising from one corner to the next, so stick i
    // lies above stick i+1 where they cross (the classic cyclic overlap): seen from above, 0
    // hides 1, 1 hides 2, 2 hides 0. Stick 2 is narrower, so both of its arcs are lighter than
    // 0→1; the order must break the cycle at the lightest arc and keep the two heavier ones.
    Soup s;
    const float width[3] = {0.2f, 0.2f, 0.08f};
    float corner[3][2];
    for (int i = 0; i < 3; ++i) {
        const double angle = M_PI / 2 + 2 * M_PI * i / 3;
        corner[i][0] = float(std::cos(angle));
        corner[i][1] = float(std::sin(angle));
    }
    for (int i = 0; i < 3; ++i) {
        const float* p = corner[i];
        const float* q = corner[(i + 1) % 3];
        float d[2] = {q[0] - p[0], q[1] - p[1]};
        const float length = std::sqrt(d[0] * d[0] + d[1] * d[1]);
        d[0] /= length;
        d[1] /= length;
        const float side[2] = {-d[1] * width[i] / 2, d[0] * width[i] / 2};  // left of the direction
        const float e = 0.3f, h = 0.25f;
        const float slope = 2 * h / length;
        const float s0[2] = {p[0] - e * d[0], p[1] - e * d[1]}, s1[2] = {q[0] + e * d[0], q[1] + e * d[1]};
        const float z0 = -h - slope * e, z1 = h + slope * e;
        const float a[3] = {s0[0] - side[0], s0[1] - side[1], z0}, b[3] = {s1[0] - side[0], s1[1] - side[1], z1};
        const float c[3] = {s1[0] + side[0], s1[1] + side[1], z1}, f[3] = {s0[0] + side[0], s0[1] + side[1], z0};
        s.quad(a, b, c, f);  // CCW seen from above
    }
    const std::vector<uint32_t> stick = {0, 0, 1, 1, 2, 2};
    std::vector<uint32_t> grouped(6);
    tipsify_clusters(grouped.data(), s.indices.data(), s.indices.size(), s.vertex_count(), stick.data(), 3);
    OverdrawGraphSettings graph;
    graph.resolution = 128;
    const std::vector<Arc> arcs =
        build_overdraw_graph(s.indices.data(), s.indices.size(), s.positions.data(), 1, s.vertex_count(), nullptr, 0,
                             stick.data(), 3, grouped.data(), graph);
    ASSERT_EQ(arcs.size(), 3u);
    uint64_t lightest = std::numeric_limits<uint64_t>::max();
    for (const Arc& arc : arcs) {
        EXPECT_EQ(arc.to, (arc.from + 1) % 3) << "a cycle 0→1→2→0";
        lightest = std::min(lightest, arc.weight);
    }
    const std::vector<uint32_t> order = fas(3, arcs);
    const FeedbackArcs violated = feedback(order, arcs);
    EXPECT_EQ(violated.count, 1u);
    EXPECT_EQ(violated.weight, lightest);
    std::printf("cycle weights: %llu %llu %llu, order %u %u %u\n", (unsigned long long)arcs[0].weight,
                (unsigned long long)arcs[1].weight, (unsigned long long)arcs[2].weight, order[0], order[1], order[2]);
}

// ---------------------------------------------------------------------------------------------
// The whole method

TEST(StaticNehab06, IdenticalWithOneOrTwoThreadsAndAutomaticClusters) {
    const AnimatedMesh knot = make_torus_knot(8000);
    Nehab06Settings settings;
    settings.views = 42;
    settings.resolution = 128;
    std::vector<uint32_t> a(knot.triangle_count()), b(knot.triangle_count());
    settings.threads = 1;
    const Nehab06Result ra =
        order_static_nehab06(a.data(), knot.indices.data(), knot.indices.size(), knot.keyframe_positions.data(), 1,
                             knot.vertex_count, nullptr, 0, settings);
    settings.threads = 2;
    const Nehab06Result rb =
        order_static_nehab06(b.data(), knot.indices.data(), knot.indices.size(), knot.keyframe_positions.data(), 1,
                             knot.vertex_count, nullptr, 0, settings);
    EXPECT_TRUE(test::is_permutation_of_iota(a));
    EXPECT_EQ(a, b);
    EXPECT_EQ(ra.cluster_count, rb.cluster_count);
    ASSERT_GE(ra.candidates.size(), 2u);
    ASSERT_EQ(ra.candidates.size(), rb.candidates.size());
    for (size_t i = 0; i < ra.candidates.size(); ++i) EXPECT_EQ(ra.candidates[i].clusters, size_t(2) << i);
    for (size_t i = 0; i < ra.candidates.size(); ++i) EXPECT_EQ(ra.candidates[i].mean_ovr, rb.candidates[i].mean_ovr);
    // The choice is the smallest count within 0.5% of the best mean OVR tried.
    double best = 1e9;
    for (const auto& c : ra.candidates) best = std::min(best, c.mean_ovr);
    size_t expected = 0;
    while (ra.candidates[expected].mean_ovr > best * 1.005) ++expected;
    EXPECT_EQ(ra.cluster_count, ra.candidates[expected].clusters);
}

TEST(StaticNehab06, AutomaticChoiceSearchesPastTheComponentCount) {
    // 40 separate knots: fewer clusters than that are unions of whole knots, whose mean OVR can
    // sit on a plateau; the search must not stop there.
    Soup s;
    const AnimatedMesh knot = make_torus_knot(300);
    for (int i = 0; i < 40; ++i) s.add(knot, 0.4f, float(i % 8), float(i / 8), 0.3f * float(i % 3));
    Nehab06Settings settings;
    settings.views = 12;
    settings.resolution = 64;
    std::vector<uint32_t> order(s.triangles());
    const Nehab06Result r = order_static_nehab06(order.data(), s.indices.data(), s.indices.size(), s.positions.data(),
                                                 1, s.vertex_count(), nullptr, 0, settings);
    EXPECT_TRUE(test::is_permutation_of_iota(order));
    ASSERT_FALSE(r.candidates.empty());
    EXPECT_GE(r.candidates.back().clusters, 32u);
}

TEST(StaticNehab06, BeatsSander07AndTipsifyOnTheBundledCharacter) {
    const AnimatedMesh mesh = make_procedural_character();
    StaticMethodSettings settings;
    const StaticMethodResult original = run_static_method(mesh, StaticMethod::Original, settings);
    const StaticMethodResult sander = run_static_method(mesh, StaticMethod::StaticSander07, settings);
    const StaticMethodResult nehab = run_static_method(mesh, StaticMethod::StaticNehab06, settings);
    settings.nehab_all_keyframes = true;
    const StaticMethodResult nehab_all = run_static_method(mesh, StaticMethod::StaticNehab06, settings);
    EXPECT_TRUE(test::same_triangles_same_winding(mesh.indices, nehab.indices));
    EXPECT_TRUE(test::is_permutation_of_iota(nehab.order));

    EvaluationSettings evaluation;
    evaluation.views = 40;
    evaluation.resolution = 256;
    auto fixed = [](const std::vector<uint32_t>& order) {
        MethodBuffers b;
        b.orders.push_back(order);
        return b;
    };
    const auto r = evaluate_methods(
        mesh, {fixed(original.order), fixed(sander.order), fixed(nehab.order), fixed(nehab_all.order)}, evaluation);
    const double acmr_original = analyze_mesh_vertex_cache(mesh, original.indices).acmr;
    const double acmr_sander = analyze_mesh_vertex_cache(mesh, sander.indices).acmr;
    const double acmr_nehab = analyze_mesh_vertex_cache(mesh, nehab.indices).acmr;
    const double acmr_nehab_all = analyze_mesh_vertex_cache(mesh, nehab_all.indices).acmr;
    std::printf(
        "character, 40 random views × every keyframe, 256²: mean OVR / ACMR\n"
        "  original        %.4f / %.3f\n  static-sander07 %.4f / %.3f\n"
        "  static-nehab06  %.4f / %.3f (%zu clusters)\n  nehab06 all kf  %.4f / %.3f (%zu clusters)\n",
        r[0].overall.ovr_mean, acmr_original, r[1].overall.ovr_mean, acmr_sander, r[2].overall.ovr_mean, acmr_nehab,
        nehab.patch_count, r[3].overall.ovr_mean, acmr_nehab_all, nehab_all.patch_count);
    EXPECT_LT(r[2].overall.ovr_mean, r[1].overall.ovr_mean);
    EXPECT_LT(r[2].overall.ovr_mean, r[0].overall.ovr_mean);
    EXPECT_LT(r[3].overall.ovr_mean, r[1].overall.ovr_mean);
    // Clusters are Tipsified inside: the vertex cache stays within the automatic choice's budget
    // of Tipsify's, and below static-sander07's.
    EXPECT_LT(acmr_nehab, acmr_original * 1.25);
    EXPECT_LT(acmr_nehab, acmr_sander);
}

TEST(StaticNehab06, BadInputThrows) {
    const Soup s = cube();
    std::vector<uint32_t> order(12);
    Nehab06Settings settings;
    auto run = [&](const Nehab06Settings& x, const uint32_t* keyframes = nullptr, size_t keyframes_count = 0,
                   const float* positions = nullptr, size_t vertex_count = 8) {
        return order_static_nehab06(order.data(), s.indices.data(), s.indices.size(),
                                    positions ? positions : s.positions.data(), 1, vertex_count, keyframes,
                                    keyframes_count, x);
    };
    Nehab06Settings bad = settings;
    bad.views = 100;
    EXPECT_THROW(run(bad), InvalidInput);
    bad = settings;
    bad.resolution = 0;
    EXPECT_THROW(run(bad), InvalidInput);
    bad = settings;
    bad.clusters = kMaxNehabClusters + 1;
    EXPECT_THROW(run(bad), InvalidInput);
    bad = settings;
    bad.cache_size = 2;
    EXPECT_THROW(run(bad), InvalidInput);
    const uint32_t missing_keyframe = 1;
    EXPECT_THROW(run(settings, &missing_keyframe, 1), InvalidInput);
    EXPECT_THROW(run(settings, nullptr, 0, nullptr, 7), InvalidInput);  // index 7 out of range
    std::vector<float> nan = s.positions;
    nan[5] = std::numeric_limits<float>::infinity();
    EXPECT_THROW(run(settings, nullptr, 0, nan.data()), InvalidInput);
    EXPECT_THROW(
        order_static_nehab06(order.data(), s.indices.data(), s.indices.size(), nullptr, 0, 8, nullptr, 0, settings),
        InvalidInput);
    EXPECT_THROW(parse_static_method("static-nehab"), InvalidInput);
    EXPECT_EQ(parse_static_method("static-nehab06"), StaticMethod::StaticNehab06);
    EXPECT_STREQ(method_name(StaticMethod::StaticNehab06), "static-nehab06");
    // Empty input is a no-op.
    EXPECT_EQ(order_static_nehab06(nullptr, nullptr, 0, nullptr, 0, 0, nullptr, 0, settings).cluster_count, 0u);
}

TEST(StaticNehab06, DoubleSidedTrianglesAreMeasuredWithoutCulling) {
    // Two unit quads one above the other, A at z = 0 facing +z and B at z = 1 facing −z. Culled,
    // every view sees at most one of them (the one facing it): no pixel is ever drawn twice and
    // every candidate's mean OVR is exactly 1. Double-sided (kDrawBothFaces), the views from
    // above see B over A and those from below A over B; the views are symmetric, so one static
    // order overdraws on one side: the mean OVR is above 1.
    Soup s;
    const float a0[3] = {0, 0, 0}, a1[3] = {1, 0, 0}, a2[3] = {1, 1, 0}, a3[3] = {0, 1, 0};
    const float b0[3] = {0, 0, 1}, b1[3] = {0, 1, 1}, b2[3] = {1, 1, 1}, b3[3] = {1, 0, 1};
    s.quad(a0, a1, a2, a3);
    s.quad(b0, b1, b2, b3);
    Nehab06Settings settings;
    settings.views = 42;
    settings.resolution = 64;
    std::vector<uint32_t> order(s.triangles());
    const Nehab06Result culled = order_static_nehab06(order.data(), s.indices.data(), s.indices.size(),
                                                      s.positions.data(), 1, s.vertex_count(), nullptr, 0, settings);
    ASSERT_FALSE(culled.candidates.empty());
    for (const Nehab06Candidate& c : culled.candidates) EXPECT_EQ(c.mean_ovr, 1.0) << c.clusters << " clusters";
    const std::vector<uint8_t> both(s.triangles(), kDrawBothFaces);
    settings.triangle_modes = both.data();
    const Nehab06Result drawn = order_static_nehab06(order.data(), s.indices.data(), s.indices.size(),
                                                     s.positions.data(), 1, s.vertex_count(), nullptr, 0, settings);
    EXPECT_TRUE(test::is_permutation_of_iota(order));
    ASSERT_FALSE(drawn.candidates.empty());
    for (const Nehab06Candidate& c : drawn.candidates) EXPECT_GT(c.mean_ovr, 1.0) << c.clusters << " clusters";
}
