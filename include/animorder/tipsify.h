// animorder — Tipsify (tipsify.cpp): Sander, Nehab & Barczak 2007, §3.
#pragma once

#include "animorder/vertex_cache.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace animorder {

struct TipsifyResult {
    // Output positions (indices into the produced order) of the first triangle emitted after each
    // dead-end jump (Skip-Dead-End), ascending. Position 0 is not listed: it starts everything.
    std::vector<uint32_t> hard_boundaries;
};

// Writes a vertex-cache-friendly face permutation of the triangles to order[0..index_count/3).
// cache_size is the target FIFO size k (>= 3). Runs in time linear in the input.
TipsifyResult tipsify(uint32_t* order, const uint32_t* indices, size_t index_count, size_t vertex_count,
                      unsigned cache_size = kDefaultCacheSize);

// The same order written directly as an index buffer (what tipsify + apply_triangle_order give,
// in one pass). destination must not alias indices.
TipsifyResult tipsify_index_buffer(uint32_t* destination, const uint32_t* indices, size_t index_count,
                                   size_t vertex_count, unsigned cache_size = kDefaultCacheSize);

}  // namespace animorder
