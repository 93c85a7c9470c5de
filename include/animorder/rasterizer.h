// animorder — the rasteriser of one node (rasterizer.cpp; DESIGN.md "Rasterisation rules").
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace animorder {

// One node's rasterisation under DESIGN.md's rules: pixel centres at +0.5, top-left fill rule
// (after flipping OpenGL's window y to point down), vertices snapped to 1/256 pixel, depth
// linear in screen space, LESS against a buffer cleared to 1, back faces (clockwise in OpenGL
// window space) culled unless the triangle is double-sided, triangles clipped against the near and far planes. It keeps, for every
// pixel, the fragments of all front-facing triangles sorted by depth, so scoring an order never
// needs another rasterisation. Reuse one instance across nodes: its buffers are kept.
// Per-triangle drawing modes (bits) for NodeRasterizer::rasterize.
constexpr uint8_t kDrawBothFaces = 1;  // double-sided material: the back face is drawn too
constexpr uint8_t kSkipTriangle = 2;   // not drawn in this pass (blended triangles in the opaque pass)

class NodeRasterizer {
public:
    NodeRasterizer();
    ~NodeRasterizer();
    NodeRasterizer(NodeRasterizer&&) noexcept;
    NodeRasterizer& operator=(NodeRasterizer&&) noexcept;

    // Rasterises the triangle list (clip-space positions, 4 floats per vertex) into a square
    // viewport of resolution × resolution pixels. Replaces the previous node. modes: null (every
    // triangle drawn, back faces culled) or one byte per triangle of kDrawBothFaces (a glTF
    // doubleSided material) and kSkipTriangle (not in this pass) bits.
    void rasterize(const float* clip_xyzw, size_t vertex_count, const uint32_t* indices, size_t index_count,
                   unsigned resolution, const uint8_t* modes = nullptr);

    // rasterize for indices the caller has already checked with validate_indices against this
    // vertex_count (a mesh drawn at many nodes is checked once, not once per node). Unchecked
    // indices here are undefined behaviour; everything else (the resolution) is still checked.
    // candidates: null, or `candidate_count` ascending triangle indices below index_count / 3
    // (FacingFilter's, unchecked like the indices) outside which no triangle draws at this node:
    // the same fragments, fewer triangles looked at. They are ignored when any vertex, drawn or
    // not, is clipped or far outside the viewport (the filter vouches for neither).
    void rasterize_validated(const float* clip_xyzw, size_t vertex_count, const uint32_t* indices, size_t index_count,
                             unsigned resolution, const uint8_t* modes = nullptr, const uint32_t* candidates = nullptr,
                             size_t candidate_count = 0);

    // The vertices as positions moved to the frame's centre (one array per coordinate) and a
    // view-projection matrix (column-major, in float): the clip-space positions transform_to_clip
    // gives (its float operations, in its order), computed in the vertex pass instead of stored and
    // read back. The same fragments as rasterize_validated of transform_to_clip's array.
    struct CentredVertices {
        const float* x = nullptr;
        const float* y = nullptr;
        const float* z = nullptr;
        float view_projection[16] = {};
    };
    void rasterize_validated(const CentredVertices& vertices, size_t vertex_count, const uint32_t* indices,
                             size_t index_count, unsigned resolution, const uint8_t* modes = nullptr,
                             const uint32_t* candidates = nullptr, size_t candidate_count = 0);

    // The per-node code is compiled in up to three copies, each doing the same operations in the
    // same order, so each giving the same bits: portable (SSE2 on x86-64); AVX2, where the CPU
    // has it; AVX-512, the AVX2 copy compiled with AVX-512 (F, VL, BW, DQ) allowed at the same
    // 256-bit vector width (more registers, mask registers, 64-bit integer lanes), where the CPU
    // has that. rasterize runs the widest copy the CPU has, or at most the one set_copy names
    // (tests compare them; benchmarks time each).
    enum class Copy : uint8_t { Portable, Avx2, Avx512 };
    static Copy widest_copy();           // the widest copy this CPU runs
    static const char* copy_name(Copy);  // "portable", "AVX2", "AVX-512"
    void set_copy(Copy widest);          // at most this copy from now on (default: widest_copy())
    Copy copy() const;                   // the copy rasterize runs: set_copy's, or narrower where the CPU lacks it

    // Pixels covered by at least one fragment (what the depth buffer shows after any order).
    uint64_t visible_pixels() const;
    // Fragments generated (what a draw with the depth test off would shade).
    uint64_t fragments() const;

    // For each of order_count orders (rank table from make_rank_table), the fragments that pass
    // the depth test when the triangles are drawn in that order.
    void score(uint64_t* passed, const uint32_t* ranks, size_t order_count) const;

    // Per pixel (row 0 at the top), fragments passing the depth test under one order
    // (order_index of the rank table): the heatmap behind the paper's Figure 1.
    std::vector<uint32_t> passed_per_pixel(const uint32_t* ranks, size_t order_count, size_t order_index) const;

    unsigned resolution() const;

    // Calls visit(pixel, triangle, depth) for every fragment of the node (pixel = row · resolution
    // + column, row 0 at the top; triangle = index in the rasterised triangle list).
    void visit_fragments(const std::function<void(uint32_t, uint32_t, float)>& visit) const;

    // The node's fragments in the compact form scoring needs (see NodeFragments).
    struct NodeFragments export_fragments() const;

    // The same lists without a copy: starts has pixels + 1 offsets into fragments. Valid until the
    // next rasterize.
    struct FragmentLists {
        uint64_t visible = 0, single = 0;
        const uint32_t* starts = nullptr;
        size_t pixels = 0;
        const uint32_t* fragments = nullptr;
    };
    FragmentLists fragment_lists() const;

    // The node's transparent pass (see BlendFragments): blended[t] non-zero marks the triangles
    // of blended primitives; every other triangle is opaque and writes depth.
    struct BlendFragments export_blend_fragments(const uint8_t* blended) const;

    struct State;  // defined in src/overdraw/raster_state.h, private to the rasteriser's files

private:
    std::unique_ptr<State> state_;
};

// What scoring needs of a rasterised node, and nothing more: the visible and single-fragment pixel
// counts, and for each pixel with several fragments its triangles nearest first (the top bit marks
// a depth equal to the previous fragment's). Orders never change it, so k-means keeps it between
// iterations instead of rasterising the node again.
struct NodeFragments {
    uint64_t visible = 0;
    uint64_t single = 0;
    std::vector<uint32_t> starts;     // multi-fragment pixels + 1
    std::vector<uint32_t> fragments;  // triangle | tie bit
    size_t bytes() const { return (starts.size() + fragments.size()) * 4 + sizeof(*this); }
};

// passed[o] for each order of the rank table, from a node's fragments (NodeRasterizer::score
// gives the same numbers).
void score_fragments(uint64_t* passed, const NodeFragments& node, const uint32_t* ranks, size_t order_count);

// The transparent pass of a node (DESIGN.md "Blend error"): the opaque triangles drawn first fill
// the depth buffer, then the blended ones with the depth test on (LESS) and depth writes off. A
// blended fragment counts iff it is nearer than every opaque fragment of its pixel. Per pixel
// with two or more such fragments, their triangles nearest first (kTieBit-style top bit: depth
// equal to the previous one's).
struct BlendFragments {
    uint64_t covered = 0;             // pixels with at least one counted blended fragment
    std::vector<uint32_t> pixels;     // the pixels with two or more
    std::vector<uint32_t> starts;     // pixels.size() + 1
    std::vector<uint32_t> fragments;  // triangle | tie bit
};

// Blend error of orders at a node: a pair of counted fragments of one pixel at different depths
// is mis-sorted when the nearer one is drawn first (blending needs back to front).
struct BlendCounts {
    uint64_t pairs = 0;             // pairs at different depths
    uint64_t missorted_pairs = 0;   // of which drawn nearer-before-farther
    uint64_t missorted_pixels = 0;  // pixels with at least one mis-sorted pair
    uint64_t covered = 0;           // BlendFragments::covered
};

// counts[o] for each order of the rank table (make_rank_table).
void score_blend(BlendCounts* counts, const BlendFragments& node, const uint32_t* ranks, size_t order_count);

// Per pixel (row 0 at the top) of a resolution² image: the mis-sorted pairs under one order.
std::vector<uint32_t> missorted_per_pixel(const BlendFragments& node, unsigned resolution, const uint32_t* ranks,
                                          size_t order_count, size_t order_index);

}  // namespace animorder
