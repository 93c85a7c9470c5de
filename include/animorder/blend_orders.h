// animorder — orders for blended primitives (issue 18; DESIGN.md "Blend error"): back to front,
// from the clusters of a Han & Sander run. No file I/O here.
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/clustering.h"
#include "animorder/rasterizer.h"
#include "animorder/viewpoints.h"

#include <cstdint>
#include <vector>

namespace animorder {

// For every cluster of a k-means run (run.assignment over run.keyframes × run.directions, eyes at
// 3R · direction with R = framing.radius, centres from framing), the triangles of each blended
// primitive sorted by their integrated distance over the cluster's nodes, farthest first (the
// reversed integrated-distance sort of JCGT 2017's update step, one triangle at a time instead of
// one patch), written into run.triangle_orders in place of that primitive's range. A cluster
// without nodes keeps its order. framing: frame_subset of the run's keyframes (global indices in
// run.keyframes index framing.centres as frame_animated_mesh lays them out: all keyframes).
void blended_orders_from_clusters(const AnimatedMesh& mesh, const Framing& all_keyframes, float radius,
                                  ClusteringResult& run);

// Every node of a run, its transparent pass (BlendFragments): rasterised with every triangle
// (double-sided ones without culling), blended fragments in front of the opaque depth kept.
std::vector<BlendFragments> blend_fragments_of_nodes(const AnimatedMesh& mesh, const Framing& framing,
                                                     const ClusteringResult& run, unsigned resolution,
                                                     unsigned threads);

// Measured blend orders: for every cluster c (nodes n with assignment[n] == c; a cluster without
// nodes keeps its order), each blended primitive's range of orders[c] replaced by the order of its
// triangles that minimises the fragment pairs drawn nearer-before-farther over the cluster's nodes:
// the measured graph of measured_order.h over those nodes' blended fragments (units: the blended
// triangles, one group per primitive; w(a→b) = pixels where a is nearer than b), the greedy
// Eades–Lin–Smyth order or the current order (whichever has fewer mis-sorted pairs) improved by
// sifting, then reversed (back to front). On the cluster's own nodes it never counts more
// mis-sorted pairs than the order it replaces.
void measured_blended_orders(const AnimatedMesh& mesh, const std::vector<BlendFragments>& nodes,
                             const std::vector<uint32_t>& assignment, std::vector<std::vector<uint32_t>>& orders,
                             unsigned threads);

// k-means over the run's nodes with the blend objective (issue 18): each node is rasterised once
// with every triangle (double-sided ones without culling) and keeps its blended fragments in
// front of the opaque depth (BlendFragments); starting from the run's own assignment, each
// cluster's order is the measured blend order over its nodes (measured_blended_orders, started
// from the reversed integrated-distance sort above) and each
// node then takes the order with the fewest mis-sorted pixels (ties: the lower cluster), until
// no node moves or max_iterations. Returns the best iteration's orders (run.triangle_orders with
// their blended ranges replaced; opaque ranges untouched) and assignment.
struct BlendClustering {
    std::vector<std::vector<uint32_t>> orders;
    std::vector<uint32_t> assignment;        // per node, as ClusteringResult::assignment
    std::vector<uint64_t> missorted_pixels;  // per iteration: Σ over nodes with its assigned order
    uint64_t covered = 0;                    // Σ over nodes of the covered pixels
};

BlendClustering cluster_blend_nodes(const AnimatedMesh& mesh, const Framing& framing, const ClusteringResult& run,
                                    unsigned resolution, unsigned threads, size_t max_iterations = 10);

// Replaces a run's clusters by the pairs (opaque cluster, blend cluster) its nodes take: buffer
// i of the result is the opaque order of the pair's first cluster with the blended ranges of
// the second's (pairs in ascending order, only those some node takes), and run.assignment names
// the pair. The runtime table then picks the right buffer for both at once.
void combine_with_blend_clusters(const AnimatedMesh& mesh, const BlendClustering& blend, ClusteringResult& run);

}  // namespace animorder
