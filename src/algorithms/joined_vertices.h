// Private to src/algorithms: vertices at bit-identical positions joined (joined_vertices.cpp),
// for the topology of the surface rather than of the vertex buffer (planar clusters' adjacency,
// `measured`'s surface patches).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace animorder {

// For each vertex, the smallest vertex whose xyz (positions: vertex_count × 3 floats) is
// bit-identical to its own: a UV or normal seam, or flat shading, then no longer cuts the surface.
std::vector<uint32_t> first_vertex_at_each_position(const float* positions, size_t vertex_count);

}  // namespace animorder
