// Han & Sander k-means: patches of a whole character, the assignment rule checked against an
// independent scoring of the final buffers, OVR that does not rise, convergence, determinism,
// re-seeding of empty clusters.
#include "animorder/animated_mesh.h"
#include "animorder/clustering.h"
#include "animorder/invalid_input.h"
#include "animorder/mesh_patches.h"
#include "animorder/overdraw.h"
#include "animorder/procedural_character.h"
#include "animorder/selection_table.h"
#include "animorder/viewpoints.h"
#include "support/meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace animorder;

namespace {
const AnimatedMesh& character() {
    static const AnimatedMesh mesh = make_procedural_character();
    return mesh;
}

std::vector<uint32_t> walk_keyframes(size_t step) {
    std::vector<uint32_t> k;
    const Clip& walk = character().clips[0];
    for (size_t f = 0; f < walk.keyframe_count; f += step) k.push_back(uint32_t(walk.first_keyframe + f));
    return k;
}

ClusteringSettings small_settings() {
    ClusteringSettings s;
    s.clusters = 3;
    s.views = 42;
    s.resolution = 64;
    s.seed = 7;
    s.max_iterations = 12;
    return s;
}

Framing framing_of(const AnimatedMesh& m) { return frame_animated_mesh(m); }
}  // namespace

TEST(MeshPatches, CoverEveryTriangleWithinItsPrimitive) {
    const AnimatedMesh& m = character();
    const MeshPatches p = build_mesh_patches(m, 0.85);
    EXPECT_TRUE(test::is_permutation_of_iota(p.cache_order));
    ASSERT_EQ(p.patch_starts.size(), p.patch_count() + 1);
    EXPECT_EQ(p.patch_starts.back(), m.triangle_count());
    for (size_t q = 0; q < p.patch_count(); ++q) {
        ASSERT_LT(p.patch_starts[q], p.patch_starts[q + 1]);
        const Primitive& prim = m.primitives[p.patch_primitive[q]];
        for (uint32_t i = p.patch_starts[q]; i < p.patch_starts[q + 1]; ++i) {
            const size_t t = p.cache_order[i];
            EXPECT_GE(3 * t, prim.first_index);
            EXPECT_LT(3 * t, prim.first_index + prim.index_count);
        }
    }
    // The identity patch order is the Tipsify order; a reversed one keeps primitives in file order.
    std::vector<uint32_t> identity(p.patch_count()), reversed(p.patch_count());
    for (size_t q = 0; q < p.patch_count(); ++q)
        identity[q] = uint32_t(q), reversed[q] = uint32_t(p.patch_count() - 1 - q);
    EXPECT_EQ(patch_order_to_triangle_order(p, identity), p.cache_order);
    const std::vector<uint32_t> r = patch_order_to_triangle_order(p, reversed);
    EXPECT_TRUE(test::is_permutation_of_iota(r));
    const size_t body_triangles = m.primitives[0].index_count / 3;
    for (size_t i = 0; i < body_triangles; ++i) EXPECT_LT(r[i], body_triangles);
}

// The measured method's alternative units: planar clusters, as many per primitive as λ's patches
// (fewer only where a cluster came out empty), each a run of its own primitive's triangles.
TEST(MeshPatches, PlanarUnitsCoverEveryTriangleWithinItsPrimitive) {
    const AnimatedMesh& m = character();
    const MeshPatches like = build_mesh_patches(m, 0.85);
    const MeshPatches p = build_planar_units(m, like, 0);
    EXPECT_TRUE(test::is_permutation_of_iota(p.cache_order));
    ASSERT_EQ(p.patch_starts.size(), p.patch_count() + 1);
    EXPECT_EQ(p.patch_starts.back(), m.triangle_count());
    EXPECT_LE(p.patch_count(), like.patch_count());
    EXPECT_GE(p.patch_count(), like.patch_count() * 9 / 10);
    for (size_t q = 0; q < p.patch_count(); ++q) {
        ASSERT_LT(p.patch_starts[q], p.patch_starts[q + 1]);
        if (q > 0) {
            EXPECT_LE(p.patch_primitive[q - 1], p.patch_primitive[q]);
        }
        const Primitive& prim = m.primitives[p.patch_primitive[q]];
        for (uint32_t i = p.patch_starts[q]; i < p.patch_starts[q + 1]; ++i) {
            const size_t t = p.cache_order[i];
            EXPECT_GE(3 * t, prim.first_index);
            EXPECT_LT(3 * t, prim.first_index + prim.index_count);
        }
    }
    EXPECT_THROW(build_planar_units(m, like, m.keyframe_count()), InvalidInput);
}

TEST(Clustering, AssignsEachNodeToItsBestBufferAndImproves) {
    const AnimatedMesh& m = character();
    const MeshPatches patches = build_mesh_patches(m, 0.85);
    const Framing framing = framing_of(m);
    const std::vector<uint32_t> keyframes = walk_keyframes(5);
    const ClusteringSettings settings = small_settings();
    const ClusteringResult r = cluster_nodes(m, patches, framing, keyframes, settings);

    ASSERT_EQ(r.triangle_orders.size(), 3u);
    for (const auto& o : r.triangle_orders) EXPECT_TRUE(test::is_permutation_of_iota(o));
    ASSERT_FALSE(r.iterations.empty());
    // The monotone update (default): the mean node OVR never rises, and k-means settles.
    for (size_t i = 1; i < r.iterations.size(); ++i)
        EXPECT_LE(r.iterations[i].mean_ovr, r.iterations[i - 1].mean_ovr + 1e-12) << "iteration " << i;
    EXPECT_LT(r.iterations.back().mean_ovr, r.iterations.front().mean_ovr);
    EXPECT_TRUE(r.converged) << r.stop_reason;
    EXPECT_EQ(r.stop_reason, "converged");

    // Independent check of the final assignment: score the final buffers at every node again.
    std::vector<const uint32_t*> pointers;
    for (const auto& o : r.triangle_orders) pointers.push_back(o.data());
    const std::vector<uint32_t> ranks = make_rank_table(pointers, m.triangle_count());
    std::vector<OverdrawNode> nodes;
    for (uint32_t k : keyframes)
        for (size_t v = 0; v < settings.views; ++v) {
            OverdrawNode n;
            n.keyframe = k;
            std::copy(&r.directions[3 * v], &r.directions[3 * v] + 3, n.direction);
            nodes.push_back(n);
        }
    std::vector<uint64_t> visible(nodes.size()), passed(nodes.size() * 3);
    ScoreSettings score;
    score.resolution = settings.resolution;
    const std::vector<uint8_t> modes = opaque_pass_modes(m);  // k-means counts the opaque pass (issue 18)
    score.triangle_modes = modes.empty() ? nullptr : modes.data();
    score_nodes(visible.data(), passed.data(), m.keyframe_positions.data(), m.vertex_count, framing, m.indices.data(),
                m.indices.size(), nodes.data(), nodes.size(), ranks.data(), 3, score);
    ASSERT_EQ(r.assignment.size(), nodes.size());
    for (size_t n = 0; n < nodes.size(); ++n) {
        const uint32_t c = r.assignment[n];
        for (uint32_t o = 0; o < 3; ++o) {
            EXPECT_LE(passed[3 * n + c], passed[3 * n + o]) << "node " << n;
            if (o < c) {
                EXPECT_GT(passed[3 * n + o], passed[3 * n + c]) << "tie not given to the lowest id, node " << n;
            }
        }
    }
}

TEST(Clustering, PaperUpdateRunsAndKeepsItsBestIteration) {
    const AnimatedMesh& m = character();
    const MeshPatches patches = build_mesh_patches(m, 0.85);
    ClusteringSettings s = small_settings();
    s.update = UpdateRule::Paper;
    const ClusteringResult r = cluster_nodes(m, patches, framing_of(m), walk_keyframes(5), s);
    ASSERT_FALSE(r.iterations.empty());
    double best = INFINITY;
    for (const auto& it : r.iterations) best = std::min(best, it.mean_ovr);
    EXPECT_DOUBLE_EQ(r.iterations[r.best_iteration].mean_ovr, best);  // the buffers returned are the best seen
    EXPECT_FALSE(r.stop_reason.empty());
}

TEST(Clustering, DeterministicWithOneOrTwoThreadsAndBothDistances) {
    const AnimatedMesh& m = character();
    const MeshPatches patches = build_mesh_patches(m, 0.85);
    const Framing framing = framing_of(m);
    const std::vector<uint32_t> keyframes = walk_keyframes(10);
    for (DistanceVariant d : {DistanceVariant::Jcgt, DistanceVariant::I3d}) {
        ClusteringSettings s = small_settings();
        s.distance = d;
        s.threads = 1;
        const ClusteringResult one = cluster_nodes(m, patches, framing, keyframes, s);
        s.threads = 2;
        const ClusteringResult two = cluster_nodes(m, patches, framing, keyframes, s);
        EXPECT_EQ(one.assignment, two.assignment);
        EXPECT_EQ(one.patch_orders, two.patch_orders);
        EXPECT_EQ(one.iterations.size(), two.iterations.size());
    }
}

// OrderSource::Measured (measured_order.h): the same bootstrap and first assignment as the
// paper's update, then orders from the measured graphs; the mean node OVR never rises, the result
// does not depend on the thread count, and on this character it ends below the distance update's.
TEST(Clustering, MeasuredOrdersAreMonotoneDeterministicAndBelowDistance) {
    const AnimatedMesh& m = character();
    const MeshPatches patches = build_mesh_patches(m, 0.85);
    const Framing framing = framing_of(m);
    const std::vector<uint32_t> keyframes = walk_keyframes(10);
    ClusteringSettings s = small_settings();
    const ClusteringResult distance = cluster_nodes(m, patches, framing, keyframes, s);
    s.order = OrderSource::Measured;
    s.threads = 1;
    const ClusteringResult one = cluster_nodes(m, patches, framing, keyframes, s);
    s.threads = 2;
    const ClusteringResult two = cluster_nodes(m, patches, framing, keyframes, s);
    EXPECT_EQ(one.assignment, two.assignment);
    EXPECT_EQ(one.patch_orders, two.patch_orders);
    ASSERT_FALSE(one.iterations.empty());
    EXPECT_DOUBLE_EQ(one.iterations[0].mean_ovr, distance.iterations[0].mean_ovr);
    for (size_t i = 1; i < one.iterations.size(); ++i)
        EXPECT_LE(one.iterations[i].mean_ovr, one.iterations[i - 1].mean_ovr + 1e-12) << "iteration " << i;
    EXPECT_LT(one.iterations[one.best_iteration].mean_ovr, distance.iterations[distance.best_iteration].mean_ovr);
    for (const auto& o : one.triangle_orders) EXPECT_TRUE(test::is_permutation_of_iota(o));
}

namespace {
// Every buffer of the result is the buffer of some node, and the assignment names only them.
void expect_every_buffer_chosen(const ClusteringResult& r) {
    std::vector<size_t> chosen(r.triangle_orders.size(), 0);
    for (const uint32_t c : r.assignment) {
        ASSERT_LT(c, chosen.size());
        ++chosen[c];
    }
    for (size_t c = 0; c < chosen.size(); ++c) EXPECT_GT(chosen[c], 0u) << "buffer " << c << " is never drawn";
    EXPECT_EQ(r.patch_orders.size(), r.triangle_orders.size());
}
}  // namespace

// Empty clusters are re-seeded while k-means runs; a cluster still empty in the end (more clusters
// than the nodes can fill) writes no buffer, which no node would ever draw.
TEST(Clustering, EmptyClustersAreReseededAndUnchosenBuffersNotWritten) {
    // 12 views of one keyframe and 10 clusters: some clusters must end up empty at first.
    const AnimatedMesh& m = character();
    const MeshPatches patches = build_mesh_patches(m, 0.85);
    ClusteringSettings s = small_settings();
    s.clusters = 10;
    s.views = 12;
    s.min_separation_deg = 10;
    std::vector<std::string> log;
    s.log = [&](const std::string& line) { log.push_back(line); };
    const ClusteringResult r = cluster_nodes(m, patches, framing_of(m), {0}, s);
    size_t reseeded = 0;
    for (const auto& it : r.iterations) reseeded += it.reseeded;
    EXPECT_GT(reseeded, 0u);
    bool logged = false;
    for (const auto& line : log) logged |= line.find("re-seeded") != std::string::npos;
    EXPECT_TRUE(logged);
    EXPECT_LE(r.triangle_orders.size(), 10u);
    expect_every_buffer_chosen(r);
    for (const auto& o : r.triangle_orders) EXPECT_TRUE(test::is_permutation_of_iota(o));

    // More clusters than nodes: at most one buffer per node (k = 20 wrote 20 buffers for 12 nodes).
    s.clusters = 20;
    const ClusteringResult over = cluster_nodes(m, patches, framing_of(m), {0}, s);
    EXPECT_LE(over.triangle_orders.size(), 12u);
    expect_every_buffer_chosen(over);
}

TEST(Clustering, RejectsAbsurdSettings) {
    const AnimatedMesh& m = character();
    const MeshPatches patches = build_mesh_patches(m, 0.85);
    ClusteringSettings s = small_settings();
    s.clusters = 0;
    EXPECT_THROW(cluster_nodes(m, patches, framing_of(m), {0}, s), InvalidInput);
    s = small_settings();
    s.views = 100;
    EXPECT_THROW(cluster_nodes(m, patches, framing_of(m), {0}, s), InvalidInput);
    s = small_settings();
    EXPECT_THROW(cluster_nodes(m, patches, framing_of(m), {}, s), InvalidInput);
}

// cluster_nodes reads the positions of its keyframes only, and build_mesh_patches none (each
// checks what it reads, so a character's clips are not each scanned whole): a position that is
// not finite elsewhere changes nothing; in a listed keyframe it is refused by name.
TEST(Clustering, ReadsAndChecksTheListedKeyframesOnly) {
    const AnimatedMesh& m = character();
    const std::vector<uint32_t> keyframes = walk_keyframes(10);
    const uint32_t unlisted = keyframes[0] + 1;
    AnimatedMesh damaged = m;
    damaged.keyframe_positions[size_t(unlisted) * 3 * m.vertex_count + 4] = NAN;  // vertex 1
    const MeshPatches patches = build_mesh_patches(m, 0.85);
    const MeshPatches damaged_patches = build_mesh_patches(damaged, 0.85);
    EXPECT_EQ(damaged_patches.cache_order, patches.cache_order);
    EXPECT_EQ(damaged_patches.patch_starts, patches.patch_starts);
    const Framing framing = framing_of(m);
    const ClusteringSettings s = small_settings();
    const ClusteringResult clean = cluster_nodes(m, patches, framing, keyframes, s);
    const ClusteringResult r = cluster_nodes(damaged, patches, framing, keyframes, s);
    EXPECT_EQ(r.assignment, clean.assignment);
    EXPECT_EQ(r.patch_orders, clean.patch_orders);
    try {
        cluster_nodes(damaged, patches, framing, {keyframes[0], unlisted}, s);
        FAIL() << "accepted keyframe " << unlisted;
    } catch (const InvalidInput& e) {
        EXPECT_EQ(std::string(e.what()),
                  "keyframe " + std::to_string(unlisted) + ": position of vertex 1 is not finite");
    }
}

// Keyframes that all shrink the mesh to a point (a clip that hides it by scale 0) draw nothing at
// any node and leave no camera to place (R = 0): one buffer, the patches in their own order (the
// cache order), every node on it, no iteration. It threw "view radius must be positive".
TEST(Clustering, KeyframesThatDrawNothingGetOneBufferInTheCacheOrder) {
    AnimatedMesh m = character();
    const std::vector<uint32_t> keyframes = walk_keyframes(10);
    for (uint32_t k : keyframes)
        for (size_t v = 0; v < m.vertex_count; ++v)
            std::copy_n(std::vector<float>{0.5f, -1, 2}.data(), 3, m.keyframe(k) + 3 * v);
    const MeshPatches patches = build_mesh_patches(m, 0.85);
    const Framing framing = frame_subset(framing_of(m), keyframes);
    ASSERT_EQ(framing.radius, 0.0f);
    const ClusteringResult r = cluster_nodes(m, patches, framing, keyframes, small_settings());
    ASSERT_EQ(r.triangle_orders.size(), 1u);
    EXPECT_EQ(r.triangle_orders[0], patches.cache_order);
    EXPECT_EQ(r.assignment, std::vector<uint32_t>(keyframes.size() * 42, 0));
    EXPECT_EQ(r.stop_reason, "nothing drawn");
    EXPECT_TRUE(r.converged);
    EXPECT_TRUE(r.iterations.empty());
    EXPECT_EQ(r.keyframes, keyframes);
}

TEST(SelectionTable, ReturnsTheNodesClusterAtEveryClusteringViewpoint) {
    const AnimatedMesh& m = character();
    const MeshPatches patches = build_mesh_patches(m, 0.85);
    const Clip& walk = m.clips[0];
    std::vector<uint32_t> keyframes;
    for (size_t f = 0; f < walk.keyframe_count; ++f) keyframes.push_back(uint32_t(walk.first_keyframe + f));
    ClusteringSettings s = small_settings();
    s.views = 162;
    s.resolution = 32;
    s.max_iterations = 2;
    const ClusteringResult r = cluster_nodes(m, patches, framing_of(m), keyframes, s);
    const SelectionTable table = build_selection_table(r, walk.first_keyframe, walk.keyframe_count);
    EXPECT_EQ(table.keyframes, walk.keyframe_count);
    for (size_t f = 0; f < walk.keyframe_count; ++f)
        for (size_t v = 0; v < 162; ++v)
            ASSERT_EQ(select_buffer(table, f, &r.directions[3 * v]), r.assignment[f * 162 + v])
                << "keyframe " << f << " view " << v;
    // Directions need not be unit length; keyframes past the end clamp to the last.
    const float scaled[3] = {5 * r.directions[0], 5 * r.directions[1], 5 * r.directions[2]};
    EXPECT_EQ(select_buffer(table, 0, scaled), r.assignment[0]);
    EXPECT_EQ(select_buffer(table, 1000, &r.directions[0]), r.assignment[(walk.keyframe_count - 1) * 162]);
}
