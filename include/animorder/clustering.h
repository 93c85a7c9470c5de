// animorder — Han & Sander 2017: k index buffers for an animated mesh by k-means over
// (keyframe, viewpoint) nodes, and the runtime lookup table that picks one (DESIGN.md
// "Han & Sander 2017, as the project implements it", "Runtime selection"). No file I/O here.
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/mesh_patches.h"
#include "animorder/viewpoints.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace animorder {

enum class DistanceVariant {
    Jcgt,  // d(p) = Σ over the cluster's nodes of |viewpoint − centroid(p, keyframe)| (JCGT 2017)
    I3d,   // the I3D poster: skip nodes where p faces wholly away, divide by the nodes that see it
};

enum class UpdateRule {
    Paper,     // JCGT 2017 Algorithm 1: every cluster takes its new integrated-distance order
    Monotone,  // the same, but a cluster keeps its old order unless the new one lowers the mean
               // OVR of its own nodes (measured): the mean node OVR never rises, k-means settles
};

// Where the update step's order of a cluster's patches comes from.
enum class OrderSource {
    Distance,  // Han & Sander 2017: the integrated distance (DistanceVariant)
    Measured,  // not in the paper (measured_order.h): the overdraw graph measured over the
               // cluster's own nodes, greedy feedback-arc-set order, then sifting
};

// The most buffers a clip may have (k, and the (opaque, blend) pairs of blend_orders.h): the
// runtime lookup table (selection_table.h, the sidecar's and glTF's cells) stores each cell's
// buffer id, within its clip, in one byte.
constexpr size_t kMaxClusters = 255;

// `measured` counts each unit's pixels against the units of this many nearest depth levels in
// front of it (MeasuredPairCounts' front_levels), not every level: drawn after those, a unit is
// hidden whatever the deeper levels hold. RESULTS.md's measured section has the pairs and the OVR
// it saves and costs against every level (`--front-levels 0`).
constexpr uint32_t kMeasuredFrontLevels = 2;
constexpr uint32_t kMaxFrontLevels = 1024;

struct ClusteringSettings {
    size_t clusters = 5;  // k, 1..kMaxClusters
    size_t views = 162;   // icosphere viewpoints (12, 42, 162, 642)
    unsigned resolution = 256;
    uint64_t seed = 1;
    double min_separation_deg = 30;  // between bootstrap viewpoints (rejection sampling)
    size_t max_iterations = 30;
    // The integrated-distance update does not minimise the measured overdraw, so on real
    // characters k-means can cycle among near-equal assignments instead of settling. It stops
    // when the mean node OVR has not improved on its best for this many iterations, and the best
    // iteration's buffers and assignment are returned.
    size_t patience = 4;
    // Stops ("settled") once an assignment's mean node OVR is not below the previous one's by
    // this fraction of it (0: never; `measured` uses kMeasuredSettledGain): the measured update
    // improves its buffers a little at every iteration, and its last dozen iterations move a few
    // nodes each for a gain in the fifth decimal.
    double settled_gain = 0;
    DistanceVariant distance = DistanceVariant::Jcgt;
    UpdateRule update = UpdateRule::Monotone;
    OrderSource order = OrderSource::Distance;
    uint32_t front_levels = kMeasuredFrontLevels;  // `measured`: as above; 0: every level in front
    unsigned threads = 0;
    // Nodes' fragments are kept between iterations (orders change, fragments do not), compactly
    // (kept_fragments.h), in node order while they fit in this many bytes; the nodes beyond are
    // rasterised again whenever they are scored (slower, same result).
    size_t max_cache_bytes = size_t(6) << 30;
    std::function<void(const std::string&)> log;  // one line per event (re-seeding, …)
    // Now and then: what the nodes go through ("rasterising nodes", "scoring the first orders",
    // "assigning nodes, iteration 2"), nodes done, total; (total, total) ends each stage.
    std::function<void(const std::string& stage, size_t done, size_t total)> progress;
};

struct ClusteringIteration {
    double mean_ovr = 0;            // mean node OVR with every node drawn by its assigned buffer
    size_t reassigned = 0;          // nodes whose cluster changed in this assignment step
    size_t reseeded = 0;            // clusters that were empty and got re-seeded
    size_t accepted = 0;            // Monotone rule: clusters whose new order was kept
    double seconds_assignment = 0;  // assignment step (scoring k orders at every node)
    double seconds_update = 0;      // integrated-distance update
};

struct ClusteringResult {
    std::vector<uint32_t> keyframes;                     // the keyframes clustered (global indices)
    std::vector<float> directions;                       // the clustering viewpoints, xyz each
    std::vector<std::vector<uint32_t>> patch_orders;     // k patch permutations
    std::vector<std::vector<uint32_t>> triangle_orders;  // k face permutations of the whole mesh
    // assignment[i · views + v]: the cluster of node (keyframes[i], directions[v]).
    std::vector<uint32_t> assignment;
    std::vector<ClusteringIteration> iterations;
    bool converged = false;            // the last iteration reassigned no node
    std::string stop_reason;           // "converged", "settled" (settled_gain), "stalled" (patience ran out), "iteration cap", or
                                       // "nothing drawn" (every keyframe a point: one buffer, no iteration)
    size_t best_iteration = 0;         // 0-based: the iteration whose buffers and assignment these are
    double seconds_rasterization = 0;  // rasterising every node once (kept for all iterations)
    size_t kept_nodes = 0;             // nodes whose fragments fit the cache budget (the first ones)
    size_t kept_bytes = 0;             // their compact fragments (KeptNode)
    // `measured` only (held_out_choice.h): the held-out nodes its buffers were checked on, and per
    // cluster 1 where its buffer (triangle_orders) is the integrated-distance order, 0 where it is
    // a measured one; empty for other methods. patch_orders stay those of the k-means itself (the
    // measured ones; `single`'s distance ones where measured ran `single`'s k-means: methods.h).
    // The check may drop a buffer no node draws any more (fewer than k then).
    size_t held_out_nodes = 0;
    std::vector<uint8_t> held_out_distance;
    double seconds_held_out = 0;
};

// Han & Sander 2017, Algorithm 1, over the nodes keyframes × icosphere viewpoints.
ClusteringResult cluster_nodes(const AnimatedMesh& mesh, const MeshPatches& patches, const Framing& framing,
                               const std::vector<uint32_t>& keyframes, const ClusteringSettings& settings);

// The update step alone (Algorithm 1 lines 21–24) for one cluster: its patches sorted by the
// integrated distance over its nodes, ascending, ties by patch id. cluster_nodes calls it for
// every non-empty cluster.
//   centroids: keyframe_count × patch_count × xyz (patch_centroids' layout, framed);
//   node_keyframes[n]: the centroids row (0 ≤ row < keyframe_count) of the cluster's node n;
//   node_eyes: node_count × xyz, node n's eye in the same framed space;
//   Jcgt: d(p) = Σ_n |eye_n − centroid(p, row_n)| (node_visible is ignored);
//   I3d:  the sum only over nodes with node_visible[n · patch_count + p] ≠ 0 (cluster_nodes sets
//         it when some triangle of p faces eye_n), divided by their number; a patch no node sees
//         goes last. node_visible == nullptr: every node sees every patch;
//   patch_primitive (may be nullptr: one primitive): patches of a lower primitive come first, so
//         primitives keep file order.
// Throws InvalidInput for a node row >= keyframe_count.
std::vector<uint32_t> integrated_distance_order(const float* centroids, size_t keyframe_count, size_t patch_count,
                                                const uint32_t* node_keyframes, const float* node_eyes,
                                                size_t node_count, DistanceVariant variant,
                                                const uint8_t* node_visible = nullptr,
                                                const uint32_t* patch_primitive = nullptr);

}  // namespace animorder
