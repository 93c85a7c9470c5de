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
#include <array>
#include <cmath>
#include <cstring>
#include <map>
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

namespace {
// The same mesh with each vertex replaced by the first at the same coordinates (an ordered map
// of the coordinates' bits: a second implementation of build_welded_patches' joining).
AnimatedMesh welded_by_map(const AnimatedMesh& m) {
    std::map<std::array<uint32_t, 3>, uint32_t> first;
    AnimatedMesh welded = m;
    for (uint32_t& v : welded.indices) {
        std::array<uint32_t, 3> key;
        std::memcpy(key.data(), m.keyframe(0) + 3 * size_t(v), sizeof key);
        v = first.emplace(key, v).first->second;  // indices ascend: the first is the lowest id
    }
    return welded;
}
}  // namespace

// A flat-shaded mesh has one λ patch per triangle (no face shares a vertex); its surface patches
// are the patches of the mesh with equal positions joined, and cut into pieces of at most
// max_triangles they stay in the same cache order, each patch in the fewest pieces, sized within
// one triangle of each other.
TEST(MeshPatches, SurfacePatchesOfAFlatShadedMeshAreThoseOfItsJoinedCopyCutIntoPieces) {
    const AnimatedMesh flat = test::flat_shaded(character());
    const MeshPatches degenerate = build_mesh_patches(flat, 0.85);
    EXPECT_GE(degenerate.patch_count(), flat.triangle_count() * 9 / 10);
    const MeshPatches reference = build_mesh_patches(welded_by_map(flat), 0.85);
    const MeshPatches surface = build_welded_patches(flat, 0.85);
    EXPECT_EQ(surface.cache_order, reference.cache_order);
    EXPECT_EQ(surface.patch_starts, reference.patch_starts);
    EXPECT_EQ(surface.patch_primitive, reference.patch_primitive);
    EXPECT_LT(surface.patch_count() * 10, degenerate.patch_count());
    // Pieces: every boundary of a patch of `most` or more triangles is a piece boundary, such a
    // patch is cut in ceil(n / most) pieces sized within one of each other, and the pieces
    // between are whole smaller patches of one primitive, packed: each pack within `most`, and
    // the next small patch of its primitive would not have fitted.
    std::vector<uint32_t> patch_at(flat.triangle_count());  // surface patch of each cache position
    for (size_t p = 0; p < surface.patch_count(); ++p)
        for (uint32_t i = surface.patch_starts[p]; i < surface.patch_starts[p + 1]; ++i) patch_at[i] = uint32_t(p);
    const auto patch_size = [&](size_t p) { return size_t(surface.patch_starts[p + 1] - surface.patch_starts[p]); };
    for (const size_t most : {1u, 3u, 8u}) {
        SCOPED_TRACE("pieces of at most " + std::to_string(most));
        const MeshPatches pieces = build_welded_patches(flat, 0.85, most);
        EXPECT_EQ(pieces.cache_order, surface.cache_order);
        ASSERT_EQ(pieces.patch_starts.size(), pieces.patch_count() + 1);
        ASSERT_EQ(pieces.patch_starts.back(), flat.triangle_count());
        for (size_t q = 0; q < pieces.patch_count(); ++q) {
            const uint32_t begin = pieces.patch_starts[q], end = pieces.patch_starts[q + 1];
            ASSERT_LT(begin, end);
            EXPECT_LE(end - begin, most);
            const size_t p = patch_at[begin];
            EXPECT_EQ(pieces.patch_primitive[q], surface.patch_primitive[p]);
            if (patch_size(p) >= most) {  // a cut of a large patch
                const size_t count = (patch_size(p) + most - 1) / most;
                EXPECT_GE(end - begin, patch_size(p) / count);
                EXPECT_LE(end - begin, (patch_size(p) + count - 1) / count);
                EXPECT_LE(end, surface.patch_starts[p + 1]);
                continue;
            }
            ASSERT_EQ(begin, surface.patch_starts[p]);  // a pack of whole small patches
            size_t last = p;
            while (surface.patch_starts[last + 1] < end) ++last;
            ASSERT_EQ(surface.patch_starts[last + 1], end);
            for (size_t x = p; x <= last; ++x) {
                EXPECT_LT(patch_size(x), most);
                EXPECT_EQ(surface.patch_primitive[x], surface.patch_primitive[p]);
            }
            const size_t next = last + 1;
            if (next < surface.patch_count() && patch_size(next) < most &&
                surface.patch_primitive[next] == surface.patch_primitive[p]) {
                EXPECT_GT(end - begin + patch_size(next), most);
            }
        }
    }
    // At λ = 3 every surface patch is one triangle: the pieces are runs of `most` of them.
    const MeshPatches runs = build_welded_patches(flat, 3.0, 8);
    EXPECT_LT(runs.patch_count() * 7, flat.triangle_count());
    // The joining: a flat-shaded mesh has the smooth one's distinct positions (its seams joined).
    const std::vector<uint32_t> first = joined_vertices(flat);
    size_t distinct = 0;
    for (size_t v = 0; v < first.size(); ++v) {
        distinct += first[v] == v;
        EXPECT_LE(first[v], v);
    }
    EXPECT_LE(2 * distinct, flat.vertex_count);
    // On the smooth character the joining changes little: seams only.
    const MeshPatches smooth = build_mesh_patches(character(), 0.85);
    EXPECT_GT(2 * build_welded_patches(character(), 0.85).patch_count(), smooth.patch_count());
}

// settled_gain: k-means stops at the first iteration (after the first) whose mean OVR is not
// below the previous iteration's by that fraction; the same run without it shows where that is.
TEST(Clustering, SettledGainStopsAtTheFirstIterationThatGainsLess) {
    ClusteringSettings s = small_settings();
    s.order = OrderSource::Measured;
    const auto run = [&s, patches = build_mesh_patches(character(), 0.85)] {
        return cluster_nodes(character(), patches, framing_of(character()), walk_keyframes(5), s);
    };
    const ClusteringResult full = run();
    ASSERT_GE(full.iterations.size(), 3u);
    // The gain of iteration 2 over 1 (0-based 1 over 0), and a fraction just above it.
    const double gain = 1 - full.iterations[1].mean_ovr / full.iterations[0].mean_ovr;
    ASSERT_GT(gain, 0);
    s.settled_gain = gain * 1.01;
    const ClusteringResult settled = run();
    EXPECT_EQ(settled.stop_reason, "settled");
    ASSERT_EQ(settled.iterations.size(), 2u);
    EXPECT_EQ(settled.iterations[1].mean_ovr, full.iterations[1].mean_ovr);
    // Just below it, the run goes on past iteration 2.
    s.settled_gain = gain * 0.99;
    const ClusteringResult on = run();
    EXPECT_GT(on.iterations.size(), 2u);
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
