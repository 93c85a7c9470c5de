// animorder — Loop subdivision of (animated) triangle meshes as one reusable linear operator.
//
// The paper's Table 1 also measures Ganfaul after one and two levels of Loop subdivision. The
// topology of an animated mesh never changes, so the subdivision is built once as a sparse
// matrix S (each new vertex a weighted sum of old vertices) and every keyframe is subdivided as
// new_positions = S · old_positions. Definitions and rules: src/algorithms/loop_subdivision.cpp.
#pragma once

#include "animorder/invalid_input.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace animorder {

// The most levels build_loop_subdivision and subdivide_animated_mesh accept (each level
// multiplies the triangles by 4).
constexpr unsigned kMaxSubdivisionLevels = 4;

// Sparse operator S of `levels` levels of Loop subdivision, rows in compressed form: output
// vertex r = Σ weights[k] · input vertex columns[k] for k in [row_starts[r], row_starts[r+1]).
// Columns are ascending within a row and the weights of a row sum to 1 (an affine combination).
struct SubdivisionOperator {
    unsigned levels = 0;
    size_t input_vertex_count = 0;
    size_t output_vertex_count = 0;
    std::vector<size_t> row_starts;  // output_vertex_count + 1 entries
    std::vector<uint32_t> columns;
    std::vector<double> weights;
    // The subdivided triangle list over the output vertices, counter-clockwise like its parent:
    // input triangle t becomes the 4^levels consecutive triangles starting at 4^levels · t.
    // Output vertices 0 .. input_vertex_count − 1 are the input vertices (even vertices) moved by
    // the vertex rule; new edge vertices follow in order of first use.
    std::vector<uint32_t> indices;
};

// Builds S for `levels` levels of Loop subdivision (Loop 1987, with Loop's β; boundary and
// non-manifold edges are creases). weld_positions (keyframe 0, position_stride bytes apart, or
// nullptr for no welding): vertices at identical positions are one surface vertex for the
// topology — a UV seam is subdivided as if it were not there — while they stay separate output
// vertices (each split edge gets its own edge vertex) with identical rows, so copies coincide in
// every keyframe. levels 0 gives the identity. Throws InvalidInput for levels >
// kMaxSubdivisionLevels, an invalid index buffer, a non-finite weld position, or a result of
// more than 2^31 indices.
SubdivisionOperator build_loop_subdivision(const uint32_t* indices, size_t index_count, const float* weld_positions,
                                           size_t vertex_count, size_t position_stride, unsigned levels);

// destination (op.output_vertex_count tightly packed xyz floats) = S · positions (op.input_vertex_count
// xyz floats, position_stride bytes apart). Sums in double. destination must not alias positions.
void apply_subdivision(float* destination, const SubdivisionOperator& op, const float* positions,
                       size_t position_stride);

}  // namespace animorder
