// animorder — vertex cache analysis (vertex_cache.cpp): ACMR and ATVR of an index buffer for a
// FIFO post-transform cache (DESIGN.md).
#pragma once

#include "animorder/invalid_input.h"

#include <cstddef>
#include <cstdint>

namespace animorder {

// The cache size every report uses unless told otherwise (DESIGN.md: FIFO of 16 entries).
constexpr unsigned kDefaultCacheSize = 16;

struct VertexCacheStats {
    size_t misses = 0;               // vertices transformed (FIFO misses)
    size_t triangles = 0;            // triangles drawn
    size_t referenced_vertices = 0;  // distinct vertices the index buffer references
    double acmr = 0;                 // misses / triangles (0 for empty input)
    double atvr = 0;                 // misses / referenced_vertices (0 for empty input)
};

// Simulates a FIFO post-transform cache of cache_size entries that starts empty, drawing the
// triangles in index-buffer order; each corner is looked up, then inserted on a miss. A hit does
// not refresh an entry (FIFO, not LRU). ATVR divides by the vertices actually referenced, so an
// index buffer that transforms each of its vertices once has ATVR 1.
VertexCacheStats analyze_vertex_cache(const uint32_t* indices, size_t index_count, size_t vertex_count,
                                      unsigned cache_size = kDefaultCacheSize);

}  // namespace animorder
