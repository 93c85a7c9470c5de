// Back-to-front orders for blended primitives from a k-means run's clusters (issue 18).
//
// Blended geometry is right only when each pixel's fragments arrive farthest first. The clusters
// of Han & Sander's k-means group nodes that see the character from nearby directions at similar
// poses; within a cluster, the triangles of a blended primitive sorted by their distance to the
// eye summed over the cluster's nodes, farthest first, is the order that is back to front for
// the cluster as a whole: the integrated-distance update of JCGT 2017 with the sort reversed, at
// triangle granularity (Tipsify patches span several hair cards, so sorting patches would leave
// the cards of one patch in cache order).
#include "animorder/blend_orders.h"

#include "animorder/clustering.h"
#include "animorder/invalid_input.h"

#include <algorithm>
#include <string>

namespace animorder {

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
                        (positions[3 * v[0] + d] + positions[3 * v[1] + d] + positions[3 * v[2] + d]) / 3.0f - centre[d];
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

}  // namespace animorder
