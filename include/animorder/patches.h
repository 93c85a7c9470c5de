// animorder — patches by fast linear clustering (patches.cpp): Sander et al. 2007, §4;
// Han & Sander 2017, §3.1.
#pragma once

#include "animorder/vertex_cache.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace animorder {

// The paper's λ values (DESIGN.md): 0.85 for a small ACMR penalty, 3 for single triangles.
constexpr double kDefaultLambda = 0.85;

// Cuts a triangle sequence (usually tipsify's output, already applied) into contiguous patches:
// at every hard boundary, and (soft boundary) before triangle i when the local ACMR of the
// current patch, counted with triangle i in a cold FIFO cache of cache_size entries, is below
// lambda. lambda < 0.5 gives hard boundaries only; lambda >= 3 gives one triangle per patch.
// Returns patch_starts: ascending start positions, patch_starts[0] == 0, followed by a final
// entry equal to the triangle count (so patch p spans [starts[p], starts[p+1])). Empty input
// returns {0}.
std::vector<uint32_t> build_patches(const uint32_t* indices, size_t index_count, size_t vertex_count,
                                    const uint32_t* hard_boundaries, size_t hard_boundary_count, double lambda,
                                    unsigned cache_size = kDefaultCacheSize);

// Expands a patch permutation to a triangle permutation: triangles of patch_order[0] first (in
// their order inside the patch), then patch_order[1], and so on. order has one entry per triangle.
void expand_patch_order(uint32_t* order, const uint32_t* patch_order, const uint32_t* patch_starts, size_t patch_count);

}  // namespace animorder
