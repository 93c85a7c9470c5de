// k-means over (keyframe, viewpoint) nodes: k index buffers for an animated mesh.
//
// This follows: Songfang Han and Pedro V. Sander, "Triangle Reordering for Efficient Rendering in
// Complex Scenes", Journal of Computer Graphics Techniques 6(3), 2017, §3 and Algorithm 1, and
// its I3D 2016 poster version for the normalised distance.
//
// Bootstrap: k random viewpoints at least a minimum angle apart (rejection sampling, §4), each
// giving a front-to-back patch order from the patches' centroids averaged over the keyframes.
// Then alternate (1) node assignment — every node to the buffer with the fewest fragments passing
// the depth test there, measured by the overdraw engine, ties to the lowest cluster id — and
// (2) buffer update — each cluster's patches sorted by the integrated distance d(p) over its
// nodes — until no assignment changes. A cluster left empty is re-seeded from the viewpoint of
// the worst-served node (highest OVR), which the paper does not cover; it is logged.
//
// Every step is deterministic: nodes are scored into their own slots, sums run in node order,
// sorts break ties by patch id, and the random viewpoints come from a seeded std::mt19937_64.
//
// Reading order, by the lines of the paper's Algorithm 1: bootstrap_orders (lines 9–14),
// assign_nodes (15–17), stop_after_assignment (18–19), update_orders and its pure core
// integrated_distance_order (20–24); not in the paper: reseed_empty_clusters and
// keep_improved_orders (UpdateRule::Monotone), and `measured`'s update in place of lines 20–24
// (measured_update.cpp). cluster_nodes, at the end, runs the loop.
#include "animorder/clustering.h"

#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/measured_order.h"
#include "animorder/mesh_patches.h"
#include "animorder/overdraw.h"
#include "animorder/rasterizer.h"
#include "animorder/viewpoints.h"

#include "../support/stopwatch.h"
#include "../support/worker_threads.h"
#include "measured_update.h"

#include <algorithm>
#include <cstdio>
#include <memory>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <cmath>
#include <numeric>
#include <random>
#include <string>

namespace animorder {
namespace {

void say(const ClusteringSettings& settings, const std::string& line) {
    if (settings.log) settings.log(line);
}

// Sorts patches by ascending key within each primitive (primitives keep file order), ties by id.
// primitive == nullptr: all patches in one primitive.
std::vector<uint32_t> sort_patches(const uint32_t* primitive, const std::vector<double>& key) {
    std::vector<uint32_t> order(key.size());
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        if (primitive && primitive[a] != primitive[b]) return primitive[a] < primitive[b];
        if (key[a] != key[b]) return key[a] < key[b];
        return a < b;
    });
    return order;
}

double distance(const float* a, const float* b) {
    const double dx = double(a[0]) - b[0], dy = double(a[1]) - b[1], dz = double(a[2]) - b[2];
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Patch centroids as the integrated distance reads them: per keyframe, one array per coordinate,
// so that a block of patches is read contiguously and its distances are computed lane-wise.
struct CentroidColumns {
    size_t keyframes = 0, patches = 0;
    std::vector<float> values;  // [(keyframe · 3 + axis) · patches + patch]

    CentroidColumns() = default;
    CentroidColumns(const float* centroids, size_t keyframe_count, size_t patch_count)
        : keyframes(keyframe_count), patches(patch_count), values(keyframe_count * patch_count * 3) {
        for (size_t k = 0; k < keyframe_count; ++k)
            for (size_t p = 0; p < patch_count; ++p)
                for (size_t axis = 0; axis < 3; ++axis)
                    values[(k * 3 + axis) * patch_count + p] = centroids[(k * patch_count + p) * 3 + axis];
    }
    const float* axis(size_t keyframe, size_t a) const { return &values[(keyframe * 3 + a) * patches]; }
};

// integrated_distance_order (clustering.h) over centroid columns. Each term is distance()'s: the
// same differences, products and sums in the same order, so the same bits.
std::vector<uint32_t> integrated_distance_order(const CentroidColumns& centroids, const uint32_t* node_keyframes,
                                                const float* node_eyes, size_t node_count, DistanceVariant variant,
                                                const uint8_t* node_visible, const uint32_t* patch_primitive) {
    const size_t keyframe_count = centroids.keyframes, patch_count = centroids.patches;
    const bool i3d = variant == DistanceVariant::I3d;
    for (size_t n = 0; n < node_count; ++n)
        if (node_keyframes[n] >= keyframe_count)
            throw InvalidInput("integrated distance: node " + std::to_string(n) + " names keyframe row " +
                               std::to_string(node_keyframes[n]) + ", but there are " + std::to_string(keyframe_count));
    std::vector<double> d(patch_count, 0.0), seen(patch_count, 0.0);
    // Blocks of patches in parallel, each patch's sum in node order: the same sums for any thread
    // count (the caller's task arena decides it).
    tbb::parallel_for(tbb::blocked_range<size_t>(0, patch_count, 64), [&](const tbb::blocked_range<size_t>& block) {
        const size_t first = block.begin(), count = block.size();
        double* sum = &d[first];
        double* sights = &seen[first];
        for (size_t n = 0; n < node_count; ++n) {
            const double ex = node_eyes[3 * n], ey = node_eyes[3 * n + 1], ez = node_eyes[3 * n + 2];
            const float* cx = centroids.axis(node_keyframes[n], 0) + first;
            const float* cy = centroids.axis(node_keyframes[n], 1) + first;
            const float* cz = centroids.axis(node_keyframes[n], 2) + first;
            const uint8_t* vis = i3d && node_visible ? &node_visible[n * patch_count + first] : nullptr;
            if (!vis) {  // the paper's sum: a loop without a branch, vectorised (sqrt is exact in any lane)
                for (size_t p = 0; p < count; ++p) {
                    const double dx = ex - double(cx[p]), dy = ey - double(cy[p]), dz = ez - double(cz[p]);
                    sum[p] += std::sqrt(dx * dx + dy * dy + dz * dz);
                }
                if (i3d)
                    for (size_t p = 0; p < count; ++p) sights[p] += 1.0;
                continue;
            }
            for (size_t p = 0; p < count; ++p) {
                if (!vis[p]) continue;  // I3D: wholly back-facing at this node
                const double dx = ex - double(cx[p]), dy = ey - double(cy[p]), dz = ez - double(cz[p]);
                sum[p] += std::sqrt(dx * dx + dy * dy + dz * dz);
                sights[p] += 1.0;
            }
        }
    });
    if (i3d)
        for (size_t p = 0; p < patch_count; ++p)
            // A patch no node of the cluster sees goes last (it is never visible there).
            d[p] = seen[p] > 0 ? d[p] / seen[p] : INFINITY;
    return sort_patches(patch_primitive, d);
}

// Front-to-back from one eye, with each patch at its centroid averaged over the keyframes.
std::vector<uint32_t> front_to_back(const MeshPatches& patches, const std::vector<float>& average_centroids,
                                    const float eye[3]) {
    std::vector<double> key(patches.patch_count());
    for (size_t p = 0; p < key.size(); ++p) key[p] = distance(eye, &average_centroids[3 * p]);
    return sort_patches(patches.patch_primitive.data(), key);
}

std::vector<float> average_over_keyframes(const std::vector<float>& centroids, size_t keyframes, size_t patch_count) {
    std::vector<double> sum(patch_count * 3, 0.0);
    for (size_t i = 0; i < keyframes; ++i)
        for (size_t j = 0; j < patch_count * 3; ++j) sum[j] += centroids[i * patch_count * 3 + j];
    std::vector<float> out(patch_count * 3);
    for (size_t j = 0; j < out.size(); ++j) out[j] = float(sum[j] / double(keyframes));
    return out;
}

// k directions uniform on the sphere, each at least min_separation from those drawn before; the
// separation halves (and says so) when 1000 draws in a row fail.
std::vector<float> bootstrap_directions(const ClusteringSettings& settings) {
    std::mt19937_64 rng(settings.seed);
    auto uniform = [&rng] { return double(rng() >> 11) * (1.0 / 9007199254740992.0); };
    double separation = settings.min_separation_deg * M_PI / 180.0;
    std::vector<float> dirs;
    size_t failures = 0;
    while (dirs.size() < 3 * settings.clusters) {
        const double z = 2.0 * uniform() - 1.0, phi = 2.0 * M_PI * uniform(), r = std::sqrt(std::max(0.0, 1 - z * z));
        const float d[3] = {float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)};
        bool far_enough = true;
        for (size_t i = 0; i < dirs.size(); i += 3) {
            const double c = double(d[0]) * dirs[i] + double(d[1]) * dirs[i + 1] + double(d[2]) * dirs[i + 2];
            far_enough &= std::acos(std::clamp(c, -1.0, 1.0)) >= separation;
        }
        if (far_enough) {
            dirs.insert(dirs.end(), d, d + 3);
            failures = 0;
        } else if (++failures == 1000) {
            separation *= 0.5;
            failures = 0;
            say(settings, "bootstrap: no room for " + std::to_string(settings.clusters) +
                              " viewpoints that far apart; minimum separation lowered to " +
                              std::to_string(separation * 180.0 / M_PI) + " degrees");
        }
    }
    return dirs;
}

// I3D variant: for each (node, patch), whether any triangle of the patch faces the node's eye.
std::vector<uint8_t> patch_visibility(const AnimatedMesh& mesh, const MeshPatches& patches, const Framing& framing,
                                      const std::vector<uint32_t>& keyframes, const std::vector<float>& eyes) {
    const size_t views = eyes.size() / 3, patch_count = patches.patch_count();
    std::vector<uint8_t> visible(keyframes.size() * views * patch_count, 0);
    std::vector<double> normal(mesh.triangle_count() * 3), point(mesh.triangle_count() * 3);
    for (size_t i = 0; i < keyframes.size(); ++i) {
        const float* pos = mesh.keyframe(keyframes[i]);
        const float* centre = &framing.centres[3 * size_t(keyframes[i])];
        for (size_t t = 0; t < mesh.triangle_count(); ++t) {
            const float* a = pos + 3 * size_t(mesh.indices[3 * t]);
            const float* b = pos + 3 * size_t(mesh.indices[3 * t + 1]);
            const float* c = pos + 3 * size_t(mesh.indices[3 * t + 2]);
            const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            normal[3 * t] = u[1] * v[2] - u[2] * v[1];
            normal[3 * t + 1] = u[2] * v[0] - u[0] * v[2];
            normal[3 * t + 2] = u[0] * v[1] - u[1] * v[0];
            for (int d = 0; d < 3; ++d) point[3 * t + d] = double(a[d]) - centre[d];
        }
        for (size_t v = 0; v < views; ++v) {
            const float* eye = &eyes[3 * v];
            uint8_t* row = &visible[(i * views + v) * patch_count];
            for (size_t p = 0; p < patch_count; ++p)
                for (uint32_t j = patches.patch_starts[p]; j < patches.patch_starts[p + 1] && !row[p]; ++j) {
                    const size_t t = patches.cache_order[j];
                    const double facing = normal[3 * t] * (eye[0] - point[3 * t]) +
                                          normal[3 * t + 1] * (eye[1] - point[3 * t + 1]) +
                                          normal[3 * t + 2] * (eye[2] - point[3 * t + 2]);
                    row[p] = facing > 0;
                }
        }
    }
    return visible;
}

// ---------------------------------------------------------------------------------------------
// The steps of Algorithm 1 (JCGT 2017 §3.2; "line" below means a line of its pseudocode), each
// a short function over the shared state below; cluster_nodes at the end strings them together.

// What every step reads and never changes: the nodes N from the keyframes F and viewpoints V
// (lines 3–5), their cameras, the patches P (line 6) and their framed centroids (lines 7–8).
struct Nodes {
    Nodes(const AnimatedMesh& m, const MeshPatches& p, const Framing& f) : mesh(m), patches(p), framing(f) {}
    const AnimatedMesh& mesh;
    const MeshPatches& patches;
    const Framing& framing;
    size_t k = 0;                        // clusters
    size_t keyframes = 0;                // listed keyframes (rows of centroids)
    size_t views = 0;                    // node n = (keyframes[n / views], directions[n % views])
    size_t count = 0;                    // keyframes × views
    std::vector<OverdrawNode> cameras;   // per node
    std::vector<float> eyes;             // per view: 3R · direction, in the framed space
    CentroidColumns columns;             // per listed keyframe, per patch (patch_centroids), in columns
    std::vector<float> average;          // per patch: its centroid averaged over the keyframes
    std::vector<uint8_t> patch_visible;  // I3D only: [n · patch_count + p], some triangle faces n
    ScoreSettings score;
    std::vector<uint8_t> modes;        // per triangle (opaque_pass_modes): score's triangle_modes
    std::unique_ptr<NodeCache> cache;  // every node rasterised once, kept compactly within the budget
};

// Measured overdraw at every node: visible[n], the pixels covered (what drawing front-to-back
// would pass), and passed[n · k + c], the fragments passing the depth test with buffer c.
// scored[c] is the patch order that column c holds (empty before the first scoring).
struct NodeScores {
    std::vector<uint64_t> visible, passed;
    std::vector<std::vector<uint32_t>> scored;
};

// The best state met so far (its orders produced its assignment): what cluster_nodes returns.
struct BestState {
    double mean_ovr = INFINITY;
    std::vector<std::vector<uint32_t>> patch_orders;
    std::vector<uint32_t> assignment;
};

std::vector<std::vector<uint32_t>> triangle_orders_of(const MeshPatches& patches,
                                                      const std::vector<std::vector<uint32_t>>& patch_orders) {
    std::vector<std::vector<uint32_t>> out;
    for (const auto& o : patch_orders) out.push_back(patch_order_to_triangle_order(patches, o));
    return out;
}

// Every node scored with the patch orders that changed since the last scoring (all of them the
// first time): the other columns already hold their counts, which depend on nothing else.
void score_orders(const Nodes& nodes, const std::vector<std::vector<uint32_t>>& patch_orders, NodeScores& out) {
    const size_t k = patch_orders.size();
    out.scored.resize(k);
    std::vector<uint32_t> changed;
    std::vector<std::vector<uint32_t>> triangle_orders;
    for (uint32_t c = 0; c < k; ++c)
        if (out.scored[c].empty() || out.scored[c] != patch_orders[c]) {
            changed.push_back(c);
            triangle_orders.push_back(patch_order_to_triangle_order(nodes.patches, patch_orders[c]));
        }
    if (changed.empty()) return;
    std::vector<const uint32_t*> pointers;
    for (const auto& o : triangle_orders) pointers.push_back(o.data());
    const std::vector<uint32_t> ranks = make_rank_table(pointers, nodes.mesh.triangle_count());
    if (changed.size() == k) {
        nodes.cache->score(out.visible.data(), out.passed.data(), ranks.data(), k);
    } else {
        std::vector<uint64_t> passed(nodes.count * changed.size());
        nodes.cache->score(out.visible.data(), passed.data(), ranks.data(), changed.size());
        for (size_t n = 0; n < nodes.count; ++n)
            for (size_t j = 0; j < changed.size(); ++j) out.passed[n * k + changed[j]] = passed[n * changed.size() + j];
    }
    for (const uint32_t c : changed) out.scored[c] = patch_orders[c];
}

// Bootstrapping (lines 9–14): k viewpoints at least min_separation apart (line 10), and for each
// the patches front-to-back by their centroids averaged over all keyframes (lines 11–14).
std::vector<std::vector<uint32_t>> bootstrap_orders(const Nodes& nodes, const ClusteringSettings& settings) {
    const std::vector<float> seeds = bootstrap_directions(settings);
    const float distance_to_eye = 3.0f * nodes.framing.radius;
    std::vector<std::vector<uint32_t>> orders(nodes.k);
    for (size_t c = 0; c < nodes.k; ++c) {
        const float eye[3] = {distance_to_eye * seeds[3 * c], distance_to_eye * seeds[3 * c + 1],
                              distance_to_eye * seeds[3 * c + 2]};
        orders[c] = front_to_back(nodes.patches, nodes.average, eye);
    }
    return orders;
}

// Node assignment (lines 15–17): every node to the buffer with the fewest fragments passing the
// depth test there, ties to the lowest cluster id. Fills the assignment, each node's OVR with its
// buffer (0 for a node that sees nothing), and the iteration's reassigned count and mean OVR.
void assign_nodes(const Nodes& nodes, const std::vector<std::vector<uint32_t>>& patch_orders, NodeScores& scores,
                  std::vector<uint32_t>& assignment, std::vector<double>& node_ovr, ClusteringIteration& log) {
    score_orders(nodes, patch_orders, scores);
    const size_t k = nodes.k;
    node_ovr.assign(nodes.count, 0.0);
    double ovr_sum = 0;
    size_t counted = 0;
    for (size_t n = 0; n < nodes.count; ++n) {
        const uint64_t* passed = &scores.passed[n * k];
        uint32_t best = 0;
        for (uint32_t c = 1; c < k; ++c)
            if (passed[c] < passed[best]) best = c;
        log.reassigned += assignment[n] != best;
        assignment[n] = best;
        if (scores.visible[n] > 0) {
            node_ovr[n] = double(passed[best]) / double(scores.visible[n]);
            ovr_sum += node_ovr[n];
            ++counted;
        }
    }
    log.mean_ovr = counted ? ovr_sum / double(counted) : 0.0;
}

// Index buffer computation (lines 20–24): each non-empty cluster's patches by the integrated
// distance d(p) over its nodes (integrated_distance_order). Empty clusters keep their order here
// (reseed_empty_clusters replaces it). Returns the number of nodes of each cluster.
std::vector<size_t> update_orders(const Nodes& nodes, DistanceVariant variant, const std::vector<uint32_t>& assignment,
                                  std::vector<std::vector<uint32_t>>& patch_orders) {
    const size_t patch_count = nodes.patches.patch_count();
    const bool i3d = variant == DistanceVariant::I3d;
    // Each cluster's nodes, in node order (so the sums run in the same order for any k).
    std::vector<std::vector<uint32_t>> rows(nodes.k);
    std::vector<std::vector<float>> eyes(nodes.k);
    std::vector<std::vector<uint8_t>> visible(nodes.k);
    for (size_t n = 0; n < nodes.count; ++n) {
        const uint32_t c = assignment[n];
        rows[c].push_back(uint32_t(n / nodes.views));
        const float* eye = &nodes.eyes[3 * (n % nodes.views)];
        eyes[c].insert(eyes[c].end(), eye, eye + 3);
        if (i3d) {
            const uint8_t* row = &nodes.patch_visible[n * patch_count];
            visible[c].insert(visible[c].end(), row, row + patch_count);
        }
    }
    std::vector<size_t> members(nodes.k);
    for (size_t c = 0; c < nodes.k; ++c) {
        members[c] = rows[c].size();
        if (members[c] == 0) continue;
        patch_orders[c] =
            integrated_distance_order(nodes.columns, rows[c].data(), eyes[c].data(), rows[c].size(), variant,
                                      i3d ? visible[c].data() : nullptr, nodes.patches.patch_primitive.data());
    }
    return members;
}

std::string megabytes(uint64_t bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f MB", double(bytes) / 1e6);
    return text;
}

// Not in the paper (DESIGN.md step 6: never drop a cluster silently): an empty cluster takes the
// front-to-back order, by averaged centroids, from the viewpoint of the worst-served node (highest
// OVR) not used for another cluster in this iteration. Marks the clusters re-seeded.
size_t reseed_empty_clusters(const Nodes& nodes, const std::vector<size_t>& members,
                             const std::vector<double>& node_ovr, const ClusteringSettings& settings,
                             std::vector<std::vector<uint32_t>>& patch_orders, std::vector<uint8_t>& reseeded) {
    std::vector<uint8_t> used_as_seed(nodes.count, 0);
    reseeded.assign(nodes.k, 0);
    size_t count = 0;
    for (size_t c = 0; c < nodes.k; ++c) {
        if (members[c] != 0) continue;
        size_t worst = 0;
        double worst_ovr = -1;
        for (size_t n = 0; n < nodes.count; ++n)
            if (!used_as_seed[n] && node_ovr[n] > worst_ovr) worst_ovr = node_ovr[n], worst = n;
        used_as_seed[worst] = 1;
        patch_orders[c] = front_to_back(nodes.patches, nodes.average, &nodes.eyes[3 * (worst % nodes.views)]);
        reseeded[c] = 1;
        ++count;
        say(settings, "cluster " + std::to_string(c) + " was empty: re-seeded from the viewpoint of node " +
                          std::to_string(worst) + " (OVR " + std::to_string(worst_ovr) + ")");
    }
    return count;
}

// UpdateRule::Monotone, not in the paper: a cluster keeps its new order only if its own nodes'
// summed OVR falls (re-seeded clusters always take theirs). With the assignment step (each node
// to its best buffer) the mean node OVR can then only fall, so k-means settles instead of
// cycling. `scores` are the previous orders' (from the assignment step). Returns the number of
// clusters whose new order was kept.
//
// Only a cluster's own nodes decide, but every node is scored with every new order (one walk
// over the kept nodes for all of them costs little more than for one): the columns of the
// orders kept go into `scores`, so the next assignment need not score them again.
size_t keep_improved_orders(const Nodes& nodes, const std::vector<uint32_t>& assignment, NodeScores& scores,
                            const std::vector<std::vector<uint32_t>>& previous, const std::vector<uint8_t>& reseeded,
                            std::vector<std::vector<uint32_t>>& patch_orders) {
    const size_t k = nodes.k;
    // A cluster whose order did not change keeps it (the same order cannot score lower).
    std::vector<uint32_t> changed, column(k, UINT32_MAX);
    std::vector<std::vector<uint32_t>> candidates;
    for (uint32_t c = 0; c < k; ++c) {
        if (patch_orders[c] == previous[c]) continue;
        column[c] = uint32_t(changed.size());
        changed.push_back(c);
        candidates.push_back(patch_order_to_triangle_order(nodes.patches, patch_orders[c]));
    }
    const size_t m = changed.size();
    std::vector<uint64_t> after_passed(nodes.count * m), visible(nodes.count);
    if (m > 0) {
        std::vector<const uint32_t*> pointers;
        for (const auto& o : candidates) pointers.push_back(o.data());
        const std::vector<uint32_t> ranks = make_rank_table(pointers, nodes.mesh.triangle_count());
        nodes.cache->score(visible.data(), after_passed.data(), ranks.data(), m);
    }
    std::vector<double> before(k, 0.0), after(k, 0.0);
    for (size_t n = 0; n < nodes.count; ++n) {
        if (scores.visible[n] == 0) continue;
        const uint32_t c = assignment[n];
        if (column[c] == UINT32_MAX) continue;
        before[c] += double(scores.passed[n * k + c]) / double(scores.visible[n]);
        after[c] += double(after_passed[n * m + column[c]]) / double(scores.visible[n]);
    }
    size_t accepted = 0;
    for (size_t c = 0; c < k; ++c) {
        if (reseeded[c]) continue;
        if (column[c] != UINT32_MAX && after[c] < before[c])
            ++accepted;
        else
            patch_orders[c] = previous[c];  // no better: keep the old buffer
    }
    // The new orders kept (improved or re-seeded) are scored already.
    for (size_t c = 0; c < k; ++c) {
        if (column[c] == UINT32_MAX || patch_orders[c] == previous[c]) continue;
        for (size_t n = 0; n < nodes.count; ++n) scores.passed[n * k + c] = after_passed[n * m + column[c]];
        scores.scored[c] = patch_orders[c];
    }
    return accepted;
}

// The stopping rule after an assignment (lines 18–19, "if no cluster assignment has changed"),
// with two guards the paper does not need: patience (no new best mean OVR for that many
// iterations: k-means is cycling) and the iteration cap. Empty: go on.
std::string stop_after_assignment(size_t iteration, const ClusteringIteration& log, double previous_ovr,
                                  size_t best_iteration, const ClusteringSettings& settings) {
    const bool settled = iteration > 0 && log.reassigned == 0;
    const bool stalled = iteration >= best_iteration + settings.patience;
    if (settled) return "converged";
    if (settings.settled_gain > 0 && iteration > 0 && log.mean_ovr > previous_ovr * (1 - settings.settled_gain))
        return "settled";
    if (stalled) return "stalled";
    if (iteration + 1 >= settings.max_iterations) return "iteration cap";
    return {};
}

// The best state's buffers and assignment into the result. A cluster that no node chose (k above
// the number of nodes, a clip of one keyframe say) gives no buffer: it would be written and never
// drawn. The others keep their order, renumbered.
void finish(ClusteringResult& result, const MeshPatches& patches, const BestState& best) {
    std::vector<uint32_t> renumbered(best.patch_orders.size(), UINT32_MAX);
    for (const uint32_t c : best.assignment)
        if (c < renumbered.size()) renumbered[c] = 0;
    result.patch_orders.clear();
    for (size_t c = 0; c < renumbered.size(); ++c)
        if (renumbered[c] == 0) {
            renumbered[c] = uint32_t(result.patch_orders.size());
            result.patch_orders.push_back(best.patch_orders[c]);
        }
    result.assignment = best.assignment;
    for (uint32_t& c : result.assignment)
        if (c < renumbered.size()) c = renumbered[c];
    result.triangle_orders = triangle_orders_of(patches, result.patch_orders);
}

void validate_settings(const std::vector<uint32_t>& keyframes, const ClusteringSettings& settings) {
    if (settings.clusters == 0 || settings.clusters > kMaxClusters)
        throw InvalidInput("the number of clusters must be between 1 and " + std::to_string(kMaxClusters) + ", not " +
                           std::to_string(settings.clusters));
    if (keyframes.empty()) throw InvalidInput("clustering needs at least one keyframe");
    if (settings.max_iterations == 0) throw InvalidInput("clustering needs at least one iteration");
    if (!(settings.min_separation_deg >= 0) || settings.min_separation_deg > 180)
        throw InvalidInput("minimum separation must be between 0 and 180 degrees");
}

}  // namespace

std::vector<uint32_t> integrated_distance_order(const float* centroids, size_t keyframe_count, size_t patch_count,
                                                const uint32_t* node_keyframes, const float* node_eyes,
                                                size_t node_count, DistanceVariant variant, const uint8_t* node_visible,
                                                const uint32_t* patch_primitive) {
    return integrated_distance_order(CentroidColumns(centroids, keyframe_count, patch_count), node_keyframes, node_eyes,
                                     node_count, variant, node_visible, patch_primitive);
}

ClusteringResult cluster_nodes(const AnimatedMesh& mesh, const MeshPatches& patches, const Framing& framing,
                               const std::vector<uint32_t>& keyframes, const ClusteringSettings& settings) {
    validate_settings(keyframes, settings);
    validate_animated_mesh(mesh, keyframes);  // the positions of these keyframes: all that it reads

    // Preprocessing (lines 2–8): nodes = keyframes × icosphere viewpoints, each keyframe framed
    // on its own centre, eyes at 3R.
    ClusteringResult result;
    result.keyframes = keyframes;
    result.directions = icosphere_directions(icosphere_subdivisions_for(settings.views));
    // Keyframes that all shrink the mesh to a point (a clip that hides it by scale 0) draw nothing
    // at any node: every order passes no fragment, so one buffer, the patches in their own order,
    // serves every node (and no camera can be placed at 3R = 0).
    if (framing.shows_nothing()) {
        BestState nothing_drawn{0.0,
                                {std::vector<uint32_t>(patches.patch_count())},
                                std::vector<uint32_t>(keyframes.size() * settings.views, 0)};
        std::iota(nothing_drawn.patch_orders[0].begin(), nothing_drawn.patch_orders[0].end(), 0u);
        result.converged = true;
        result.stop_reason = "nothing drawn";
        say(settings, "the mesh has no size at any of its keyframes: nothing is drawn, one buffer for every node");
        finish(result, patches, nothing_drawn);
        return result;
    }
    Nodes nodes(mesh, patches, framing);
    nodes.k = settings.clusters;
    nodes.keyframes = keyframes.size();
    nodes.views = settings.views;
    nodes.count = nodes.keyframes * nodes.views;
    nodes.eyes.resize(result.directions.size());
    for (size_t j = 0; j < nodes.eyes.size(); ++j) nodes.eyes[j] = 3.0f * framing.radius * result.directions[j];
    nodes.cameras.resize(nodes.count);
    for (size_t i = 0; i < keyframes.size(); ++i)
        for (size_t v = 0; v < nodes.views; ++v) {
            nodes.cameras[i * nodes.views + v].keyframe = keyframes[i];
            std::copy(&result.directions[3 * v], &result.directions[3 * v] + 3,
                      nodes.cameras[i * nodes.views + v].direction);
        }
    // Each keyframe's patch centroids on its own (patch_centroids of that keyframe: the same
    // values), the keyframes side by side.
    const size_t centroid_floats = patches.patch_count() * 3;
    std::vector<float> centroids(keyframes.size() * centroid_floats);
    tbb::task_arena(worker_threads(settings.threads)).execute([&] {
        tbb::parallel_for(size_t(0), keyframes.size(), [&](size_t i) {
            const std::vector<float> row = patch_centroids(mesh, patches, framing, {keyframes[i]});
            std::copy(row.begin(), row.end(), centroids.begin() + ptrdiff_t(i * centroid_floats));
        });
    });
    nodes.columns = CentroidColumns(centroids.data(), keyframes.size(), patches.patch_count());
    nodes.average = average_over_keyframes(centroids, keyframes.size(), patches.patch_count());
    if (settings.distance == DistanceVariant::I3d)
        nodes.patch_visible = patch_visibility(mesh, patches, framing, keyframes, nodes.eyes);
    nodes.score.resolution = settings.resolution;
    nodes.score.threads = settings.threads;
    std::string stage = "scoring the first orders";  // what nodes.score's progress reports
    if (settings.progress)
        nodes.score.progress = [&settings, &stage](size_t done, size_t total) {
            settings.progress(stage, done, total);
        };
    nodes.modes = opaque_pass_modes(mesh);
    nodes.score.triangle_modes = nodes.modes.empty() ? nullptr : nodes.modes.data();

    result.patch_orders = bootstrap_orders(nodes, settings);

    // Rasterise every node once; later iterations only replay the kept fragments in new orders.
    stage = "rasterising nodes";
    const Clock::time_point raster_start = Clock::now();
    nodes.cache =
        std::make_unique<NodeCache>(mesh.keyframe_positions.data(), mesh.vertex_count, framing, mesh.indices.data(),
                                    mesh.indices.size(), nodes.cameras.data(), nodes.count,
                                    make_unit_partition(patches.patch_starts.data(), patches.patch_count(),
                                                        patches.cache_order.data(), mesh.triangle_count()),
                                    nodes.score, settings.max_cache_bytes);
    result.seconds_rasterization = seconds_since(raster_start);
    result.kept_nodes = nodes.cache->kept_count();
    result.kept_bytes = nodes.cache->kept_bytes();
    if (nodes.cache->kept_count() < nodes.count)
        say(settings, "node fragments exceed the cache budget of " + megabytes(settings.max_cache_bytes) + ": " +
                          std::to_string(nodes.cache->kept_count()) + " of " + std::to_string(nodes.count) +
                          " nodes kept (" + megabytes(nodes.cache->kept_bytes()) +
                          "), the others rasterised again when scored");

    NodeScores scores{std::vector<uint64_t>(nodes.count), std::vector<uint64_t>(nodes.count * nodes.k), {}};
    std::vector<double> node_ovr;
    result.assignment.assign(nodes.count, UINT32_MAX);
    BestState best;
    MeasuredGraphs measured;
    tbb::task_arena update_arena(worker_threads(settings.threads));
    for (size_t iteration = 0;; ++iteration) {
        ClusteringIteration log;
        stage = "assigning nodes, iteration " + std::to_string(iteration + 1);
        const Clock::time_point assignment_start = Clock::now();
        assign_nodes(nodes, result.patch_orders, scores, result.assignment, node_ovr, log);
        log.seconds_assignment = seconds_since(assignment_start);

        // Keep the best state (its orders produced this assignment), so cycling never loses it.
        if (log.mean_ovr < best.mean_ovr) {
            best = {log.mean_ovr, result.patch_orders, result.assignment};
            result.best_iteration = iteration;
        }
        const double previous_ovr = result.iterations.empty() ? log.mean_ovr : result.iterations.back().mean_ovr;
        const std::string stop = stop_after_assignment(iteration, log, previous_ovr, result.best_iteration, settings);
        if (!stop.empty()) {
            result.converged = stop == "converged";
            result.stop_reason = stop;
            result.iterations.push_back(log);
            say(settings, "iteration " + std::to_string(iteration + 1) + ": mean OVR " + std::to_string(log.mean_ovr) +
                              ", " + std::to_string(log.reassigned) + " nodes reassigned — " + result.stop_reason +
                              "; keeping iteration " + std::to_string(result.best_iteration + 1) + " (mean OVR " +
                              std::to_string(best.mean_ovr) + ")");
            finish(result, patches, best);
            break;
        }

        stage = "updating orders, iteration " + std::to_string(iteration + 1);
        const Clock::time_point update_start = Clock::now();
        const std::vector<std::vector<uint32_t>> previous_orders = result.patch_orders;
        std::vector<size_t> members;
        update_arena.execute([&] {
            members = settings.order == OrderSource::Measured
                          ? measured_update_orders(
                                {nodes.patches, nodes.mesh.triangle_count(), *nodes.cache, nodes.count, nodes.k},
                                settings, result.assignment, measured, result.patch_orders)
                          : update_orders(nodes, settings.distance, result.assignment, result.patch_orders);
        });
        std::vector<uint8_t> reseeded;
        log.reseeded = reseed_empty_clusters(nodes, members, node_ovr, settings, result.patch_orders, reseeded);
        if (settings.update == UpdateRule::Monotone)
            log.accepted =
                keep_improved_orders(nodes, result.assignment, scores, previous_orders, reseeded, result.patch_orders);
        log.seconds_update = seconds_since(update_start);
        result.iterations.push_back(log);
        say(settings, "iteration " + std::to_string(iteration + 1) + ": mean OVR " + std::to_string(log.mean_ovr) +
                          ", " + std::to_string(log.reassigned) + " nodes reassigned" +
                          (settings.update == UpdateRule::Monotone ? ", " + std::to_string(log.accepted) + " of " +
                                                                         std::to_string(nodes.k) + " buffers improved"
                                                                   : std::string()));
        if (settings.update == UpdateRule::Monotone && log.accepted == 0 && log.reseeded == 0) {
            // Same buffers, so the next assignment would be this one: k-means has settled (the
            // Monotone rule's form of lines 18–19).
            result.converged = true;
            result.stop_reason = "converged";
            say(settings, "converged: no buffer changed; keeping iteration " +
                              std::to_string(result.best_iteration + 1) + " (mean OVR " +
                              std::to_string(best.mean_ovr) + ")");
            finish(result, patches, best);
            break;
        }
    }
    return result;
}

}  // namespace animorder
