// Private to src/overdraw: the rasteriser's per-node state and the types its files share:
// rasterizer.cpp (the NodeRasterizer API and the choice of copy), rasterize_node.h with its three
// compiled copies rasterize_node_{portable,avx2,avx512}.cpp, fragment_scoring.cpp (replaying the
// kept fragments under many orders) and blend_fragments.cpp (blended primitives' pairs).
#pragma once

#include "animorder/camera.h"
#include "animorder/rasterizer.h"

#include "always_inline.h"

#include <cstddef>
#include <cstdint>
#include <vector>

#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
#define ANIMORDER_RASTER_AVX2 1
#include <immintrin.h>
#endif
#ifdef __SSE2__
#include <emmintrin.h>
#endif

namespace animorder {

// A vertex in window space: snapped fixed-point x and y (y down, pixel centres at integer
// multiples of 256) for coverage, float x, y (same frame, in pixels) and depth for the depth plane.
struct WindowVertex {
    int64_t X, Y;
    float x, y, z;
};

struct Fragment {
    uint32_t pixel;
    uint32_t triangle;
    float depth;
};

namespace raster {

constexpr size_t kBatch = 128;  // triangles per pre-pass batch

// rasterize_window_triangle's set-up for a batch of triangles, as straight-line double arithmetic
// over arrays (vectorised). Exact: snapped coordinates are integers below 2^24 in magnitude, so
// every edge-function term is an integer below 2^51; the depth plane repeats the scalar code's
// double operations one for one.
struct BatchSetup {
    // In: corners in positive order (snapped X, Y), first pixel centre of the box, the plane
    // differences (corner 1 − corner 0, corner 2 − corner 0, in float) and corner 0.
    double X[3][kBatch], Y[3][kBatch], px0[kBatch], py0[kBatch];
    double ax[kBatch], ay[kBatch], az[kBatch], bx[kBatch], by[kBatch], bz[kBatch], x[kBatch], y[kBatch], z[kBatch];
    // Out: edge functions at the first pixel centre and their steps, the plane.
    double e[3][kBatch], sx[3][kBatch], sy[3][kBatch], det[kBatch], dzdx[kBatch], dzdy[kBatch], z_origin[kBatch];

    // Edge functions for the first `edges` entries of X, Y, px0, py0 and planes for the first
    // `planes` entries of the rest (the triangles of the pre-pass's small-box test need no edges).
    ANIMORDER_ALWAYS_INLINE void compute(size_t edges, size_t planes) {
        for (int k = 0; k < 3; ++k) {
            const int b = (k + 1) % 3;
            for (size_t j = 0; j < edges; ++j) {
                const double dx = X[b][j] - X[k][j], dy = Y[b][j] - Y[k][j];
                // 1 unless a top or left edge (dy < 0, or dy = 0 and dx > 0): branch-free selects.
                const double right = dx > 0.0 ? 0.0 : 1.0;
                const double flat = dy == 0.0 ? right : 1.0;
                const double bias = dy < 0.0 ? 0.0 : flat;
                e[k][j] = dx * (py0[j] * 256.0 - Y[k][j]) - dy * (px0[j] * 256.0 - X[k][j]) - bias;
                sx[k][j] = -dy * 256.0;
                sy[k][j] = dx * 256.0;
            }
        }
        for (size_t j = 0; j < planes; ++j) {
            det[j] = ax[j] * by[j] - ay[j] * bx[j];
            dzdx[j] = (az[j] * by[j] - ay[j] * bz[j]) / det[j];
            dzdy[j] = (ax[j] * bz[j] - az[j] * bx[j]) / det[j];
            z_origin[j] = z[j] - dzdx[j] * x[j] - dzdy[j] * y[j];
        }
    }
};

// Pixels up to which group_fragments chains the fragments through an image of the viewport.
constexpr uint32_t kPixelImageLimit = uint32_t(1) << 20;
constexpr int kSubpixelBits = 8;
constexpr int64_t kSubpixel = int64_t(1) << kSubpixelBits;  // 256
constexpr float kGuardBand = 2.0f;                          // |x|, |y| <= 2w: twice the viewport, never a visible pixel

struct ClipVertex {
    float x, y, z, w;
};

// Where the vertex pass reads the clip-space vertices: an array of them, or positions moved to the
// frame's centre (NodeRasterizer::CentredVertices) transformed as transform_to_clip does
// (clip_row), so the same bits.
struct VertexSource {
    const ClipVertex* clip = nullptr;  // null: the centred positions and m
    const float *x = nullptr, *y = nullptr, *z = nullptr, *m = nullptr;

    ClipVertex operator[](size_t v) const {
        if (clip) return clip[v];
        const float px = x[v], py = y[v], pz = z[v];
        return {clip_row(m, 0, px, py, pz), clip_row(m, 1, px, py, pz), clip_row(m, 2, px, py, pz),
                clip_row(m, 3, px, py, pz)};
    }
};

// The three compiled copies of the per-node code (rasterize_node.h), each in its own file: after
// the checks, rasterise one node into s (s.resolution set).
void rasterize_node_portable(NodeRasterizer::State& s, const VertexSource& source, size_t vertex_count,
                             const uint32_t* indices, size_t index_count, unsigned resolution, const uint8_t* modes,
                             const uint32_t* candidates, size_t candidate_count);
#ifdef ANIMORDER_RASTER_AVX2
void rasterize_node_avx2(NodeRasterizer::State& s, const VertexSource& source, size_t vertex_count,
                         const uint32_t* indices, size_t index_count, unsigned resolution, const uint8_t* modes,
                         const uint32_t* candidates, size_t candidate_count);
void rasterize_node_avx512(NodeRasterizer::State& s, const VertexSource& source, size_t vertex_count,
                           const uint32_t* indices, size_t index_count, unsigned resolution, const uint8_t* modes,
                           const uint32_t* candidates, size_t candidate_count);
#endif

}  // namespace raster

struct NodeRasterizer::State {
    unsigned resolution = 0;
    // Raw fragments, in rasterisation order, as three arrays (pixel, triangle, depth): the first
    // raw_count entries are this node's. One array per field lets the wide copies store a row's
    // covered pixels with a few vector stores. `sorted`, `gathered`: group_fragments' radix sort.
    std::vector<uint32_t> raw_pixel, raw_triangle;
    std::vector<float> raw_depth;
    std::vector<Fragment> sorted, gathered;
    size_t raw_count = 0;
    std::vector<uint32_t> single_pixels;  // pixels with exactly one fragment: the first `single` entries
    // Per pixel fragment count; start of the pixel's slots among the multi-fragment pixels.
    // Pixels with two or more fragments, their fragments nearest first: what scoring walks.
    // A fragment is its triangle index, with kTieBit set when its depth equals the previous one's.
    size_t multi_count = 0;
    std::vector<uint32_t> multi_pixel, multi_start, multi_fragment;
    uint64_t visible = 0, single = 0;
    // Per-vertex setup, done once per node rather than once per triangle corner. The batched
    // pre-pass's view of the vertices: snapped X, Y as int32 (kSpecialVertex for a vertex that
    // cannot take the pre-pass), 8 bytes a vertex, what the pre-pass gathers for every triangle;
    // apart, a 16-byte record of the window-space x, y, z of the depth plane, gathered for the
    // drawn triangles only; why a vertex cannot take the pre-pass (kClippedVertex, kWideVertex; 0
    // when it can). The rare triangles of the exact paths project their corners again (the same
    // function, the same bits).
    struct Snapped {
        int32_t X, Y;
    };
    struct alignas(16) VertexRecord {
        float x, y, z, unused;
    };
    std::vector<Snapped> snapped;
    std::vector<VertexRecord> vertices;
    std::vector<uint8_t> vertex_flags;
    NodeRasterizer::Copy copy = NodeRasterizer::widest_copy();  // set_copy; never wider than the CPU runs
    std::vector<uint32_t> histogram;                            // counting sort of the fragments by pixel
    // group_fragments_by_image's chains: per pixel, 1 + its last fragment (zero between nodes;
    // kPixelImageLimit pixels at most); per fragment, 1 + the one before it in its pixel (0: none).
    std::vector<uint32_t> pixel_last, chain;
    std::vector<uint8_t> touched;  // per 64-pixel block, 1 when it has fragments; zero between nodes
    std::vector<uint64_t> keys;    // (depth, triangle) sort keys of the fragments being grouped
    raster::BatchSetup setup;
};

}  // namespace animorder
