// animorder — the camera of every node (camera.cpp; DESIGN.md "Camera").
#pragma once

#include "animorder/rasterizer.h"

#include <array>
#include <cstddef>
#include <vector>

namespace animorder {

using Mat4d = std::array<double, 16>;  // column-major, as OpenGL

// Camera at distance 3R along the unit direction `view_direction` (from the origin towards the
// eye), looking at the origin, square viewport, vertical field of view 2·asin(1/3) so the sphere
// of radius R exactly fits, near plane at distance R, far at 5R. Up is +Y, or +Z when the view
// direction is within ~2.6° of ±Y. Returns projection · view (OpenGL clip space, z in [−w, w]).
Mat4d node_view_projection(const float view_direction[3], float radius);

// cot of half that field of view: tan(asin(1/3)) = 1/(2√2), so 2√2 (the double nearest).
constexpr double kCotHalfFov = 2.8284271247461903;

// clip[4v..4v+3] = view_projection · (positions[v] − centre, 1), in float as a vertex shader would
// (row by row, ((m·x + m·y) + m·z) + m, no fused multiply-add). Runs a copy compiled for AVX2
// where the CPU has it: the same operations, so the same bits.
void transform_to_clip(float* clip_xyzw, const float* positions, size_t vertex_count, const float centre[3],
                       const Mat4d& view_projection);
// The same, always in the portable copy (tests compare the two).
void transform_to_clip_portable(float* clip_xyzw, const float* positions, size_t vertex_count, const float centre[3],
                                const Mat4d& view_projection);

// transform_to_clip's first step for a whole keyframe, done once for all its views: positions[v] −
// centre in float, into one array per coordinate (x, y, z: vertex_count floats each).
void centre_positions(float* x, float* y, float* z, const float* positions, size_t vertex_count,
                      const float centre[3]);
// The matrix as transform_to_clip uses it: each entry rounded to float.
std::array<float, 16> float_matrix(const Mat4d& m);
// Row `row` of m · (x, y, z, 1) for a centred position, as transform_to_clip computes it and every
// copy of the vertex transform must: ((m[row]·x + m[4+row]·y) + m[8+row]·z) + m[12+row] in float,
// no fused multiply-add (the build turns contraction off).
inline float clip_row(const float* m, int row, float x, float y, float z) {
    return m[row] * x + m[4 + row] * y + m[8 + row] * z + m[12 + row];
}

// A worker's keyframe moved to its frame's centre (centre_positions), kept while its nodes follow
// one another: what NodeRasterizer's centred entry reads, so that no node transforms the whole
// keyframe to clip space apart from its vertex pass.
class CentredKeyframe {
public:
    // Centres the keyframe unless it is the one centred last (same address, count and centre: the
    // positions are compared by address, so they must not change while their nodes are drawn).
    void centre(const float* positions, size_t vertex_count, const float centre[3]);
    // The centred keyframe under a node's view-projection; valid until the next centre().
    NodeRasterizer::CentredVertices vertices(const Mat4d& view_projection) const;

private:
    std::vector<float> xyz_;  // x | y | z: 3 · its vertex count
    const float* positions_ = nullptr;
    float centre_[3] = {0.0f, 0.0f, 0.0f};
};

}  // namespace animorder
