// Private to src/algorithms: the update step of `measured` k-means (measured_update.cpp), which
// cluster_nodes (clustering.cpp) runs in place of Han & Sander's sort by integrated distance.
#pragma once

#include "animorder/clustering.h"
#include "animorder/measured_order.h"
#include "animorder/mesh_patches.h"
#include "animorder/overdraw.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace animorder {

// Full fragment lists of nodes rasterised again are held about this many bytes at a time (a few
// hundred nodes at 256², a few dozen at 4096²): by the update below, and by held_out_choice.cpp.
constexpr uint64_t kTransientFragmentBytes = uint64_t(64) << 20;

// OrderSource::Measured: each cluster's pair counts (measured_order.h), kept between iterations
// and updated with the nodes that changed cluster only.
struct MeasuredGraphs {
    std::vector<uint32_t> unit_of_triangle;
    std::vector<MeasuredPairCounts> graphs;    // per cluster, over the nodes `counted` gives it
    std::vector<uint32_t> counted;             // per node: the cluster whose graph counts it (or UINT32_MAX)
    std::vector<std::vector<uint32_t>> last;   // per cluster: the last measured order (a local optimum)
    std::vector<std::vector<uint32_t>> start;  // per cluster: the buffer that order started from
};

// What the update reads of k-means' nodes: the patches, the node cache (the kept fragments; the
// others rasterised again) and the counts.
struct MeasuredNodes {
    const MeshPatches& patches;
    size_t triangle_count;
    const NodeCache& cache;
    size_t count;  // nodes
    size_t k;      // clusters
};

// OrderSource::Measured, not in Han & Sander 2017 (measured_order.cpp): each non-empty cluster's patches
// ordered by the overdraw graph measured over its own nodes' kept fragments (rasterised again for
// nodes beyond the memory budget), starting from the better of the greedy order and its current
// one. Returns the number of nodes of each cluster.
std::vector<size_t> measured_update_orders(const MeasuredNodes& nodes, const ClusteringSettings& settings,
                                           const std::vector<uint32_t>& assignment, MeasuredGraphs& state,
                                           std::vector<std::vector<uint32_t>>& patch_orders);

}  // namespace animorder
