// animorder — linear blend skinning (skinning.cpp).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace animorder {

// Column-major 4×4 matrix, as glTF stores them.
using Mat4 = std::array<float, 16>;

// For each vertex v: out[v] = Σ_i w[v][i] · (joint_matrices[j[v][i]] · bind[v]), over
// influences_per_vertex influences. Weights are normalised by their sum when it is not 1 (and a
// vertex whose weights sum to 0 keeps its bind position). joints and weights are
// vertex_count × influences_per_vertex arrays. Throws InvalidInput for a joint index >=
// joint_count or a non-finite weight.
void skin_positions(float* out_positions, const float* bind_positions, size_t vertex_count, const uint16_t* joints,
                    const float* weights, size_t influences_per_vertex, const Mat4* joint_matrices, size_t joint_count);

}  // namespace animorder
