// animorder — static-sander07 (static_sander07.cpp): Sander et al. 2007, §5, equation 4.
#pragma once

#include "animorder/patches.h"
#include "animorder/vertex_cache.h"

#include <cstddef>
#include <cstdint>

namespace animorder {

// Per patch: area-weighted centroid C(P) and area-weighted average normal N(P) of its triangles
// (the normal is the mean of unit normals weighted by area, not renormalised), and the mesh's
// area-weighted surface centroid C(M). rank(P) = (C(P) − C(M))·N(P). Writes patch_order: patches
// by descending rank, ties by ascending patch id. positions: vertex_count xyz floats with
// position_stride bytes between vertices.
void sort_patches_sander07(uint32_t* patch_order, const uint32_t* indices, size_t index_count, const float* positions,
                           size_t vertex_count, size_t position_stride, const uint32_t* patch_starts,
                           size_t patch_count);

struct StaticOrderResult {
    size_t patch_count = 0;
    size_t hard_boundary_count = 0;
};

// The whole static-sander07 method: tipsify, cut into patches with lambda, sort the patches with
// equation 4 at the given positions. order: a face permutation of the input triangles.
StaticOrderResult order_static_sander07(uint32_t* order, const uint32_t* indices, size_t index_count,
                                        const float* positions, size_t vertex_count, size_t position_stride,
                                        double lambda = kDefaultLambda, unsigned cache_size = kDefaultCacheSize);

}  // namespace animorder
