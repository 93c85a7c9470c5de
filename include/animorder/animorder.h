// animorder — triangle reordering for animated meshes.
//
// The algorithm layer: plain functions over plain arrays, in the spirit of meshoptimizer.
// Destination first, then inputs; counts are size_t; strides are in bytes; no hidden state.
// Nothing here reads or writes files. Definitions (ACMR, patches, keyframes, ...) follow
// shared/docs/DESIGN.md exactly; each function names the paper section it implements.
//
// Orders are *face permutations* (DirectXMesh style): order[i] is the input triangle drawn
// i-th. A permutation never changes a triangle's corners or their winding; apply it with
// apply_triangle_order(). Empty input is a no-op. Invalid input (an index >= vertex_count, an
// index count that is not a multiple of 3, a bad permutation) throws animorder::InvalidInput,
// in Release builds too.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace animorder {

// Thrown for input the algorithms cannot accept; what() says which argument and why.
class InvalidInput : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// The cache size every report uses unless told otherwise (DESIGN.md: FIFO of 16 entries).
constexpr unsigned kDefaultCacheSize = 16;

// ---------------------------------------------------------------------------------------------
// Validation and permutations (triangle_order.cpp)

// Throws InvalidInput unless index_count is a multiple of 3 and every index < vertex_count.
void validate_indices(const uint32_t* indices, size_t index_count, size_t vertex_count);

// Throws InvalidInput unless order[0..triangle_count) is a permutation of 0..triangle_count-1.
void validate_triangle_order(const uint32_t* order, size_t triangle_count);

// destination[3i..3i+2] = indices[3·order[i] ..], corners in their original sequence.
// destination must not alias indices. order must be a valid permutation (validated).
void apply_triangle_order(uint32_t* destination, const uint32_t* indices, const uint32_t* order,
                          size_t triangle_count);

// order = composition: result[i] = inner[outer[i]] (outer indexes positions of inner's output).
void compose_triangle_orders(uint32_t* destination, const uint32_t* inner, const uint32_t* outer,
                             size_t triangle_count);

// ---------------------------------------------------------------------------------------------
// Vertex cache analysis (vertex_cache.cpp)

struct VertexCacheStats {
    size_t misses = 0;             // vertices transformed (FIFO misses)
    size_t triangles = 0;          // triangles drawn
    size_t referenced_vertices = 0;  // distinct vertices the index buffer references
    double acmr = 0;               // misses / triangles (0 for empty input)
    double atvr = 0;               // misses / referenced_vertices (0 for empty input)
};

// Simulates a FIFO post-transform cache of cache_size entries that starts empty, drawing the
// triangles in index-buffer order; each corner is looked up, then inserted on a miss. A hit does
// not refresh an entry (FIFO, not LRU). ATVR divides by the vertices actually referenced, so an
// index buffer that transforms each of its vertices once has ATVR 1.
VertexCacheStats analyze_vertex_cache(const uint32_t* indices, size_t index_count,
                                      size_t vertex_count, unsigned cache_size = kDefaultCacheSize);

// ---------------------------------------------------------------------------------------------
// Tipsify (tipsify.cpp) — Sander, Nehab & Barczak 2007, §3.

struct TipsifyResult {
    // Output positions (indices into the produced order) of the first triangle emitted after each
    // dead-end jump (Skip-Dead-End), ascending. Position 0 is not listed: it starts everything.
    std::vector<uint32_t> hard_boundaries;
};

// Writes a vertex-cache-friendly face permutation of the triangles to order[0..index_count/3).
// cache_size is the target FIFO size k (>= 3). Runs in time linear in the input.
TipsifyResult tipsify(uint32_t* order, const uint32_t* indices, size_t index_count,
                      size_t vertex_count, unsigned cache_size = kDefaultCacheSize);

// The same order written directly as an index buffer (what tipsify + apply_triangle_order give,
// in one pass). destination must not alias indices.
TipsifyResult tipsify_index_buffer(uint32_t* destination, const uint32_t* indices, size_t index_count,
                                   size_t vertex_count, unsigned cache_size = kDefaultCacheSize);

// ---------------------------------------------------------------------------------------------
// Patches: fast linear clustering (patches.cpp) — Sander et al. 2007, §4; Han & Sander 2017 §3.1.

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
                                    const uint32_t* hard_boundaries, size_t hard_boundary_count,
                                    double lambda, unsigned cache_size = kDefaultCacheSize);

// Expands a patch permutation to a triangle permutation: triangles of patch_order[0] first (in
// their order inside the patch), then patch_order[1], and so on. order has one entry per triangle.
void expand_patch_order(uint32_t* order, const uint32_t* patch_order, const uint32_t* patch_starts,
                        size_t patch_count);

// ---------------------------------------------------------------------------------------------
// static-sander07 (static_sander07.cpp) — Sander et al. 2007, §5, equation 4.

// Per patch: area-weighted centroid C(P) and area-weighted average normal N(P) of its triangles
// (the normal is the mean of unit normals weighted by area, not renormalised), and the mesh's
// area-weighted surface centroid C(M). rank(P) = (C(P) − C(M))·N(P). Writes patch_order: patches
// by descending rank, ties by ascending patch id. positions: vertex_count xyz floats with
// position_stride bytes between vertices.
void sort_patches_sander07(uint32_t* patch_order, const uint32_t* indices, size_t index_count,
                           const float* positions, size_t vertex_count, size_t position_stride,
                           const uint32_t* patch_starts, size_t patch_count);

struct StaticOrderResult {
    size_t patch_count = 0;
    size_t hard_boundary_count = 0;
};

// The whole static-sander07 method: tipsify, cut into patches with lambda, sort the patches with
// equation 4 at the given positions. order: a face permutation of the input triangles.
StaticOrderResult order_static_sander07(uint32_t* order, const uint32_t* indices, size_t index_count,
                                        const float* positions, size_t vertex_count,
                                        size_t position_stride, double lambda = kDefaultLambda,
                                        unsigned cache_size = kDefaultCacheSize);

}  // namespace animorder
