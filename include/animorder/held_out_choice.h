// animorder — measured orders checked on views they did not learn from (held_out_choice.cpp).
//
// A measured order (measured_order.h) minimises the overdraw of the nodes it was measured at; on
// a mesh of many small units it can fit those views and serve the views between them worse than
// Han & Sander's integrated-distance sort, which is smooth between views. After a k-means run,
// each cluster keeps whichever of two orders passes fewer fragments on views the run never
// rasterised. No file I/O.
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/clustering.h"
#include "animorder/mesh_patches.h"
#include "animorder/viewpoints.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace animorder {

// The held-out views: held_out_views_per_keyframe(keyframes) directions from
// random_sphere_directions with this seed (not the evaluation's default, 20170501), the same at
// every keyframe of the run, at the run's own resolution; each node is drawn with the buffer of
// the clustering view nearest to it at its keyframe (what the runtime table's cell holds).
constexpr uint64_t kHeldOutSeed = 0x4e1d0f;
// About 600 held-out nodes a run (more on long clips): clamp(ceil(600 / keyframes), 12, 162) views
// per keyframe.
size_t held_out_views_per_keyframe(size_t keyframes);

// Each cluster's JCGT integrated-distance order of `patches` over its nodes (clustering.h's
// integrated_distance_order: Han & Sander's update), as a face permutation; empty for a cluster
// no node is assigned to. framing: the run's (its R).
std::vector<std::vector<uint32_t>> distance_cluster_orders(const AnimatedMesh& mesh, const MeshPatches& patches,
                                                           const Framing& framing, const ClusteringResult& run);

// Each cluster's measured order (measured_order.h: the greedy feedback-arc-set order, then
// sifting) of `units` from the overdraw graph over every `stride`-th of its nodes, rasterised
// again (the clusters side by side, a chunk of nodes at a time), as a face permutation; empty for
// a cluster no node is assigned to. front_levels: MeasuredPairCounts'. For runs whose own units
// are too many to measure (methods.h).
std::vector<std::vector<uint32_t>> measured_cluster_orders(const AnimatedMesh& mesh, const MeshPatches& units,
                                                           const Framing& framing, const ClusteringResult& run,
                                                           unsigned resolution, unsigned threads, size_t stride,
                                                           uint32_t front_levels = kMeasuredFrontLevels);

struct HeldOutChoice {
    size_t nodes = 0;                // held-out nodes scored
    std::vector<uint8_t> taken;      // per cluster: 1 where the alternative order was kept
    uint64_t current_passed = 0;     // fragments passed on the held-out nodes by the run's buffers
    uint64_t chosen_passed = 0;      // … by the buffers kept
    uint64_t visible = 0;            // pixels covered on them (the overdraw ratio's denominator)
    size_t reassigned = 0;           // clustering nodes moved to another buffer after a change
    size_t dropped = 0;              // buffers no node drew after that: removed, the rest renumbered
};

// For each cluster c of `run`, alternatives[c] (a face permutation; empty: none) replaces
// run.triangle_orders[c] when it passes strictly fewer fragments than it on the held-out nodes
// c's buffer is drawn at (opaque pass, as the evaluation scores). When some order changed, every
// clustering node then goes to the kept buffer that passes the fewest of its fragments
// (run.assignment; ties keep its cluster, then the lower one), as k-means' assignment step
// would, and a buffer left with no node is removed (triangle_orders, patch_orders, taken; the
// assignment renumbered). run.patch_orders is left as it was otherwise. framing: the run's (its R). Deterministic, whatever
// the thread count (0: all cores).
HeldOutChoice choose_on_held_out_views(const AnimatedMesh& mesh, const Framing& framing, unsigned resolution,
                                       unsigned threads, ClusteringResult& run,
                                       std::vector<std::vector<uint32_t>> alternatives);

}  // namespace animorder
