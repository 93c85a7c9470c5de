// animorder — planar clusters (planar_clusters.cpp): Nehab, Barczak & Sander 2006 §3, adapting
// Sander et al. 2003.
#pragma once

#include "animorder/vertex_cache.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace animorder {

// The tie-breaking constant ε of the edge cost 1 − n̄c·nf + ε (a small cost per step, so that in
// flat regions a face goes to the nearest seed).
constexpr double kPlanarClusterEpsilon = 1e-3;

// Clusters the triangles into min(cluster_count, triangle count) regions of similar normal,
// grown over the edge adjacency (triangles sharing an undirected edge; vertices at bit-identical
// positions count as one, so seams do not cut the surface). Seeds are placed one at a time: in
// the connected component with most triangles that has no seed yet (at its lowest triangle),
// while any is left, then at the face farthest (in accumulated edge cost) from the seeds so far;
// then Lloyd iterations (at most max_iterations) alternate growing every cluster from its seed
// (Dijkstra with edge cost 1 − n̄c·nf + ε, n̄c the cluster's area-weighted mean normal) and moving
// each seed to the face of its cluster farthest (in steps) from the cluster's boundary, until the
// seeds stop moving. A component that got no seed joins, whole, the cluster whose normal is
// closest to the component's area-weighted mean normal. Returns one cluster id per triangle;
// every id below the cluster count is used.
// positions: vertex_count xyz floats. Deterministic. Throws InvalidInput for bad indices, a
// non-finite position or cluster_count == 0 with triangles present.
std::vector<uint32_t> cluster_by_normals(const uint32_t* indices, size_t index_count, const float* positions,
                                         size_t vertex_count, size_t cluster_count, unsigned max_iterations = 8);

// The same clustering for several counts of one mesh: normals and adjacency are computed once,
// and seeding for a larger count resumes from the last one's seeds (identical results to
// cluster_by_normals). The arrays are read in the constructor only.
class PlanarClusterer {
public:
    PlanarClusterer(const uint32_t* indices, size_t index_count, const float* positions, size_t vertex_count);
    ~PlanarClusterer();
    PlanarClusterer(const PlanarClusterer&) = delete;
    PlanarClusterer& operator=(const PlanarClusterer&) = delete;
    std::vector<uint32_t> cluster(size_t cluster_count, unsigned max_iterations = 8);
    // Connected components of the welded edge adjacency: below this many clusters, clusters are
    // unions of whole components.
    size_t component_count() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

// Writes a face permutation grouping triangles by cluster (ascending id), each cluster in Tipsify
// order (its triangles Tipsified on their own, vertices renumbered locally so the cost is linear
// in the cluster). Returns cluster_starts: cluster c occupies [starts[c], starts[c+1]) of order.
std::vector<uint32_t> tipsify_clusters(uint32_t* order, const uint32_t* indices, size_t index_count,
                                       size_t vertex_count, const uint32_t* cluster_of, size_t cluster_count,
                                       unsigned cache_size = kDefaultCacheSize);

}  // namespace animorder
