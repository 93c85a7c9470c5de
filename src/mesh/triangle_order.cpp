// Triangle orders as face permutations, and the input checks every algorithm shares.
//
// Following DirectXMesh (Microsoft): optimisers return a face permutation and a separate function
// applies it, which maps cleanly onto the k alternative orders of one mesh that Han & Sander 2017
// produce. Validation raises distinct, explicit errors instead of asserts that vanish in Release.
#include "animorder/triangle_order.h"

#include "animorder/invalid_input.h"

#include <string>
#include <vector>

namespace animorder {

void validate_indices(const uint32_t* indices, size_t index_count, size_t vertex_count) {
    if (index_count % 3 != 0)
        throw InvalidInput("index count " + std::to_string(index_count) +
                           " is not a multiple of 3 (triangle lists only)");
    if (index_count > 0 && indices == nullptr) throw InvalidInput("index buffer is null");
    if (vertex_count > UINT32_MAX)
        throw InvalidInput("vertex count " + std::to_string(vertex_count) + " exceeds 32-bit indices");
    // One branch-free pass finds the largest index; only a failure pays for locating it.
    uint32_t largest = 0;
    for (size_t i = 0; i < index_count; ++i) largest = indices[i] > largest ? indices[i] : largest;
    if (index_count > 0 && largest >= vertex_count) {
        for (size_t i = 0; i < index_count; ++i)
            if (indices[i] >= vertex_count)
                throw InvalidInput("index " + std::to_string(i) + " (triangle " + std::to_string(i / 3) + ") is " +
                                   std::to_string(indices[i]) + ", but there are only " + std::to_string(vertex_count) +
                                   " vertices");
    }
}

void validate_triangle_order(const uint32_t* order, size_t triangle_count) {
    if (triangle_count > 0 && order == nullptr) throw InvalidInput("triangle order is null");
    std::vector<uint8_t> seen(triangle_count, 0);  // bytes: faster than vector<bool> here
    for (size_t i = 0; i < triangle_count; ++i) {
        const uint32_t t = order[i];
        if (t >= triangle_count)
            throw InvalidInput("triangle order entry " + std::to_string(i) + " is " + std::to_string(t) +
                               ", but there are only " + std::to_string(triangle_count) + " triangles");
        if (seen[t])
            throw InvalidInput("triangle order lists triangle " + std::to_string(t) + " twice (second time at entry " +
                               std::to_string(i) + ")");
        seen[t] = 1;
    }
}

void apply_triangle_order(uint32_t* destination, const uint32_t* indices, const uint32_t* order,
                          size_t triangle_count) {
    validate_triangle_order(order, triangle_count);
    if (triangle_count > 0 && destination == indices)
        throw InvalidInput("apply_triangle_order: destination must not alias indices");
    for (size_t i = 0; i < triangle_count; ++i) {
        const uint32_t* src = indices + 3 * size_t(order[i]);
        destination[3 * i + 0] = src[0];
        destination[3 * i + 1] = src[1];
        destination[3 * i + 2] = src[2];
    }
}

void compose_triangle_orders(uint32_t* destination, const uint32_t* inner, const uint32_t* outer,
                             size_t triangle_count) {
    validate_triangle_order(inner, triangle_count);
    validate_triangle_order(outer, triangle_count);
    for (size_t i = 0; i < triangle_count; ++i) destination[i] = inner[outer[i]];
}

}  // namespace animorder
