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
#include "animorder/clustering.h"

#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/mesh_patches.h"
#include "animorder/overdraw.h"
#include "animorder/rasterizer.h"
#include "animorder/viewpoints.h"

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>
#include <string>

namespace animorder {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

void say(const ClusteringSettings& settings, const std::string& line) {
    if (settings.log) settings.log(line);
}

// Sorts patches by ascending key within each primitive (primitives keep file order), ties by id.
std::vector<uint32_t> sort_patches(const MeshPatches& patches, const std::vector<double>& key) {
    std::vector<uint32_t> order(patches.patch_count());
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        if (patches.patch_primitive[a] != patches.patch_primitive[b])
            return patches.patch_primitive[a] < patches.patch_primitive[b];
        if (key[a] != key[b]) return key[a] < key[b];
        return a < b;
    });
    return order;
}

double distance(const float* a, const float* b) {
    const double dx = double(a[0]) - b[0], dy = double(a[1]) - b[1], dz = double(a[2]) - b[2];
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Front-to-back from one eye, with each patch at its centroid averaged over the keyframes.
std::vector<uint32_t> front_to_back(const MeshPatches& patches, const std::vector<float>& average_centroids,
                                    const float eye[3]) {
    std::vector<double> key(patches.patch_count());
    for (size_t p = 0; p < key.size(); ++p) key[p] = distance(eye, &average_centroids[3 * p]);
    return sort_patches(patches, key);
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

}  // namespace

ClusteringResult cluster_nodes(const AnimatedMesh& mesh, const MeshPatches& patches, const Framing& framing,
                               const std::vector<uint32_t>& keyframes, const ClusteringSettings& settings) {
    validate_animated_mesh(mesh);
    if (settings.clusters == 0 || settings.clusters > 255)
        throw InvalidInput("the number of clusters must be between 1 and 255, not " + std::to_string(settings.clusters));
    if (keyframes.empty()) throw InvalidInput("clustering needs at least one keyframe");
    if (settings.max_iterations == 0) throw InvalidInput("clustering needs at least one iteration");
    if (!(settings.min_separation_deg >= 0) || settings.min_separation_deg > 180)
        throw InvalidInput("minimum separation must be between 0 and 180 degrees");
    const size_t k = settings.clusters;
    const size_t patch_count = patches.patch_count();

    ClusteringResult result;
    result.keyframes = keyframes;
    result.directions = icosphere_directions(icosphere_subdivisions_for(settings.views));
    const size_t views = settings.views, node_count = keyframes.size() * views;
    std::vector<float> eyes(result.directions.size());
    for (size_t j = 0; j < eyes.size(); ++j) eyes[j] = 3.0f * framing.radius * result.directions[j];

    std::vector<OverdrawNode> nodes(node_count);
    for (size_t i = 0; i < keyframes.size(); ++i)
        for (size_t v = 0; v < views; ++v) {
            nodes[i * views + v].keyframe = keyframes[i];
            std::copy(&result.directions[3 * v], &result.directions[3 * v] + 3, nodes[i * views + v].direction);
        }

    const std::vector<float> centroids = patch_centroids(mesh, patches, framing, keyframes);
    const std::vector<float> average = average_over_keyframes(centroids, keyframes.size(), patch_count);
    std::vector<uint8_t> patch_visible;
    if (settings.distance == DistanceVariant::I3d)
        patch_visible = patch_visibility(mesh, patches, framing, keyframes, eyes);

    // Bootstrap.
    const std::vector<float> seeds = bootstrap_directions(settings);
    result.patch_orders.resize(k);
    for (size_t c = 0; c < k; ++c) {
        const float eye[3] = {3.0f * framing.radius * seeds[3 * c], 3.0f * framing.radius * seeds[3 * c + 1],
                              3.0f * framing.radius * seeds[3 * c + 2]};
        result.patch_orders[c] = front_to_back(patches, average, eye);
    }

    ScoreSettings score;
    score.resolution = settings.resolution;
    score.threads = settings.threads;
    score.progress = settings.progress;
    std::vector<uint64_t> visible(node_count), passed(node_count * k);
    result.assignment.assign(node_count, UINT32_MAX);

    // Rasterise every node once; later iterations only replay the kept fragments in new orders.
    const Clock::time_point raster_start = Clock::now();
    const std::vector<NodeFragments> kept =
        rasterize_nodes(mesh.keyframe_positions.data(), mesh.vertex_count, framing, mesh.indices.data(),
                        mesh.indices.size(), nodes.data(), node_count, score, settings.max_cache_bytes);
    result.seconds_rasterization = seconds_since(raster_start);
    if (kept.empty())
        say(settings, "node fragments exceed the cache budget: rasterising again every iteration");

    double best_ovr = INFINITY;
    std::vector<std::vector<uint32_t>> best_orders;
    std::vector<uint32_t> best_assignment;
    for (size_t iteration = 0;; ++iteration) {
        ClusteringIteration log;
        // Step 1: node assignment by measured overdraw.
        const Clock::time_point raster_start = Clock::now();
        result.triangle_orders.clear();
        std::vector<const uint32_t*> pointers;
        for (size_t c = 0; c < k; ++c) result.triangle_orders.push_back(patch_order_to_triangle_order(patches, result.patch_orders[c]));
        for (const auto& o : result.triangle_orders) pointers.push_back(o.data());
        const std::vector<uint32_t> ranks = make_rank_table(pointers, mesh.triangle_count());
        if (kept.empty())
            score_nodes(visible.data(), passed.data(), mesh.keyframe_positions.data(), mesh.vertex_count, framing,
                        mesh.indices.data(), mesh.indices.size(), nodes.data(), node_count, ranks.data(), k, score);
        else
            score_kept_nodes(visible.data(), passed.data(), kept, ranks.data(), k, score);
        std::vector<double> node_ovr(node_count, 0.0);
        double ovr_sum = 0;
        size_t counted = 0;
        for (size_t n = 0; n < node_count; ++n) {
            uint32_t best = 0;
            for (uint32_t c = 1; c < k; ++c)
                if (passed[n * k + c] < passed[n * k + best]) best = c;
            log.reassigned += result.assignment[n] != best;
            result.assignment[n] = best;
            if (visible[n] > 0) {
                node_ovr[n] = double(passed[n * k + best]) / double(visible[n]);
                ovr_sum += node_ovr[n];
                ++counted;
            }
        }
        log.mean_ovr = counted ? ovr_sum / double(counted) : 0.0;
        log.seconds_raster = seconds_since(raster_start);

        // Keep the best state (its orders produced this assignment), so cycling never loses it.
        if (log.mean_ovr < best_ovr) {
            best_ovr = log.mean_ovr;
            best_orders = result.patch_orders;
            best_assignment = result.assignment;
            result.best_iteration = iteration;
        }
        const bool settled = iteration > 0 && log.reassigned == 0;
        const bool stalled = iteration >= result.best_iteration + settings.patience;
        if (settled || stalled || iteration + 1 >= settings.max_iterations) {
            result.converged = settled;
            result.stop_reason = settled ? "converged" : stalled ? "stalled" : "iteration cap";
            result.iterations.push_back(log);
            say(settings, "iteration " + std::to_string(iteration + 1) + ": mean OVR " + std::to_string(log.mean_ovr) +
                              ", " + std::to_string(log.reassigned) + " nodes reassigned — " + result.stop_reason +
                              "; keeping iteration " + std::to_string(result.best_iteration + 1) + " (mean OVR " +
                              std::to_string(best_ovr) + ")");
            result.patch_orders = best_orders;
            result.assignment = best_assignment;
            result.triangle_orders.clear();
            for (const auto& o : result.patch_orders) result.triangle_orders.push_back(patch_order_to_triangle_order(patches, o));
            break;
        }

        // Step 2: each cluster's patches by integrated distance d(p) over its nodes.
        const Clock::time_point update_start = Clock::now();
        std::vector<std::vector<double>> d(k, std::vector<double>(patch_count, 0.0));
        std::vector<std::vector<double>> seen(k, std::vector<double>(patch_count, 0.0));
        std::vector<size_t> members(k, 0);
        for (size_t n = 0; n < node_count; ++n) {
            const uint32_t c = result.assignment[n];
            ++members[c];
            const size_t i = n / views, v = n % views;
            const float* eye = &eyes[3 * v];
            const float* cent = &centroids[i * patch_count * 3];
            const uint8_t* vis = patch_visible.empty() ? nullptr : &patch_visible[n * patch_count];
            for (size_t p = 0; p < patch_count; ++p) {
                if (vis && !vis[p]) continue;  // I3D: wholly back-facing at this node
                d[c][p] += distance(eye, cent + 3 * p);
                seen[c][p] += 1.0;
            }
        }
        std::vector<uint8_t> used_as_seed(node_count, 0);
        std::vector<uint8_t> reseeded(k, 0);
        const std::vector<std::vector<uint32_t>> previous_orders = result.patch_orders;
        for (size_t c = 0; c < k; ++c) {
            if (members[c] == 0) {
                // Re-seed from the worst-served node not used yet.
                size_t worst = 0;
                double worst_ovr = -1;
                for (size_t n = 0; n < node_count; ++n)
                    if (!used_as_seed[n] && node_ovr[n] > worst_ovr) worst_ovr = node_ovr[n], worst = n;
                used_as_seed[worst] = 1;
                result.patch_orders[c] = front_to_back(patches, average, &eyes[3 * (worst % views)]);
                reseeded[c] = 1;
                ++log.reseeded;
                say(settings, "cluster " + std::to_string(c) + " was empty: re-seeded from the viewpoint of node " +
                                  std::to_string(worst) + " (OVR " + std::to_string(worst_ovr) + ")");
                continue;
            }
            if (settings.distance == DistanceVariant::I3d)
                for (size_t p = 0; p < patch_count; ++p)
                    // A patch no node of the cluster sees goes last (it is never visible there).
                    d[c][p] = seen[c][p] > 0 ? d[c][p] / seen[c][p] : INFINITY;
            result.patch_orders[c] = sort_patches(patches, d[c]);
        }
        if (settings.update == UpdateRule::Monotone) {
            // Keep a cluster's new order only if its own nodes' mean OVR does not rise: with the
            // assignment step (each node to its best buffer) the mean node OVR can then only fall,
            // so k-means settles instead of cycling. Scored from the kept fragments.
            std::vector<const uint32_t*> pointers;
            std::vector<std::vector<uint32_t>> candidate;
            for (size_t c = 0; c < k; ++c) candidate.push_back(patch_order_to_triangle_order(patches, result.patch_orders[c]));
            for (const auto& o : candidate) pointers.push_back(o.data());
            std::vector<uint64_t> candidate_visible(node_count), candidate_passed(node_count * k);
            if (kept.empty()) {
                const std::vector<uint32_t> candidate_ranks = make_rank_table(pointers, mesh.triangle_count());
                score_nodes(candidate_visible.data(), candidate_passed.data(), mesh.keyframe_positions.data(),
                            mesh.vertex_count, framing, mesh.indices.data(), mesh.indices.size(), nodes.data(), node_count,
                            candidate_ranks.data(), k, score);
            } else {
                // Each node only needs its own cluster's candidate: one order per node, not k.
                std::vector<std::vector<uint32_t>> single_ranks;
                for (const uint32_t* o : pointers) single_ranks.push_back(make_rank_table({o}, mesh.triangle_count()));
                const int threads = settings.threads ? int(settings.threads) : tbb::this_task_arena::max_concurrency();
                tbb::task_arena arena(threads);
                arena.execute([&] {
                    tbb::parallel_for(tbb::blocked_range<size_t>(0, node_count, 64), [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t n = r.begin(); n != r.end(); ++n) {
                            const uint32_t c = result.assignment[n];
                            score_fragments(&candidate_passed[n * k + c], kept[n], single_ranks[c].data(), 1);
                        }
                    });
                });
            }
            std::vector<double> before(k, 0.0), after(k, 0.0);
            for (size_t n = 0; n < node_count; ++n) {
                if (visible[n] == 0) continue;
                const uint32_t c = result.assignment[n];
                before[c] += double(passed[n * k + c]) / double(visible[n]);
                after[c] += double(candidate_passed[n * k + c]) / double(visible[n]);
            }
            for (size_t c = 0; c < k; ++c) {
                if (reseeded[c]) continue;
                if (after[c] < before[c]) ++log.accepted;
                else result.patch_orders[c] = previous_orders[c];  // no better: keep the old buffer
            }
        }
        log.seconds_update = seconds_since(update_start);
        result.iterations.push_back(log);
        say(settings, "iteration " + std::to_string(iteration + 1) + ": mean OVR " + std::to_string(log.mean_ovr) + ", " +
                          std::to_string(log.reassigned) + " nodes reassigned" +
                          (settings.update == UpdateRule::Monotone
                               ? ", " + std::to_string(log.accepted) + " of " + std::to_string(k) + " buffers improved"
                               : std::string()));
        if (settings.update == UpdateRule::Monotone && log.accepted == 0 && log.reseeded == 0) {
            // Same buffers, so the next assignment would be this one: k-means has settled.
            result.converged = true;
            result.stop_reason = "converged";
            result.patch_orders = best_orders;
            result.assignment = best_assignment;
            result.triangle_orders.clear();
            for (const auto& o : result.patch_orders) result.triangle_orders.push_back(patch_order_to_triangle_order(patches, o));
            break;
        }
    }
    return result;
}

}  // namespace animorder
