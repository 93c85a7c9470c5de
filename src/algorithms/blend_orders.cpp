// Back-to-front orders for blended primitives from a k-means run's clusters (issue 18).
//
// Blended geometry is right only when each pixel's fragments arrive farthest first. The clusters
// of Han & Sander's k-means group nodes that see the character from nearby directions at similar
// poses; within a cluster, the triangles of a blended primitive sorted by their distance to the
// eye summed over the cluster's nodes, farthest first, is the order that is back to front for
// the cluster as a whole: the integrated-distance update of JCGT 2017 with the sort reversed, at
// triangle granularity (Tipsify patches span several hair cards, so sorting patches would leave
// the cards of one patch in cache order).
//
// That sort is only the start: centroid distance orders a card by its middle, while two
// overlapping cards are mis-sorted by where they overlap. measured_blended_orders replaces it by
// the order that minimises the fragment pairs the cluster's own nodes count as mis-sorted (the
// measured graph and feedback-arc-set search of measured_order.cpp, triangles as units): on the
// bundled character it took k = 5 buffers from less than two thirds of the way to the per-node
// centroid sort past it (RESULTS.md "Materials").
#include "animorder/blend_orders.h"

#include "animorder/camera.h"
#include "animorder/clustering.h"
#include "animorder/invalid_input.h"
#include "animorder/measured_order.h"
#include "animorder/overdraw.h"
#include "animorder/rasterizer.h"
#include "animorder/triangle_order.h"
#include "../support/worker_threads.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <map>
#include <string>

namespace animorder {
namespace {

// Units of the measured blend order: the blended triangles (unit u ↔ triangle triangle_of[u]),
// grouped by blended primitive (group = its rank among the blended primitives, ascending in
// mesh.primitives order, so that groups keep the primitives' order).
struct BlendUnits {
    std::vector<uint32_t> unit_of_triangle;  // per triangle; 0 for opaque ones (never in BlendFragments)
    std::vector<uint32_t> triangle_of, group;
};

BlendUnits blend_units(const AnimatedMesh& mesh) {
    BlendUnits u;
    u.unit_of_triangle.assign(mesh.triangle_count(), 0);
    uint32_t g = 0;
    for (const Primitive& p : mesh.primitives) {
        if (p.alpha_mode != AlphaMode::Blend || p.index_count == 0) continue;
        for (size_t t = p.first_index / 3; t < (p.first_index + p.index_count) / 3; ++t) {
            u.unit_of_triangle[t] = uint32_t(u.triangle_of.size());
            u.triangle_of.push_back(uint32_t(t));
            u.group.push_back(g);
        }
        ++g;
    }
    return u;
}

}  // namespace

std::vector<BlendFragments> blend_fragments_of_nodes(const AnimatedMesh& mesh, const Framing& framing,
                                                     const ClusteringResult& run, unsigned resolution,
                                                     unsigned threads) {
    const size_t views = run.directions.size() / 3, node_count = run.assignment.size();
    if (views == 0 || node_count != views * run.keyframes.size())
        throw InvalidInput("a clustering run's assignment does not cover its nodes");
    validate_indices(mesh.indices.data(), mesh.indices.size(), mesh.vertex_count);  // once, not once a node
    const std::vector<uint8_t> blended = blended_triangles(mesh);
    const std::vector<uint8_t> modes = full_pass_modes(mesh);
    std::vector<BlendFragments> kept(node_count);
    struct Worker {
        NodeRasterizer rasterizer;
        CentredKeyframe centred;  // the keyframe last drawn's
    };
    tbb::enumerable_thread_specific<Worker> workers;
    tbb::task_arena arena(worker_threads(threads));
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, node_count, 1), [&](const tbb::blocked_range<size_t>& range) {
            Worker& w = workers.local();
            for (size_t n = range.begin(); n != range.end(); ++n) {
                const uint32_t keyframe = run.keyframes[n / views];
                w.centred.centre(mesh.keyframe(keyframe), mesh.vertex_count, &framing.centres[3 * size_t(keyframe)]);
                w.rasterizer.rasterize_validated(
                    w.centred.vertices(node_view_projection(&run.directions[3 * (n % views)], framing.radius)),
                    mesh.vertex_count, mesh.indices.data(), mesh.indices.size(), resolution,
                    modes.empty() ? nullptr : modes.data());
                kept[n] = w.rasterizer.export_blend_fragments(blended.data());
            }
        });
    });
    return kept;
}

void measured_blended_orders(const AnimatedMesh& mesh, const std::vector<BlendFragments>& nodes,
                             const std::vector<uint32_t>& assignment, std::vector<std::vector<uint32_t>>& orders,
                             unsigned threads) {
    if (nodes.size() != assignment.size()) throw InvalidInput("blend fragments do not match the run's nodes");
    const BlendUnits units = blend_units(mesh);
    if (units.triangle_of.empty()) return;
    // BlendFragments lists each pixel's triangles nearest first with tie bits, as NodeFragments.
    std::vector<NodeFragments> as_nodes(nodes.size());
    for (size_t n = 0; n < nodes.size(); ++n) {
        as_nodes[n].starts = nodes[n].starts;
        as_nodes[n].fragments = nodes[n].fragments;
    }
    for (size_t c = 0; c < orders.size(); ++c) {
        std::vector<const NodeFragments*> mine;
        for (size_t n = 0; n < assignment.size(); ++n)
            if (assignment[n] == c) mine.push_back(&as_nodes[n]);
        if (mine.empty()) continue;
        std::vector<uint32_t>& order = orders[c];
        if (order.size() != mesh.triangle_count()) throw InvalidInput("a run's order does not cover the mesh");
        // w(a→b): pixels where a is nearer than b, so a should come *after* b; the feedback arc
        // set order puts `from` first, i.e. nearest first: reversed below.
        const std::vector<Arc> arcs =
            measured_overdraw_graph(mine.data(), mine.size(), units.unit_of_triangle.data(),
                                    units.unit_of_triangle.size(), units.triangle_of.size(), units.group.data(), threads);
        // The current order (back to front), reversed, as the start to beat.
        std::vector<uint32_t> previous;
        previous.reserve(units.triangle_of.size());
        for (const Primitive& p : mesh.primitives) {
            if (p.alpha_mode != AlphaMode::Blend || p.index_count == 0) continue;
            for (size_t i = (p.first_index + p.index_count) / 3; i-- > p.first_index / 3;)
                previous.push_back(units.unit_of_triangle[order[i]]);
        }
        const std::vector<uint32_t> nearest_first = measured_unit_order(
            units.triangle_of.size(), arcs.data(), arcs.size(), units.group.data(), previous.data());
        size_t at = 0;
        for (const Primitive& p : mesh.primitives) {
            if (p.alpha_mode != AlphaMode::Blend || p.index_count == 0) continue;
            const size_t count = p.index_count / 3;
            for (size_t i = 0; i < count; ++i)
                order[p.first_index / 3 + i] = units.triangle_of[nearest_first[at + count - 1 - i]];
            at += count;
        }
    }
}

void blended_orders_from_clusters(const AnimatedMesh& mesh, const Framing& all_keyframes, float radius,
                                  ClusteringResult& run) {
    const size_t views = run.directions.size() / 3, keyframes = run.keyframes.size();
    if (views == 0 || run.assignment.size() != views * keyframes)
        throw InvalidInput("a clustering run's assignment does not cover its nodes");
    for (const Primitive& p : mesh.primitives) {
        if (p.alpha_mode != AlphaMode::Blend || p.index_count == 0) continue;
        const size_t first = p.first_index / 3, count = p.index_count / 3;
        // Centroids of the primitive's triangles at every keyframe of the run, framed.
        std::vector<float> centroids(keyframes * count * 3);
        for (size_t i = 0; i < keyframes; ++i) {
            const uint32_t k = run.keyframes[i];
            if (size_t(k) * 3 + 2 >= all_keyframes.centres.size()) throw InvalidInput("a run names a missing keyframe");
            const float* positions = mesh.keyframe(k);
            const float* centre = &all_keyframes.centres[3 * size_t(k)];
            for (size_t t = 0; t < count; ++t)
                for (int d = 0; d < 3; ++d) {
                    const uint32_t* v = &mesh.indices[3 * (first + t)];
                    centroids[(i * count + t) * 3 + d] =
                        (positions[3 * v[0] + d] + positions[3 * v[1] + d] + positions[3 * v[2] + d]) / 3.0f -
                        centre[d];
                }
        }
        for (size_t c = 0; c < run.triangle_orders.size(); ++c) {
            std::vector<uint32_t> rows;
            std::vector<float> eyes;
            for (size_t n = 0; n < run.assignment.size(); ++n) {
                if (run.assignment[n] != c) continue;
                rows.push_back(uint32_t(n / views));
                for (int d = 0; d < 3; ++d) eyes.push_back(3.0f * radius * run.directions[3 * (n % views) + d]);
            }
            if (rows.empty()) continue;
            const std::vector<uint32_t> nearest_first = integrated_distance_order(
                centroids.data(), keyframes, count, rows.data(), eyes.data(), rows.size(), DistanceVariant::Jcgt);
            std::vector<uint32_t>& order = run.triangle_orders[c];
            if (order.size() != mesh.triangle_count()) throw InvalidInput("a run's order does not cover the mesh");
            for (size_t i = 0; i < count; ++i) order[first + i] = uint32_t(first + nearest_first[count - 1 - i]);
        }
    }
}

BlendClustering cluster_blend_nodes(const AnimatedMesh& mesh, const Framing& framing, const ClusteringResult& run,
                                    unsigned resolution, unsigned threads, size_t max_iterations) {
    const size_t views = run.directions.size() / 3, node_count = run.assignment.size();
    const size_t k = run.triangle_orders.size(), triangles = mesh.triangle_count();
    if (views == 0 || node_count != views * run.keyframes.size() || k == 0)
        throw InvalidInput("a clustering run's assignment does not cover its nodes");
    // Every node's transparent pass, once.
    const std::vector<BlendFragments> kept = blend_fragments_of_nodes(mesh, framing, run, resolution, threads);
    tbb::task_arena arena(worker_threads(threads));

    BlendClustering best;
    for (const BlendFragments& f : kept) best.covered += f.covered;
    ClusteringResult current = run;  // its triangle_orders and assignment evolve
    uint64_t best_cost = UINT64_MAX;
    std::vector<uint64_t> cost(node_count * k);
    for (size_t iteration = 0; iteration <= max_iterations; ++iteration) {
        blended_orders_from_clusters(mesh, framing, framing.radius, current);  // update
        measured_blended_orders(mesh, kept, current.assignment, current.triangle_orders, threads);
        std::vector<const uint32_t*> pointers;
        for (const auto& o : current.triangle_orders) pointers.push_back(o.data());
        const std::vector<uint32_t> ranks = make_rank_table(pointers, triangles);
        arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, node_count, 16),
                              [&](const tbb::blocked_range<size_t>& range) {
                                  std::vector<BlendCounts> counts(k);
                                  for (size_t n = range.begin(); n != range.end(); ++n) {
                                      score_blend(counts.data(), kept[n], ranks.data(), k);
                                      for (size_t c = 0; c < k; ++c) cost[n * k + c] = counts[c].missorted_pixels;
                                  }
                              });
        });
        // The cost of these orders with the assignment that produced them, then the reassignment.
        uint64_t total = 0;
        for (size_t n = 0; n < node_count; ++n) total += cost[n * k + current.assignment[n]];
        best.missorted_pixels.push_back(total);
        if (total < best_cost) {
            best_cost = total;
            best.orders = current.triangle_orders;
            best.assignment = current.assignment;
        }
        size_t moved = 0;
        for (size_t n = 0; n < node_count; ++n) {
            uint32_t choice = 0;
            for (uint32_t c = 1; c < k; ++c)
                if (cost[n * k + c] < cost[n * k + choice]) choice = c;
            if (cost[n * k + choice] == cost[n * k + current.assignment[n]])
                choice = current.assignment[n];  // stay on ties
            moved += choice != current.assignment[n];
            current.assignment[n] = choice;
        }
        if (moved == 0) break;
    }
    return best;
}

void combine_with_blend_clusters(const AnimatedMesh& mesh, const BlendClustering& blend, ClusteringResult& run) {
    if (blend.assignment.size() != run.assignment.size())
        throw InvalidInput("blend clusters do not match the run's nodes");
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> pairs;
    for (size_t n = 0; n < run.assignment.size(); ++n) pairs[{run.assignment[n], blend.assignment[n]}] = 0;
    if (pairs.size() > kMaxClusters)
        throw InvalidInput("more than " + std::to_string(kMaxClusters) + " buffers per clip");
    std::vector<std::vector<uint32_t>> orders;
    for (auto& [pair, index] : pairs) {
        index = uint32_t(orders.size());
        std::vector<uint32_t> order = run.triangle_orders.at(pair.first);
        const std::vector<uint32_t>& from = blend.orders.at(pair.second);
        for (const Primitive& p : mesh.primitives)
            if (p.alpha_mode == AlphaMode::Blend)
                std::copy(from.begin() + ptrdiff_t(p.first_index / 3),
                          from.begin() + ptrdiff_t((p.first_index + p.index_count) / 3),
                          order.begin() + ptrdiff_t(p.first_index / 3));
        orders.push_back(std::move(order));
    }
    for (size_t n = 0; n < run.assignment.size(); ++n)
        run.assignment[n] = pairs[{run.assignment[n], blend.assignment[n]}];
    run.triangle_orders = std::move(orders);
}

}  // namespace animorder
