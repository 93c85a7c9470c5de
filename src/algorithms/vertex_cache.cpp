// Post-transform vertex cache analysis: ACMR and ATVR for a FIFO cache.
//
// The metric of Hoppe 1999 and Sander, Nehab & Barczak 2007 (§6): average cache miss ratio
// (misses per triangle) and average transform to vertex ratio (misses per vertex), for a FIFO
// cache of k entries that starts empty (DESIGN.md). FIFO is what the papers simulate; a hit does
// not move the entry. Cache membership uses insertion time stamps, as Tipsify does: a vertex
// is cached iff it was inserted fewer than k insertions ago, so the simulation is O(1) per corner
// whatever k is.
#include "animorder/vertex_cache.h"

#include "animorder/invalid_input.h"
#include "animorder/triangle_order.h"

#include <vector>

namespace animorder {

VertexCacheStats analyze_vertex_cache(const uint32_t* indices, size_t index_count, size_t vertex_count,
                                      unsigned cache_size) {
    validate_indices(indices, index_count, vertex_count);
    if (cache_size == 0) throw InvalidInput("cache size must be at least 1");

    VertexCacheStats stats;
    stats.triangles = index_count / 3;
    if (index_count == 0) return stats;

    // inserted_at[v] is the insertion counter value when v last entered the cache; 0 = never.
    // Counters start at cache_size + 1 so that "now − inserted_at > cache_size" means "evicted".
    std::vector<uint64_t> inserted_at(vertex_count, 0);
    uint64_t now = uint64_t(cache_size) + 1;
    for (size_t i = 0; i < index_count; ++i) {
        const uint32_t v = indices[i];
        if (inserted_at[v] == 0) ++stats.referenced_vertices;
        if (now - inserted_at[v] > cache_size) {
            inserted_at[v] = now++;
            ++stats.misses;
        }
    }
    stats.acmr = double(stats.misses) / double(stats.triangles);
    stats.atvr = double(stats.misses) / double(stats.referenced_vertices);
    return stats;
}

}  // namespace animorder
