// animorder — triangles of one index buffer found in another (triangle_matching.cpp): by vertex
// indices (is an order a permutation of a primitive's triangles?), by corner data (which
// triangle of a processed mesh is which triangle of the optimised one?) and by nearness (which
// triangle of the optimised mesh does a simplified mesh's triangle stand for?).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace animorder {

// For each triangle t of `order`, the triangle of `base` with the same three vertex indices in
// the same cyclic order (winding kept), every triangle of `base` used once (repeated triangles
// paired in sequence). Empty when `order` is no such permutation of `base` (or has no triangles).
std::vector<uint32_t> triangle_permutation(const uint32_t* base, const uint32_t* order, size_t triangle_count);

// Triangles given by their corners: per triangle, 3 corners of `dims` floats each (positions,
// possibly at several keyframes, and any attributes). Triangle t of `to` matches triangle s of
// `from` when, for one rotation r of to's corners (winding kept, never mirrored), every value of
// corner c lies within `tolerance` of from's corner (c + r) mod 3. Among matching triangles the
// one with the smallest largest difference wins; each triangle of `from` is used at most once,
// `to`'s triangles taken in sequence. Deterministic.
struct TriangleMatch {
    std::vector<int64_t> from_of_to;  // per triangle of `to`: its triangle of `from`, −1 when none
    size_t matched = 0;
};
TriangleMatch match_triangles(const std::vector<float>& from, const std::vector<float>& to, size_t dims,
                              float tolerance);

// For each triangle of `to`, the triangle of `from` whose centroid is nearest (Euclidean distance
// over the centroid's `dims` values: a corner's values averaged over the three corners), and that
// distance; triangles laid out as in match_triangles. Several triangles of `to` may name the same
// one (a simplified mesh's triangles stand for several of the original's). Among equally near
// triangles of `from`, the one the search meets first: the same for the same input. Empty when
// `from` has no triangle.
struct NearestTriangles {
    std::vector<uint32_t> from_of_to;
    std::vector<double> distance;
};
NearestTriangles nearest_triangles(const std::vector<float>& from, const std::vector<float>& to, size_t dims);

}  // namespace animorder
