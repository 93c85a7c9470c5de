// The "meshopt" method of DESIGN.md: what users have today, meshoptimizer's
// optimizeVertexCache (Forsyth-style) followed by optimizeOverdraw with threshold 1.05 (at most 5%
// worse ACMR), on one keyframe's positions. It is a baseline, never scored by meshoptimizer's own
// overdraw analyser (0.18's has a depth bug): the overdraw engine scores it like every method.
#include "animorder/meshopt_order.h"

#include "animorder/invalid_input.h"
#include "animorder/triangle_order.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <map>

namespace animorder {

std::vector<uint32_t> meshopt_order(const uint32_t* indices, size_t index_count, const float* positions,
                                    size_t vertex_count, unsigned cache_size) {
    validate_indices(indices, index_count, vertex_count);
    (void)cache_size;  // meshopt_optimizeVertexCache targets generic hardware, not one FIFO size
    std::vector<uint32_t> cache(index_count), overdraw(index_count);
    meshopt_optimizeVertexCache(cache.data(), indices, index_count, vertex_count);
    meshopt_optimizeOverdraw(overdraw.data(), cache.data(), index_count, positions, vertex_count, 3 * sizeof(float),
                             1.05f);

    // Back to a face permutation: match each output triangle to an input triangle with the same
    // corners in the same cyclic order (duplicates taken in input order).
    auto canonical = [](const uint32_t* t) {
        std::array<uint32_t, 3> c{t[0], t[1], t[2]};
        while (c[0] > c[1] || c[0] > c[2]) c = {c[1], c[2], c[0]};
        return c;
    };
    std::map<std::array<uint32_t, 3>, std::vector<uint32_t>> by_corners;
    for (size_t t = index_count / 3; t-- > 0;) by_corners[canonical(indices + 3 * t)].push_back(uint32_t(t));
    std::vector<uint32_t> order;
    order.reserve(index_count / 3);
    for (size_t t = 0; t < index_count / 3; ++t) {
        auto& ids = by_corners[canonical(overdraw.data() + 3 * t)];
        if (ids.empty()) throw InvalidInput("meshoptimizer changed a triangle's corners");
        order.push_back(ids.back());
        ids.pop_back();
    }
    return order;
}

}  // namespace animorder
