// animorder — static-nehab06: Nehab, Barczak & Sander, "Triangle Order Optimization for
// Graphics Hardware Computation Culling", I3D 2006.
//
// Planar clusters by normals (§3), a partial-order graph of the overdraw every pair of clusters
// causes over many viewpoints (§4), a cluster order from the greedy minimum feedback-arc-set
// heuristic (§5), each cluster Tipsified inside. One view-independent order, one index buffer.
// Plain arrays in and out; the overdraw is measured with the project's own rasteriser
// (overdraw.h), under DESIGN.md's framing and camera. No file I/O here.
#pragma once

#include "animorder/feedback_arc_set.h"
#include "animorder/planar_clusters.h"
#include "animorder/vertex_cache.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace animorder {

// The partial-order graph (§4) and its order (§5: feedback_arc_set.h).

struct OverdrawGraphSettings {
    size_t views = 162;         // icosphere directions (12, 42, 162, 642, ...)
    unsigned resolution = 256;  // square viewport
    unsigned threads = 0;       // 0: all hardware threads; the result does not depend on it
};

// The partial-order graph of §4. For every node (each listed keyframe × each icosphere view,
// framed and seen with DESIGN.md's camera; R is the largest radius over the listed keyframes),
// one rasterisation keeps every pixel's fragments; then for every pair of clusters a < b and
// every pixel both cover, the fragments passing the depth test when a alone is drawn and then b
// alone is compared with b then a, each cluster drawn in the sequence `draw_order` gives its
// triangles (a face permutation: only the order within each cluster matters). The net saving of
// a-before-b summed over all nodes gives an arc a→b (or b→a when negative; none when zero).
// Exactly passed(b, a) − passed(a, b) of the two-cluster draw, as score_nodes would count it.
// Arcs come sorted by (min(a,b), max(a,b)). keyframes empty → keyframe 0. Deterministic whatever
// the thread count (integer sums). cluster_count <= kMaxNehabClusters.
std::vector<Arc> build_overdraw_graph(const uint32_t* indices, size_t index_count, const float* keyframe_positions,
                                      size_t keyframe_count, size_t vertex_count, const uint32_t* keyframes,
                                      size_t keyframe_list_count, const uint32_t* cluster_of, size_t cluster_count,
                                      const uint32_t* draw_order, const OverdrawGraphSettings& settings);

// The graph keeps a dense triangular matrix of pair sums per worker: 4096 clusters take 64 MiB.
constexpr size_t kMaxNehabClusters = 4096;

// The whole method.

struct Nehab06Settings {
    // Clusters; 0 chooses automatically as the paper suggests (§6: "trying the method on
    // successive powers of two, until the average overdraw stops improving consistently", and
    // the count is reached "long before [it] starts to harm the vertex cache performance"):
    // 2, 4, 8, ... clusters, each scored by its mean OVR over the graph's own nodes, stopping
    // after two doublings in a row that lower the best mean OVR by less than 0.5% (counted only
    // from the number of connected components on: below it clusters are unions of whole
    // components and the OVR can plateau before it falls), at 1024 or the triangle count, or at
    // the first count whose ACMR (clusters Tipsified) exceeds Tipsify's on the whole mesh by more
    // than 25% (that count is not eligible; static-sander07 at λ = 0.85 costs 12–39% on the
    // characters of ../shared/data, and 10% left too few clusters to beat it on Xbot); of the
    // eligible counts, the smallest within 0.5% of their best mean OVR wins (the first if none is).
    size_t clusters = 0;
    size_t views = 162;
    unsigned resolution = 256;
    unsigned cache_size = kDefaultCacheSize;
    unsigned threads = 0;
    // Null (every triangle drawn, back faces culled), or one mode per triangle of the index list
    // (kDrawBothFaces, kSkipTriangle of rasterizer.h): how the graph's and the candidates' nodes
    // draw them (a double-sided material: no culling). Not owned.
    const uint8_t* triangle_modes = nullptr;
};

struct Nehab06Candidate {
    size_t clusters = 0;
    double mean_ovr = 0;  // over the graph's nodes, of that candidate's final order
    double acmr = 0;      // of its clusters Tipsified (the cluster order does not change it much)
};

struct Nehab06Result {
    size_t cluster_count = 0;
    size_t arc_count = 0;
    size_t feedback_arc_count = 0;
    double feedback_weight = 0;                // fragments the violated arcs would have saved
    std::vector<Nehab06Candidate> candidates;  // automatic choice only: every count tried
    double seconds_clustering = 0;             // clustering and Tipsify inside clusters, all candidates
    double seconds_rasterization = 0;          // rasterising the nodes (part of seconds_graph)
    double seconds_graph = 0;                  // rasterisation + pair sums, all candidates
    double seconds_ordering = 0;               // feedback-arc-set ordering, all candidates
    double seconds_selection = 0;              // scoring candidates (automatic choice only)
};

// static-nehab06: writes a face permutation of index_count/3 triangles to order. Clusters are
// built on the normals of the first listed keyframe; the graph sums over every listed keyframe
// (one buffer for the whole animation). keyframe_positions: keyframe_count × vertex_count × xyz.
// keyframes empty → keyframe 0. A cluster count above the triangle count is lowered to it.
// Throws InvalidInput for bad indices, missing or non-finite positions, a keyframe out of range,
// a view count that is no icosphere, resolution 0 or above 8192, cache_size < 3, or more than
// kMaxNehabClusters clusters.
Nehab06Result order_static_nehab06(uint32_t* order, const uint32_t* indices, size_t index_count,
                                   const float* keyframe_positions, size_t keyframe_count, size_t vertex_count,
                                   const uint32_t* keyframes, size_t keyframe_list_count,
                                   const Nehab06Settings& settings);

}  // namespace animorder
