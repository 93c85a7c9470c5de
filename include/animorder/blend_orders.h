// animorder — orders for blended primitives (issue 18; DESIGN.md "Blend error"): back to front,
// from the clusters of a Han & Sander run. No file I/O here.
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/clustering.h"
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

}  // namespace animorder
