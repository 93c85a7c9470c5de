// Measured orders checked on held-out views (held_out_choice.h).
//
// This follows: Han & Sander, "Triangle Reordering for Efficient Rendering in Complex Scenes",
// JCGT 2017, Algorithm 1 lines 20–24 (the integrated-distance update, the candidate every cluster
// can fall back to), and the usual hold-out check of a model fitted to samples: an order measured
// at the clustering views is kept where it also serves views it never saw at least as well.
#include "animorder/held_out_choice.h"

#include "animorder/invalid_input.h"
#include "animorder/measured_order.h"
#include "animorder/kept_fragments.h"
#include "animorder/overdraw.h"

#include "../support/worker_threads.h"
#include "measured_update.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <string>

namespace animorder {

namespace {

// Throws InvalidInput unless the run's assignment covers its nodes and names its clusters.
void check_run(const ClusteringResult& run) {
    const size_t k = run.triangle_orders.size(), keyframes = run.keyframes.size();
    const size_t views = run.directions.size() / 3;
    if (run.assignment.size() != keyframes * views)
        throw InvalidInput("held-out choice: the run assigns " + std::to_string(run.assignment.size()) +
                           " nodes, not " + std::to_string(keyframes) + " × " + std::to_string(views));
    for (const uint32_t c : run.assignment)
        if (c >= k)
            throw InvalidInput("held-out choice: a node of cluster " + std::to_string(c) + " of " + std::to_string(k));
}

// Clustering node n of the run: keyframes[n / views] seen from directions[n % views].
OverdrawNode clustering_node(const ClusteringResult& run, size_t n) {
    const size_t views = run.directions.size() / 3;
    OverdrawNode node;
    node.keyframe = run.keyframes[n / views];
    std::copy(&run.directions[3 * (n % views)], &run.directions[3 * (n % views)] + 3, node.direction);
    return node;
}

// The opaque pass at the run's resolution, as the evaluation scores it (modes must outlive it).
ScoreSettings opaque_pass(const std::vector<uint8_t>& modes, unsigned resolution, unsigned threads) {
    ScoreSettings score;
    score.resolution = resolution;
    score.threads = threads;
    score.triangle_modes = modes.empty() ? nullptr : modes.data();
    return score;
}

}  // namespace

size_t held_out_views_per_keyframe(size_t keyframes) {
    if (keyframes == 0) return 0;
    return std::clamp<size_t>((600 + keyframes - 1) / keyframes, 12, 162);
}

std::vector<std::vector<uint32_t>> distance_cluster_orders(const AnimatedMesh& mesh, const MeshPatches& patches,
                                                           const Framing& framing, const ClusteringResult& run) {
    const size_t k = run.triangle_orders.size(), keyframes = run.keyframes.size();
    const size_t views = run.directions.size() / 3;
    check_run(run);
    // The centroids of the run's keyframes (framed), and each cluster's nodes and eyes.
    const std::vector<float> centroids = patch_centroids(mesh, patches, framing, run.keyframes);
    std::vector<std::vector<uint32_t>> rows(k);
    std::vector<std::vector<float>> eyes(k);
    for (size_t n = 0; n < run.assignment.size(); ++n) {
        const uint32_t c = run.assignment[n];
        rows[c].push_back(uint32_t(n / views));
        for (int a = 0; a < 3; ++a) eyes[c].push_back(3.0f * framing.radius * run.directions[3 * (n % views) + a]);
    }
    std::vector<std::vector<uint32_t>> orders(k);
    for (size_t c = 0; c < k; ++c) {
        if (rows[c].empty()) continue;
        orders[c] = patch_order_to_triangle_order(
            patches, integrated_distance_order(centroids.data(), keyframes, patches.patch_count(), rows[c].data(),
                                               eyes[c].data(), rows[c].size(), DistanceVariant::Jcgt, nullptr,
                                               patches.patch_primitive.data()));
    }
    return orders;
}

std::vector<std::vector<uint32_t>> measured_cluster_orders(const AnimatedMesh& mesh, const MeshPatches& units,
                                                           const Framing& framing, const ClusteringResult& run,
                                                           unsigned resolution, unsigned threads, size_t stride,
                                                           uint32_t front_levels) {
    check_run(run);
    if (stride == 0) throw InvalidInput("measured cluster orders: a stride of 0 nodes");
    const size_t k = run.triangle_orders.size();
    const std::vector<uint32_t> unit_of_triangle =
        make_unit_partition(units.patch_starts.data(), units.patch_count(), units.cache_order.data(),
                            mesh.triangle_count())
            .unit_of_triangle;
    // Every stride-th node of each cluster, in node order.
    std::vector<std::vector<OverdrawNode>> nodes(k);
    std::vector<size_t> seen(k, 0);
    for (size_t n = 0; n < run.assignment.size(); ++n) {
        const uint32_t c = run.assignment[n];
        if (seen[c]++ % stride == 0) nodes[c].push_back(clustering_node(run, n));
    }
    const std::vector<uint8_t> modes = opaque_pass_modes(mesh);
    std::vector<std::vector<uint32_t>> orders(k);
    // The clusters side by side, each counted by one worker straight into its own graph.
    tbb::task_arena arena(worker_threads(threads));
    const uint64_t workers = uint64_t(arena.max_concurrency());
    arena.execute([&] {
        tbb::parallel_for(size_t(0), k, [&](size_t c) {
            if (nodes[c].empty()) return;
            const ScoreSettings score = opaque_pass(modes, resolution, 1);
            MeasuredPairCounts graph(units.patch_count(), unit_of_triangle.data(), unit_of_triangle.size(),
                                     units.patch_primitive.data(), front_levels);
            // Full fragment lists a chunk at a time, about kTransientFragmentBytes per worker: one node
            // first, then as many as the nodes so far say fit (a node at 4096² is hundreds of MB).
            uint64_t bytes = 0;
            for (size_t begin = 0, count = 1; begin < nodes[c].size(); begin += count) {
                if (begin > 0)
                    count = std::clamp<size_t>(size_t(kTransientFragmentBytes * begin / (bytes * workers + 1)), 1, 64);
                count = std::min(count, nodes[c].size() - begin);
                const std::vector<NodeFragments> fragments = rasterize_nodes(
                    mesh.keyframe_positions.data(), mesh.vertex_count, framing, mesh.indices.data(),
                    mesh.indices.size(), nodes[c].data() + begin, count, score, SIZE_MAX);
                std::vector<const NodeFragments*> pointers;
                for (const NodeFragments& f : fragments) {
                    pointers.push_back(&f);
                    bytes += f.bytes();
                }
                graph.add(pointers.data(), pointers.size(), +1, 1);
            }
            const std::vector<uint32_t> order = measured_unit_order(graph, nullptr);
            orders[c] = patch_order_to_triangle_order(units, order);
        });
    });
    return orders;
}

HeldOutChoice choose_on_held_out_views(const AnimatedMesh& mesh, const Framing& framing, unsigned resolution,
                                       unsigned threads, ClusteringResult& run,
                                       std::vector<std::vector<uint32_t>> alternatives) {
    const size_t k = run.triangle_orders.size(), keyframes = run.keyframes.size();
    const size_t views = run.directions.size() / 3;
    HeldOutChoice choice;
    choice.taken.assign(k, 0);
    if (k < 1 || keyframes == 0 || views == 0) return choice;
    check_run(run);
    if (alternatives.size() != k)
        throw InvalidInput("held-out choice: " + std::to_string(alternatives.size()) + " alternatives for " +
                           std::to_string(k) + " clusters");
    for (const auto& a : alternatives)
        if (!a.empty() && a.size() != mesh.triangle_count())
            throw InvalidInput("held-out choice: an alternative order of " + std::to_string(a.size()) +
                               " triangles, the mesh has " + std::to_string(mesh.triangle_count()));

    // The held-out nodes and the cluster whose buffer each is drawn with.
    const size_t held_views = held_out_views_per_keyframe(keyframes);
    const std::vector<float> directions = random_sphere_directions(held_views, kHeldOutSeed);
    std::vector<OverdrawNode> nodes(keyframes * held_views);
    std::vector<uint32_t> cluster(nodes.size());
    for (size_t i = 0; i < keyframes; ++i)
        for (size_t v = 0; v < held_views; ++v) {
            OverdrawNode& node = nodes[i * held_views + v];
            node.keyframe = run.keyframes[i];
            std::copy(&directions[3 * v], &directions[3 * v] + 3, node.direction);
            size_t nearest = 0;
            double best = -2.0;
            for (size_t u = 0; u < views; ++u) {
                const float* d = &run.directions[3 * u];
                const double dot = double(d[0]) * node.direction[0] + double(d[1]) * node.direction[1] +
                                   double(d[2]) * node.direction[2];
                if (dot > best) best = dot, nearest = u;
            }
            cluster[i * held_views + v] = run.assignment[i * views + nearest];
        }

    // Every node scored with the k current buffers and the k alternatives (a cluster without an
    // alternative scores its buffer twice: never changed).
    std::vector<const uint32_t*> orders;
    for (size_t c = 0; c < k; ++c) orders.push_back(run.triangle_orders[c].data());
    for (size_t c = 0; c < k; ++c) orders.push_back(alternatives[c].empty() ? run.triangle_orders[c].data() : alternatives[c].data());
    const std::vector<uint32_t> ranks = make_rank_table(orders, mesh.triangle_count());
    const std::vector<uint8_t> modes = opaque_pass_modes(mesh);
    const ScoreSettings score = opaque_pass(modes, resolution, threads);
    std::vector<uint64_t> visible(nodes.size()), passed(nodes.size() * 2 * k);
    score_nodes(visible.data(), passed.data(), mesh.keyframe_positions.data(), mesh.vertex_count, framing,
                mesh.indices.data(), mesh.indices.size(), nodes.data(), nodes.size(), ranks.data(), 2 * k, score);

    std::vector<uint64_t> current(k, 0), alternative(k, 0);
    for (size_t n = 0; n < nodes.size(); ++n) {
        current[cluster[n]] += passed[n * 2 * k + cluster[n]];
        alternative[cluster[n]] += passed[n * 2 * k + k + cluster[n]];
        choice.visible += visible[n];
    }
    choice.nodes = nodes.size();
    bool switched = false;
    for (size_t c = 0; c < k; ++c) {
        choice.current_passed += current[c];
        if (!alternatives[c].empty() && alternative[c] < current[c]) {
            choice.taken[c] = 1;
            switched = true;
            run.triangle_orders[c] = std::move(alternatives[c]);
            choice.chosen_passed += alternative[c];
        } else {
            choice.chosen_passed += current[c];
        }
    }
    if (!switched || k < 2) return choice;

    // The clusters were formed around the measured orders: every clustering node goes to the
    // buffer, of the k now kept, that passes the fewest of its fragments (k-means' assignment
    // step, rasterising the nodes once more; ties keep the node's cluster, then the lower one).
    std::vector<OverdrawNode> learnt(keyframes * views);
    for (size_t n = 0; n < learnt.size(); ++n) learnt[n] = clustering_node(run, n);
    orders.clear();
    for (size_t c = 0; c < k; ++c) orders.push_back(run.triangle_orders[c].data());
    const std::vector<uint32_t> kept_ranks = make_rank_table(orders, mesh.triangle_count());
    std::vector<uint64_t> learnt_visible(learnt.size()), learnt_passed(learnt.size() * k);
    score_nodes(learnt_visible.data(), learnt_passed.data(), mesh.keyframe_positions.data(), mesh.vertex_count,
                framing, mesh.indices.data(), mesh.indices.size(), learnt.data(), learnt.size(), kept_ranks.data(), k,
                score);
    for (size_t n = 0; n < learnt.size(); ++n) {
        const uint64_t* p = &learnt_passed[n * k];
        uint32_t best = run.assignment[n];
        for (uint32_t c = 0; c < k; ++c)
            if (p[c] < p[best]) best = c;
        choice.reassigned += best != run.assignment[n];
        run.assignment[n] = best;
    }
    // A buffer no node draws any more is dropped and the others renumbered, as k-means' own
    // finish does: a table never names it, so it would only be bytes in the file.
    std::vector<uint32_t> renumbered(k, UINT32_MAX);
    for (const uint32_t c : run.assignment) renumbered[c] = 0;
    size_t kept = 0;
    for (size_t c = 0; c < k; ++c) {
        if (renumbered[c] == UINT32_MAX) continue;
        renumbered[c] = uint32_t(kept);
        if (kept != c) {  // (a vector moved onto itself is left empty)
            run.triangle_orders[kept] = std::move(run.triangle_orders[c]);
            if (run.patch_orders.size() == k) run.patch_orders[kept] = std::move(run.patch_orders[c]);
            choice.taken[kept] = choice.taken[c];
        }
        ++kept;
    }
    choice.dropped = k - kept;
    run.triangle_orders.resize(kept);
    if (run.patch_orders.size() == k) run.patch_orders.resize(kept);
    choice.taken.resize(kept);
    for (uint32_t& c : run.assignment) c = renumbered[c];
    return choice;
}

}  // namespace animorder
