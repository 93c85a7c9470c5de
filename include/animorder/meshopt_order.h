// animorder — the "meshopt" baseline of DESIGN.md (meshopt_order.cpp): meshoptimizer's vertex
// cache and overdraw optimisers, what users have today, as a face permutation.
#pragma once

#include "animorder/vertex_cache.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace animorder {

// meshoptimizer's optimizeVertexCache then optimizeOverdraw(1.05) of one index buffer, at the
// given positions (vertex_count xyz floats), returned as a face permutation of its triangles.
std::vector<uint32_t> meshopt_order(const uint32_t* indices, size_t index_count, const float* positions,
                                    size_t vertex_count, unsigned cache_size = kDefaultCacheSize);

}  // namespace animorder
