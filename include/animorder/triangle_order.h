// animorder — validation and face permutations (triangle_order.cpp): orders are face
// permutations (order[i] is the input triangle drawn i-th); a permutation never changes a
// triangle's corners or their winding.
#pragma once

#include "animorder/invalid_input.h"

#include <cstddef>
#include <cstdint>

namespace animorder {

// Throws InvalidInput unless index_count is a multiple of 3 and every index < vertex_count.
void validate_indices(const uint32_t* indices, size_t index_count, size_t vertex_count);

// Throws InvalidInput unless order[0..triangle_count) is a permutation of 0..triangle_count-1.
void validate_triangle_order(const uint32_t* order, size_t triangle_count);

// destination[3i..3i+2] = indices[3·order[i] ..], corners in their original sequence.
// destination must not alias indices. order must be a valid permutation (validated).
void apply_triangle_order(uint32_t* destination, const uint32_t* indices, const uint32_t* order, size_t triangle_count);

// order = composition: result[i] = inner[outer[i]] (outer indexes positions of inner's output).
void compose_triangle_orders(uint32_t* destination, const uint32_t* inner, const uint32_t* outer,
                             size_t triangle_count);

}  // namespace animorder
