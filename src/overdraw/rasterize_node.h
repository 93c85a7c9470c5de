// Private to src/overdraw: the per-node code of the rasteriser (DESIGN.md's rasterisation rules;
// the method is described at the top of rasterizer.cpp), as one template that each of
// rasterize_node_{portable,avx2,avx512}.cpp compiles for its own instructions: project the
// vertices, pre-pass and set up the triangles in batches, walk their edge functions, clip the
// few that need it, and group the fragments by pixel, nearest first.
//
#include <string>

// The per-node code is compiled three times (rasterize_node below): portable (SSE2 on x86-64)
// and, on x86 with GCC or Clang, for AVX2 (wider vectors for the batched pre-pass and set-up)
// and for AVX-512 at 256-bit width (the AVX2 copy's source; the compiler's loops gain mask
// registers, 32 vector registers and 64-bit integer lanes), each run where the CPU has it. All do
// the same IEEE operations in the same order (no FMA: the build turns contraction off), so they
// give the same bits; test_rasterizer compares them.
// Everything here has internal linkage: each copy's file gets its own instances, inlined into it.
#pragma once

#include "raster_state.h"

#include "animorder/invalid_input.h"
#include "animorder/triangle_order.h"

#include "fragment_encoding.h"
#include "lane_packing.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace animorder {
namespace raster {
namespace {

// llvmpipe's util_iround: round half away from zero.
int64_t round_half_away(float v) { return int64_t(v >= 0.0f ? v + 0.5f : v - 0.5f); }

// Floor and ceiling of a / kSubpixel: an arithmetic shift rounds towards minus infinity.
int64_t floor_subpixel(int64_t a) { return a >> kSubpixelBits; }
int64_t ceil_subpixel(int64_t a) { return -((-a) >> kSubpixelBits); }

// Where the rasteriser puts fragments (pixel, triangle, depth). Capacity is ensured once per
// triangle (its bounding box bounds its fragments), so a fragment is one plain store.
struct FragmentSink {
    std::vector<uint32_t>& pixel;
    std::vector<uint32_t>& triangle;
    std::vector<float>& depth;
    size_t count = 0;

    void reserve_more(size_t more) {
        if (count + more <= pixel.size()) return;
        const size_t size = std::max(2 * pixel.size(), count + more);
        pixel.resize(size);
        triangle.resize(size);
        depth.resize(size);
    }
};

inline void project(const ClipVertex& v, unsigned resolution, WindowVertex& out) {
    const float half = 0.5f * float(resolution);
    const float inv_w = 1.0f / v.w;
    const float x = v.x * inv_w * half + half;  // OpenGL window coordinates, y up
    const float y = v.y * inv_w * half + half;
    out.z = v.z * inv_w * 0.5f + 0.5f;
    const int64_t top_row = int64_t(resolution - 1) * kSubpixel;
    out.X = round_half_away((x - 0.5f) * float(kSubpixel));
    out.Y = top_row - round_half_away((y - 0.5f) * float(kSubpixel));  // y down, centres at integers
    out.x = x - 0.5f;
    out.y = float(resolution) - y - 0.5f;
}

// What the full set-up needs first, and the cheap reasons to skip it: the signed area (zero, or
// a culled back face: nothing drawn) and the pixel centres inside the bounding box (none: nothing
// drawn, the fate of most small triangles of a character).
struct TriangleBox {
    int64_t area, px0, px1, py0, py1;
};

inline bool triangle_box(const WindowVertex& v0, const WindowVertex& v1, const WindowVertex& v2, unsigned resolution,
                         bool two_sided, TriangleBox& box) {
    // With y pointing down, OpenGL's counter-clockwise front faces have negative area.
    box.area = (v1.X - v0.X) * (v2.Y - v0.Y) - (v2.X - v0.X) * (v1.Y - v0.Y);
    if (box.area == 0 || (box.area > 0 && !two_sided)) return false;  // zero area, or a culled back face
    const int64_t min_x = std::min({v0.X, v1.X, v2.X}), max_x = std::max({v0.X, v1.X, v2.X});
    const int64_t min_y = std::min({v0.Y, v1.Y, v2.Y}), max_y = std::max({v0.Y, v1.Y, v2.Y});
    box.px0 = std::max<int64_t>(0, ceil_subpixel(min_x));
    box.px1 = std::min<int64_t>(resolution - 1, floor_subpixel(max_x));
    box.py0 = std::max<int64_t>(0, ceil_subpixel(min_y));
    box.py1 = std::min<int64_t>(resolution - 1, floor_subpixel(max_y));
    return box.px0 <= box.px1 && box.py0 <= box.py1;
}

// Writes the fragments of one set-up triangle: edge functions at the box's first pixel centre and
// their steps, the depth plane. Every pixel of the box is written and the count advances only for
// a covered pixel whose depth lies in [0, 1): no branch on coverage.
ANIMORDER_ALWAYS_INLINE void emit_box(const int64_t (&e_first)[3], const int64_t (&step_x)[3],
                                      const int64_t (&step_y)[3], double dzdx, double dzdy, double z_origin,
                                      const TriangleBox& box, uint32_t triangle, unsigned resolution,
                                      FragmentSink& sink) {
    const int64_t px0 = box.px0, px1 = box.px1, py0 = box.py0, py1 = box.py1;
    int64_t e_row[3] = {e_first[0], e_first[1], e_first[2]};
    sink.reserve_more(size_t(px1 - px0 + 1) * size_t(py1 - py0 + 1));
    uint32_t* out_pixel = sink.pixel.data();
    uint32_t* out_triangle = sink.triangle.data();
    float* out_depth = sink.depth.data();
    size_t count = sink.count;
    for (int64_t py = py0; py <= py1; ++py) {
        int64_t e0 = e_row[0], e1 = e_row[1], e2 = e_row[2];
        const double z_row = z_origin + dzdy * double(py);
        const uint32_t row = uint32_t(py * resolution);
        double x = double(px0);  // double(px), exactly
        for (int64_t px = px0; px <= px1; ++px, x += 1.0) {
            const float depth = float(z_row + dzdx * x);
            out_pixel[count] = row + uint32_t(px);
            out_triangle[count] = triangle;
            out_depth[count] = depth;
            count += size_t((e0 | e1 | e2) >= 0) & size_t(depth < 1.0f) & size_t(depth >= 0.0f);
            e0 += step_x[0];
            e1 += step_x[1];
            e2 += step_x[2];
        }
        e_row[0] += step_y[0];
        e_row[1] += step_y[1];
        e_row[2] += step_y[2];
    }
    sink.count = count;
}

#ifdef ANIMORDER_RASTER_AVX2
// For each 4-bit mask of lanes, those lanes in order (then lane 0 as filler), and how many.
struct LaneCompaction {
    alignas(16) int32_t lanes[16][4] = {};
    uint8_t count[16] = {};
    constexpr LaneCompaction() {
        for (int mask = 0; mask < 16; ++mask) {
            int n = 0;
            for (int lane = 0; lane < 4; ++lane)
                if (mask >> lane & 1) lanes[mask][n++] = lane;
            count[mask] = uint8_t(n);
        }
    }
};
constexpr LaneCompaction kLaneCompaction;

// Four pixels' fragments in the wide (AVX2, AVX-512) copies: the lanes set in `covered` (bit k for
// lane k) whose depth (z, rounded to float) lies in [0, 1), packed to the front and stored at
// `count` (one 16-byte store per array, whatever the count); returns the new count.
__attribute__((target("avx2"))) ANIMORDER_ALWAYS_INLINE size_t emit_lanes_avx2(int covered, __m256d z, __m128i pixels,
                                                                               __m128i triangles, FragmentSink& sink,
                                                                               size_t count) {
    const __m128 depth = _mm256_cvtpd_ps(z);
    const __m128 in_range = _mm_and_ps(_mm_cmplt_ps(depth, _mm_set1_ps(1.0f)), _mm_cmpge_ps(depth, _mm_setzero_ps()));
    const int mask = covered & _mm_movemask_ps(in_range);
    const __m128i order = _mm_load_si128(reinterpret_cast<const __m128i*>(kLaneCompaction.lanes[mask]));
    _mm_storeu_ps(reinterpret_cast<float*>(sink.pixel.data() + count),
                  _mm_permutevar_ps(_mm_castsi128_ps(pixels), order));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(sink.triangle.data() + count), triangles);
    _mm_storeu_ps(sink.depth.data() + count, _mm_permutevar_ps(depth, order));
    return count + kLaneCompaction.count[mask];
}

// One group of four pixels in the wide copies: emit_lanes_avx2 of the lanes whose three edge
// values are >= 0 and that lie in the box.
__attribute__((target("avx2"))) ANIMORDER_ALWAYS_INLINE size_t emit_group_avx2(__m256d a0, __m256d a1, __m256d a2,
                                                                               __m256d in_box, __m256d z,
                                                                               __m128i pixels, __m128i triangles,
                                                                               FragmentSink& sink, size_t count) {
    const __m256d zero = _mm256_setzero_pd();
    const __m256d covered =
        _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(a0, zero, _CMP_GE_OQ), _mm256_cmp_pd(a1, zero, _CMP_GE_OQ)),
                      _mm256_and_pd(_mm256_cmp_pd(a2, zero, _CMP_GE_OQ), in_box));
    return emit_lanes_avx2(_mm256_movemask_pd(covered), z, pixels, triangles, sink, count);
}

// emit_box in the wide copies, from BatchSetup's doubles (no conversion to int64): 4 pixels of a row
// at a time, in double lanes. Exact: the edge values e + k·step_x + r·step_y are integers below
// 2^53 in magnitude (BatchSetup's bound plus at most 2 · 2^14 · 2^33), so double holds them, sums
// included, and their signs decide coverage as in emit_box; the depth of a lane is
// emit_box's float(z_row + dzdx · double(px)), the same multiply, add and conversion (to nearest,
// no FMA). The covered lanes are packed to the front (a lane permutation) and stored to the three
// arrays with one 16-byte store each: the fragments of emit_box, in its order. Up to 3 slots past
// the fragments are written too (reserved). A box at most 4 pixels wide (most of them) takes one
// group a row without an inner loop: the same lanes, so the same values.
template <NodeRasterizer::Copy>  // one instance a wide copy: each inlines its own
__attribute__((target("avx2"))) void emit_box_avx2(const double (&e_first)[3], const double (&step_x)[3],
                                                   const double (&step_y)[3], double dzdx, double dzdy, double z_origin,
                                                   const TriangleBox& box, uint32_t triangle, unsigned resolution,
                                                   FragmentSink& sink) {
    const int64_t px0 = box.px0, px1 = box.px1, py0 = box.py0, py1 = box.py1;
    double e_row[3] = {e_first[0], e_first[1], e_first[2]};
    sink.reserve_more(size_t(px1 - px0 + 1) * size_t(py1 - py0 + 1) + 4);
    size_t count = sink.count;
    const __m256d lane = _mm256_set_pd(3.0, 2.0, 1.0, 0.0);
    const __m128i lane_index = _mm_set_epi32(3, 2, 1, 0);
    __m256d lane_step[3], group_step[3];
    for (int i = 0; i < 3; ++i) {
        lane_step[i] = _mm256_mul_pd(lane, _mm256_set1_pd(step_x[i]));
        group_step[i] = _mm256_set1_pd(4.0 * step_x[i]);
    }
    const __m256d slope = _mm256_set1_pd(dzdx), last = _mm256_set1_pd(double(px1));
    const __m128i triangles = _mm_set1_epi32(int32_t(triangle));
    if (px1 - px0 < 4) {  // a box at most 4 pixels wide (most drawn boxes): one group a row, no inner loop
        const __m256d x = _mm256_add_pd(_mm256_set1_pd(double(px0)), lane);
        const __m256d in_box = _mm256_cmp_pd(x, last, _CMP_LE_OQ);
        const __m256d slope_x = _mm256_mul_pd(slope, x);
        __m256d a0 = _mm256_add_pd(_mm256_set1_pd(e_row[0]), lane_step[0]);
        __m256d a1 = _mm256_add_pd(_mm256_set1_pd(e_row[1]), lane_step[1]);
        __m256d a2 = _mm256_add_pd(_mm256_set1_pd(e_row[2]), lane_step[2]);
        const __m256d row_step0 = _mm256_set1_pd(step_y[0]), row_step1 = _mm256_set1_pd(step_y[1]),
                      row_step2 = _mm256_set1_pd(step_y[2]);
        for (int64_t py = py0; py <= py1; ++py) {
            const __m256d z_row = _mm256_set1_pd(z_origin + dzdy * double(py));
            const uint32_t row = uint32_t(py * resolution);
            const __m128i pixels = _mm_add_epi32(_mm_set1_epi32(int32_t(row + uint32_t(px0))), lane_index);
            count = emit_group_avx2(a0, a1, a2, in_box, _mm256_add_pd(z_row, slope_x), pixels, triangles, sink, count);
            a0 = _mm256_add_pd(a0, row_step0);
            a1 = _mm256_add_pd(a1, row_step1);
            a2 = _mm256_add_pd(a2, row_step2);
        }
        sink.count = count;
        return;
    }
    for (int64_t py = py0; py <= py1; ++py) {
        const __m256d z_row = _mm256_set1_pd(z_origin + dzdy * double(py));
        const uint32_t row = uint32_t(py * resolution);
        __m256d a0 = _mm256_add_pd(_mm256_set1_pd(e_row[0]), lane_step[0]);
        __m256d a1 = _mm256_add_pd(_mm256_set1_pd(e_row[1]), lane_step[1]);
        __m256d a2 = _mm256_add_pd(_mm256_set1_pd(e_row[2]), lane_step[2]);
        for (int64_t px = px0; px <= px1; px += 4) {
            const __m256d x = _mm256_add_pd(_mm256_set1_pd(double(px)), lane);
            const __m128i pixels = _mm_add_epi32(_mm_set1_epi32(int32_t(row + uint32_t(px))), lane_index);
            count = emit_group_avx2(a0, a1, a2, _mm256_cmp_pd(x, last, _CMP_LE_OQ),
                                    _mm256_add_pd(z_row, _mm256_mul_pd(slope, x)), pixels, triangles, sink, count);
            a0 = _mm256_add_pd(a0, group_step[0]);
            a1 = _mm256_add_pd(a1, group_step[1]);
            a2 = _mm256_add_pd(a2, group_step[2]);
        }
        e_row[0] += step_y[0];
        e_row[1] += step_y[1];
        e_row[2] += step_y[2];
    }
    sink.count = count;
}

// emit_small_box_avx2 for a triangle of the pre-pass's small-box test: its covered centres (cover's
// low four bits, lanes as emit_small_box's) are known, so only the depths are computed, as there.
__attribute__((target("avx2"))) inline void emit_covered_box_avx2(int32_t cover, double dzdx, double dzdy,
                                                                  double z_origin, int32_t px0, int32_t py0,
                                                                  uint32_t triangle, unsigned resolution,
                                                                  FragmentSink& sink) {
    sink.reserve_more(4);
    const double x0 = double(px0), x1 = x0 + 1.0;
    const double z_row0 = z_origin + dzdy * double(py0), z_row1 = z_origin + dzdy * double(py0 + 1);
    const __m256d x = _mm256_set_pd(x1, x0, x1, x0), z_row = _mm256_set_pd(z_row1, z_row1, z_row0, z_row0);
    const uint32_t row = uint32_t(py0) * resolution + uint32_t(px0);
    const __m128i pixels =
        _mm_add_epi32(_mm_set1_epi32(int32_t(row)), _mm_set_epi32(int32_t(resolution + 1), int32_t(resolution), 1, 0));
    sink.count = emit_lanes_avx2(cover, _mm256_add_pd(z_row, _mm256_mul_pd(_mm256_set1_pd(dzdx), x)), pixels,
                                 _mm_set1_epi32(int32_t(triangle)), sink, sink.count);
}

// emit_small_box in the wide copies: the box's four pixels are the four lanes (x0 y0, x1 y0, x0 y1,
// x1 y1, emit_small_box's order), edge values e, e + sx, e + sy, e + sx + sy (integers below 2^53:
// exact in double), the lanes past the box masked, then emit_covered_box_avx2 of the covered
// lanes. Takes BatchSetup's doubles as they are: no conversion to int64.
__attribute__((target("avx2"))) inline void emit_small_box_avx2(const double (&e)[3], const double (&step_x)[3],
                                                                const double (&step_y)[3], double dzdx, double dzdy,
                                                                double z_origin, const TriangleBox& box,
                                                                uint32_t triangle, unsigned resolution,
                                                                FragmentSink& sink) {
    const __m256d zero = _mm256_setzero_pd();
    __m256d covered = _mm256_castsi256_pd(_mm256_set_epi64x(
        box.px1 > box.px0 && box.py1 > box.py0 ? -1 : 0, box.py1 > box.py0 ? -1 : 0, box.px1 > box.px0 ? -1 : 0, -1));
    for (int k = 0; k < 3; ++k) {
        const __m256d a =
            _mm256_add_pd(_mm256_set1_pd(e[k]), _mm256_set_pd(step_x[k] + step_y[k], step_y[k], step_x[k], 0.0));
        covered = _mm256_and_pd(covered, _mm256_cmp_pd(a, zero, _CMP_GE_OQ));
    }
    emit_covered_box_avx2(_mm256_movemask_pd(covered), dzdx, dzdy, z_origin, int32_t(box.px0), int32_t(box.py0),
                          triangle, resolution, sink);
}
#endif

// emit_small_box for a triangle of the pre-pass's small-box test: its covered centres (cover's low
// four bits, in emit_small_box's order) are known, so only the depths are computed, as there.
ANIMORDER_ALWAYS_INLINE void emit_covered_box(int32_t cover, double dzdx, double dzdy, double z_origin, int32_t px0,
                                              int32_t py0, uint32_t triangle, unsigned resolution, FragmentSink& sink) {
    sink.reserve_more(4);
    uint32_t* out_pixel = sink.pixel.data();
    uint32_t* out_triangle = sink.triangle.data();
    float* out_depth = sink.depth.data();
    size_t count = sink.count;
    const double x[2] = {double(px0), double(px0) + 1.0};
    for (int lane = 0; lane < 4; ++lane) {
        const int dx = lane & 1, dy = lane >> 1;
        const double z_row = z_origin + dzdy * double(py0 + dy);
        const float depth = float(z_row + dzdx * x[dx]);
        out_pixel[count] = (uint32_t(py0) + uint32_t(dy)) * resolution + uint32_t(px0) + uint32_t(dx);
        out_triangle[count] = triangle;
        out_depth[count] = depth;
        count += size_t(cover >> lane & 1) & size_t(depth < 1.0f) & size_t(depth >= 0.0f);
    }
    sink.count = count;
}

// emit_box for a box of at most 2 × 2 pixels (most drawn triangles of a character at 256²):
// its four pixels unrolled, those past the box's right or bottom end masked like uncovered ones,
// then emit_covered_box of the covered ones: the same arithmetic and fragment order as emit_box.
ANIMORDER_ALWAYS_INLINE void emit_small_box(const int64_t (&e)[3], const int64_t (&step_x)[3],
                                            const int64_t (&step_y)[3], double dzdx, double dzdy, double z_origin,
                                            const TriangleBox& box, uint32_t triangle, unsigned resolution,
                                            FragmentSink& sink) {
    const bool wide = box.px1 > box.px0, tall = box.py1 > box.py0;
    const bool in_box[4] = {true, wide, tall, wide && tall};
    int32_t cover = 0;
    for (int lane = 0; lane < 4; ++lane) {
        const int64_t dx = lane & 1, dy = lane >> 1;
        const int64_t a0 = e[0] + dx * step_x[0] + dy * step_y[0], a1 = e[1] + dx * step_x[1] + dy * step_y[1],
                      a2 = e[2] + dx * step_x[2] + dy * step_y[2];
        cover |= int32_t(in_box[lane] && (a0 | a1 | a2) >= 0) << lane;
    }
    emit_covered_box(cover, dzdx, dzdy, z_origin, int32_t(box.px0), int32_t(box.py0), triangle, resolution, sink);
}

// Rasterises one window-space triangle that passed triangle_box: fill rule and depth as
// described at the top.
void rasterize_window_triangle(const WindowVertex& v0, const WindowVertex& v1, const WindowVertex& v2,
                               const TriangleBox& box, uint32_t triangle, unsigned resolution, FragmentSink& sink) {
    // Corners with positive area, so edge functions are >= 0 inside: 0, 2, 1 for a front face,
    // 0, 1, 2 for the back face of a double-sided triangle. The fill rule depends on the edges'
    // directions on screen only, not on which corner comes first.
    const WindowVertex* c[3] = {&v0, &v2, &v1};
    if (box.area > 0) std::swap(c[1], c[2]);
    const int64_t px0 = box.px0, px1 = box.px1, py0 = box.py0, py1 = box.py1;

    // Edge a→b: E(P) = (Xb−Xa)(Py−Ya) − (Yb−Ya)(Px−Xa). Top edge: horizontal going right; left
    // edge: going up (y down, clockwise on screen). Other edges exclude their own pixel centres.
    int64_t e_row[3], step_x[3], step_y[3];
    for (int i = 0; i < 3; ++i) {
        const WindowVertex& a = *c[i];
        const WindowVertex& b = *c[(i + 1) % 3];
        const int64_t dx = b.X - a.X, dy = b.Y - a.Y;
        const bool top_left = (dy == 0 && dx > 0) || dy < 0;
        e_row[i] = dx * (py0 * kSubpixel - a.Y) - dy * (px0 * kSubpixel - a.X) - (top_left ? 0 : 1);
        step_x[i] = -dy * kSubpixel;
        step_y[i] = dx * kSubpixel;
    }

    // A box of one pixel (the most common drawn case): its centre covered or nothing drawn.
    if (px0 == px1 && py0 == py1 && (e_row[0] | e_row[1] | e_row[2]) < 0) return;

    // Depth plane through the three window-space vertices (centres at integer coordinates). A
    // float-degenerate sliver (det = 0) draws nothing: no fragment has a defined depth.
    const double ax = c[1]->x - c[0]->x, ay = c[1]->y - c[0]->y, az = c[1]->z - c[0]->z;
    const double bx = c[2]->x - c[0]->x, by = c[2]->y - c[0]->y, bz = c[2]->z - c[0]->z;
    const double det = ax * by - ay * bx;
    if (det == 0.0) return;
    const double dzdx = (az * by - ay * bz) / det;
    const double dzdy = (ax * bz - az * bx) / det;
    const double z_origin = c[0]->z - dzdx * c[0]->x - dzdy * c[0]->y;  // depth at pixel (0, 0)

    emit_box(e_row, step_x, step_y, dzdx, dzdy, z_origin, box, triangle, resolution, sink);
}

// Sutherland–Hodgman against one plane: keeps the part where dot(plane, v) >= 0.
int clip_polygon(const ClipVertex* in, int count, ClipVertex* out, float a, float b, float c, float d) {
    int n = 0;
    for (int i = 0; i < count; ++i) {
        const ClipVertex& p = in[i];
        const ClipVertex& q = in[(i + 1) % count];
        const float dp = a * p.x + b * p.y + c * p.z + d * p.w;
        const float dq = a * q.x + b * q.y + c * q.z + d * q.w;
        if (dp >= 0) out[n++] = p;
        if ((dp >= 0) != (dq >= 0)) {
            const float t = dp / (dp - dq);
            out[n++] = {p.x + t * (q.x - p.x), p.y + t * (q.y - p.y), p.z + t * (q.z - p.z), p.w + t * (q.w - p.w)};
        }
    }
    return n;
}

bool inside_all(const ClipVertex& v) {
    return v.z >= -v.w && v.z <= v.w && std::fabs(v.x) <= kGuardBand * v.w && std::fabs(v.y) <= kGuardBand * v.w;
}

// The rare triangle that crosses the near or far plane or leaves the guard band: clipped in
// clip space, then drawn as a fan (shared fan edges are split exactly by the fill rule).
void rasterize_clipped_triangle(const ClipVertex (&v)[3], uint32_t triangle, unsigned resolution, FragmentSink& sink,
                                bool two_sided) {
    ClipVertex a[12], b[12];
    int n = 3;
    std::copy(v, v + 3, a);
    const float planes[6][4] = {{0, 0, 1, 1},           {0, 0, -1, 1},         {1, 0, 0, kGuardBand},
                                {-1, 0, 0, kGuardBand}, {0, 1, 0, kGuardBand}, {0, -1, 0, kGuardBand}};
    for (const auto& p : planes) {
        n = clip_polygon(a, n, b, p[0], p[1], p[2], p[3]);
        std::copy(b, b + n, a);
        if (n < 3) return;
    }
    WindowVertex w[12];
    for (int i = 0; i < n; ++i) project(a[i], resolution, w[i]);
    for (int i = 1; i + 1 < n; ++i) {
        TriangleBox box;
        if (triangle_box(w[0], w[i], w[i + 1], resolution, two_sided, box))
            rasterize_window_triangle(w[0], w[i], w[i + 1], box, triangle, resolution, sink);
    }
}

// group_fragments for viewports up to kPixelImageLimit pixels, with the same results, at a cost
// that follows the covered pixels, not the viewport. Each pixel's fragments are chained: an image
// (zero between nodes, padded to whole blocks of 64 pixels) holds 1 + the pixel's last fragment,
// and `chain` 1 + each fragment's predecessor in its pixel (0 ends a chain). The blocks with
// fragments (one byte a block, set by a plain store) are walked in pixel order, each as a 64-bit
// mask of its non-empty pixels; both are returned to zero where touched. A pixel's lone fragment
// is only listed; the fragments of the other pixels are read along the chain as (depth, triangle)
// keys, one 64-bit integer each: a depth is a float in [0, 1), whose bits order as its values
// once −0 is made +0 (adding +0 does that), so the keys compare as the pairs (no two are equal:
// a triangle covers a pixel once), and equal high halves are equal depths.
ANIMORDER_ALWAYS_INLINE void group_fragments_by_image(NodeRasterizer::State& s) {
    const size_t n = s.raw_count;
    const uint32_t pixels = s.resolution * s.resolution;
    const size_t blocks = (size_t(pixels) + 63) / 64;
    s.pixel_last.resize(blocks * 64);
    s.touched.resize(blocks);
    if (s.chain.size() < n) s.chain.resize(n);
    if (s.single_pixels.size() < n) s.single_pixels.resize(n);
    if (s.multi_pixel.size() < n) s.multi_pixel.resize(n);
    if (s.multi_start.size() < n + 1) s.multi_start.resize(n + 1);
    if (s.multi_fragment.size() < n + 7) s.multi_fragment.resize(n + 7);
    if (s.keys.size() < n) s.keys.resize(n);
    uint32_t* last = s.pixel_last.data();
    uint32_t* chain = s.chain.data();
    uint8_t* touched = s.touched.data();
    const uint32_t* raw_pixel = s.raw_pixel.data();
    const uint32_t* raw_triangle = s.raw_triangle.data();
    const float* raw_depth = s.raw_depth.data();
    for (size_t f = 0; f < n; ++f) {
        const uint32_t p = raw_pixel[f];
        chain[f] = last[p];
        last[p] = uint32_t(f + 1);
        touched[p >> 6] = 1;  // a plain store: no chain through memory from one fragment to the next
    }
    const auto key = [&](uint32_t f) {
        const float depth = raw_depth[f] + 0.0f;
        uint32_t depth_bits;
        std::memcpy(&depth_bits, &depth, 4);
        return uint64_t(depth_bits) << 32 | raw_triangle[f];
    };
    // Pixels in order: a single one is listed; a multiple one gets its slots, its keys sorted, then
    // its triangles nearest first. Up to 4 keys (nearly all pixels): a sorting network of
    // compare-exchanges on 4 values, the missing ones the largest key, and 4 triangles written
    // (those past the pixel's are overwritten by the next pixel's, or land in the spare slots past
    // the end): no branch on the data. Up to 8: the same on 8 values. More: insertion sort.
    uint32_t* single = s.single_pixels.data();
    uint32_t* multi = s.multi_pixel.data();
    uint32_t* starts = s.multi_start.data();
    uint32_t* out = s.multi_fragment.data();
    size_t singles = 0, multis = 0;
    uint32_t offset = 0;
    constexpr uint64_t kMissing = ~uint64_t(0);
    for (size_t w = 0; w < blocks; ++w) {
        if (!touched[w]) continue;
        touched[w] = 0;
        uint32_t* block = last + w * 64;
        uint64_t nonempty = 0;  // the block's pixels with fragments
#ifdef __SSE2__
        const __m128i zero = _mm_setzero_si128();
        for (int g = 0; g < 16; ++g) {
            const __m128i c = _mm_loadu_si128(reinterpret_cast<const __m128i*>(block + 4 * g));
            const int empty = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(c, zero)));
            nonempty |= uint64_t(empty ^ 15) << (4 * g);
        }
#else
        for (int k = 0; k < 64; ++k) nonempty |= uint64_t(block[k] != 0) << k;
#endif
        for (uint64_t bits_left = nonempty; bits_left; bits_left &= bits_left - 1) {
            const size_t i = size_t(__builtin_ctzll(bits_left));
            const uint32_t p = uint32_t(w * 64 + i);
            const uint32_t f0 = block[i];
            block[i] = 0;
            const uint32_t f1 = chain[f0 - 1];
            if (f1 == 0) {
                single[singles++] = p;
                continue;
            }
            multi[multis] = p;
            starts[multis++] = offset;
            uint32_t* o = out + offset;
            const uint32_t f2 = chain[f1 - 1];
            const uint32_t f3 = f2 ? chain[f2 - 1] : 0;
            const uint32_t f4 = f3 ? chain[f3 - 1] : 0;
            if (f4 == 0) {
                uint64_t v0 = key(f0 - 1), v1 = key(f1 - 1), v2 = f2 ? key(f2 - 1) : kMissing,
                         v3 = f3 ? key(f3 - 1) : kMissing;
                const auto exchange = [](uint64_t& a, uint64_t& b) {
                    const uint64_t lo = a < b ? a : b, hi = a < b ? b : a;
                    a = lo;
                    b = hi;
                };
                exchange(v0, v1);
                exchange(v2, v3);
                exchange(v0, v2);
                exchange(v1, v3);
                exchange(v1, v2);
                o[0] = uint32_t(v0);
                o[1] = uint32_t(v1) | ((v1 >> 32) == (v0 >> 32) ? kTieBit : 0);
                o[2] = uint32_t(v2) | ((v2 >> 32) == (v1 >> 32) ? kTieBit : 0);
                o[3] = uint32_t(v3) | ((v3 >> 32) == (v2 >> 32) ? kTieBit : 0);
                offset += 2 + uint32_t(f2 != 0) + uint32_t(f3 != 0);
                continue;
            }
            uint64_t* k = s.keys.data();  // the pixel's keys, read along its chain
            size_t c = 0;
            for (uint32_t f = f0; f != 0; f = chain[f - 1]) k[c++] = key(f - 1);
            offset += uint32_t(c);
            if (c <= 8) {  // the same with 8 keys: a 19 compare-exchange network, 7 spare slots
                uint64_t v[8];
                for (size_t j = 0; j < 8; ++j) v[j] = j < c ? k[j < c ? j : 0] : kMissing;
                const auto exchange = [&v](int a, int b) {
                    const uint64_t lo = v[a] < v[b] ? v[a] : v[b], hi = v[a] < v[b] ? v[b] : v[a];
                    v[a] = lo;
                    v[b] = hi;
                };
                exchange(0, 2), exchange(1, 3), exchange(4, 6), exchange(5, 7);
                exchange(0, 4), exchange(1, 5), exchange(2, 6), exchange(3, 7);
                exchange(0, 1), exchange(2, 3), exchange(4, 5), exchange(6, 7);
                exchange(2, 4), exchange(3, 5);
                exchange(1, 4), exchange(3, 6);
                exchange(1, 2), exchange(3, 4), exchange(5, 6);
                o[0] = uint32_t(v[0]);
                for (size_t j = 1; j < 8; ++j) o[j] = uint32_t(v[j]) | ((v[j] >> 32) == (v[j - 1] >> 32) ? kTieBit : 0);
                continue;
            }
            for (size_t j = 1; j < c; ++j) {
                const uint64_t moving = k[j];
                size_t at = j;
                for (; at > 0 && k[at - 1] > moving; --at) k[at] = k[at - 1];
                k[at] = moving;
            }
            o[0] = uint32_t(k[0]);
            for (size_t j = 1; j < c; ++j) o[j] = uint32_t(k[j]) | ((k[j] >> 32) == (k[j - 1] >> 32) ? kTieBit : 0);
        }
    }
    starts[multis] = offset;
    s.single = singles;
    s.visible = singles + multis;
    s.multi_count = multis;
}

// Groups the node's fragments by pixel: group_fragments_by_image up to kPixelImageLimit pixels,
// beyond an LSD radix sort on the pixel index in passes of 11 bits (linear in the fragments, never
// a loop over every pixel of the viewport). Each pixel with two or more fragments is then sorted
// by depth into the compact list that scoring walks; a single-fragment pixel only counts, its
// fragment passes under every order.
ANIMORDER_ALWAYS_INLINE void group_fragments(NodeRasterizer::State& s) {
    const uint32_t image_pixels = s.resolution * s.resolution;
    if (image_pixels <= kPixelImageLimit) return group_fragments_by_image(s);
    const size_t n = s.raw_count;
    s.sorted.resize(std::max(s.sorted.size(), n));
    s.gathered.resize(std::max(s.gathered.size(), n));
    for (size_t f = 0; f < n; ++f) s.gathered[f] = {s.raw_pixel[f], s.raw_triangle[f], s.raw_depth[f]};
    const uint32_t pixels = s.resolution * s.resolution;
    int bits = 0;
    while ((uint64_t(1) << bits) < pixels) ++bits;
    Fragment* from = s.gathered.data();
    Fragment* to = s.sorted.data();
    // Up to 2^16 pixels (256²) one counting pass; beyond, passes of 11 bits.
    const int digit_bits = bits <= 16 ? 16 : 11;
    const uint32_t digits = uint32_t(1) << digit_bits;
    s.histogram.resize(digits + 1);
    for (int shift = 0; shift < bits; shift += digit_bits) {
        uint32_t* histogram = s.histogram.data();
        std::fill(histogram, histogram + digits + 1, 0u);
        for (size_t f = 0; f < n; ++f) ++histogram[((from[f].pixel >> shift) & (digits - 1)) + 1];
        for (uint32_t d = 0; d < digits; ++d) histogram[d + 1] += histogram[d];
        for (size_t f = 0; f < n; ++f) to[histogram[(from[f].pixel >> shift) & (digits - 1)]++] = from[f];
        std::swap(from, to);
    }
    // `from` now holds the fragments by pixel (rasterisation order kept within a pixel).
    s.visible = 0;
    s.single_pixels.clear();
    s.multi_pixel.clear();
    s.multi_start.clear();
    if (s.multi_fragment.size() < n) s.multi_fragment.resize(n);
    uint32_t* out = s.multi_fragment.data();
    uint32_t written = 0;
    if (s.keys.size() < n) s.keys.resize(n);
    uint64_t* key_scratch = s.keys.data();
    for (size_t i = 0; i < n;) {
        size_t end = i + 1;
        while (end < n && from[end].pixel == from[i].pixel) ++end;
        ++s.visible;
        if (end - i == 1) {
            s.single_pixels.push_back(from[i].pixel);
        } else {
            // Insertion sort by (depth, triangle) as one 64-bit key: a depth is a float in [0, 1),
            // whose bits order as its values once −0 is made +0 (adding +0 does that); so keys
            // compare as the pair, and equal high halves are equal depths.
            uint64_t* keys = key_scratch;
            for (size_t j = i; j < end; ++j) {
                const float depth = from[j].depth + 0.0f;
                uint32_t bits_of_depth;
                std::memcpy(&bits_of_depth, &depth, 4);
                const uint64_t key = uint64_t(bits_of_depth) << 32 | from[j].triangle;
                size_t k = j - i;
                for (; k > 0 && keys[k - 1] > key; --k) keys[k] = keys[k - 1];
                keys[k] = key;
            }
            s.multi_pixel.push_back(from[i].pixel);
            s.multi_start.push_back(written);
            out[written++] = uint32_t(keys[0]);
            for (size_t j = 1; j < end - i; ++j)
                out[written++] = uint32_t(keys[j]) | ((keys[j] >> 32) == (keys[j - 1] >> 32) ? kTieBit : 0);
        }
        i = end;
    }
    s.multi_count = s.multi_pixel.size();
    s.multi_start.push_back(written);
    s.single = s.single_pixels.size();
}

constexpr uint8_t kClippedVertex = 1;  // outside the near, far or guard-band planes: the triangle is clipped
constexpr uint8_t kWideVertex = 2;     // snapped X or Y not inside ±kCompactLimit (or not a number): exact path
constexpr int64_t kCompactLimit = int64_t(1) << 24;  // |x| <= 1.5 · 16384 pixels is below 2^23
// The snapped X and Y of a clipped or wide vertex: outside ±kCompactLimit, so never a compact
// coordinate, and small enough that the pre-pass's int32 differences and shifts stay defined.
constexpr int32_t kSpecialVertex = int32_t(1) << 30;
// The box test of triangle_box for a batch of triangles whose vertices are all compact and
// unclipped: int32 arithmetic over arrays that the compiler vectorises. keep[i] is non-zero
// exactly when the bounding box, clamped to the viewport, holds a pixel centre.
//
// It also drops from `keep` the pixel-sized triangles that cover none of their box's centres (on
// a character whose triangles are that small, many of the drawn ones), which would be set up only
// to emit nothing. A triangle takes this test when its box has at most 2 × 2 pixels and
// its corners lie within 4 pixels of each other; the test is BatchSetup::compute's edge functions
// at the box's (up to) four centres, corners in positive order (0, 2, 1 for a front face, else 0,
// 1, 2), in int32 lanes: every difference is then below 2^11 in magnitude, every product below 2^21,
// so the values are exact (the orientation too: its area below 2^21). The other triangles' lanes
// compute wrapped values (uint32) that are not used.
//
// For such a triangle, cover[i] holds in its four bits the centres it covers (x0 y0, x1 y0, x0 y1,
// x1 y1: emit_small_box's lanes, those past the box clear), the signs emit_small_box would find:
// a drawn one (it covers some) skips the edge functions' set-up. Else 0.
ANIMORDER_ALWAYS_INLINE void batch_box_test(size_t n, const int32_t* x0, const int32_t* y0, const int32_t* x1,
                                            const int32_t* y1, const int32_t* x2, const int32_t* y2, int32_t last,
                                            int32_t* keep, int32_t (*box)[4], int32_t* cover) {
    constexpr int32_t kNear = 4 * int32_t(kSubpixel);
    for (size_t i = 0; i < n; ++i) {
        const int32_t min_x = std::min(x0[i], std::min(x1[i], x2[i])), max_x = std::max(x0[i], std::max(x1[i], x2[i]));
        const int32_t min_y = std::min(y0[i], std::min(y1[i], y2[i])), max_y = std::max(y0[i], std::max(y1[i], y2[i]));
        const int32_t px0 = std::max(0, -((-min_x) >> kSubpixelBits)), px1 = std::min(last, max_x >> kSubpixelBits);
        const int32_t py0 = std::max(0, -((-min_y) >> kSubpixelBits)), py1 = std::min(last, max_y >> kSubpixelBits);
        box[i][0] = px0;
        box[i][1] = px1;
        box[i][2] = py0;
        box[i][3] = py1;
        // The small-box test.
        const uint32_t area = (uint32_t(x1[i]) - uint32_t(x0[i])) * (uint32_t(y2[i]) - uint32_t(y0[i])) -
                              (uint32_t(x2[i]) - uint32_t(x0[i])) * (uint32_t(y1[i]) - uint32_t(y0[i]));
        const bool front = int32_t(area) < 0;
        const int32_t cx[3] = {x0[i], front ? x2[i] : x1[i], front ? x1[i] : x2[i]};
        const int32_t cy[3] = {y0[i], front ? y2[i] : y1[i], front ? y1[i] : y2[i]};
        const uint32_t X = uint32_t(px0) * uint32_t(kSubpixel), Y = uint32_t(py0) * uint32_t(kSubpixel);
        const uint32_t wide = px1 > px0 ? ~0u : 0u, tall = py1 > py0 ? ~0u : 0u;
        // Per centre, the sign bit set while it is in the box and every edge value so far is >= 0.
        uint32_t inside[4] = {~0u, wide, tall, wide & tall};
        for (int k = 0; k < 3; ++k) {
            const int b = (k + 1) % 3;
            const uint32_t dx = uint32_t(cx[b]) - uint32_t(cx[k]), dy = uint32_t(cy[b]) - uint32_t(cy[k]);
            const int32_t sdx = int32_t(dx), sdy = int32_t(dy);
            const uint32_t bias = sdy < 0 ? 0u : (sdy == 0 ? (sdx > 0 ? 0u : 1u) : 1u);
            const uint32_t e = dx * (Y - uint32_t(cy[k])) - dy * (X - uint32_t(cx[k])) - bias;
            const uint32_t sx = (0u - dy) * uint32_t(kSubpixel), sy = dx * uint32_t(kSubpixel);
            inside[0] &= ~e;
            inside[1] &= ~(e + sx);
            inside[2] &= ~(e + sy);
            inside[3] &= ~(e + sx + sy);
        }
        const bool small = (px1 - px0 < 2) & (py1 - py0 < 2) & (max_x - min_x < kNear) & (max_y - min_y < kNear);
        const bool covered = int32_t(inside[0] | inside[1] | inside[2] | inside[3]) < 0;
        keep[i] = int32_t(px0 <= px1) & int32_t(py0 <= py1) & int32_t(!small | covered);
        const uint32_t lanes =
            inside[0] >> 31 | (inside[1] >> 31) << 1 | (inside[2] >> 31) << 2 | (inside[3] >> 31) << 3;
        cover[i] = small ? int32_t(lanes) : 0;
    }
}

#ifdef ANIMORDER_RASTER_AVX2
// clip_row for 8 vertices: ((m[r]·x + m[4+r]·y) + m[8+r]·z) + m[12+r], rounded as there.
__attribute__((target("avx2"), always_inline)) inline __m256 transform_row_avx2(const __m256 (&m)[16], int r, __m256 x,
                                                                                __m256 y, __m256 z) {
    return _mm256_add_ps(
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(m[r], x), _mm256_mul_ps(m[4 + r], y)), _mm256_mul_ps(m[8 + r], z)),
        m[12 + r]);
}

// The vertex pass of rasterize_node (from centred positions VertexSource's transform first;
// inside_all, project, the compact test, the record) for 8 vertices at a time in the wide copies:
// the same float operations in the same order (a division, products and sums rounded one by one,
// no FMA), so the same bits. Returns how many vertices it
// did (a multiple of 8); the scalar loop does the rest. round_half_away's int64(v ± 0.5f) is
// taken as an int32 truncation where |v ± 0.5f| < 2^30 (the same integer) and the compact test
// as there: X compact iff |t| < 2^24 (t = v ± 0.5f; floats at 2^23 and above are integers), Y
// compact iff top_row − trunc(t) lies inside ±2^24; NaN compares false (not compact).
template <NodeRasterizer::Copy, bool kCentred>  // one instance a wide copy and source: each inlines its own
__attribute__((target("avx2"))) size_t project_vertices_avx2(const VertexSource& source, size_t count,
                                                             unsigned resolution,
                                                             NodeRasterizer::State::Snapped* snapped,
                                                             NodeRasterizer::State::VertexRecord* out, uint8_t* flags) {
    const __m256 half = _mm256_set1_ps(0.5f * float(resolution)), point5 = _mm256_set1_ps(0.5f);
    const __m256 subpixel = _mm256_set1_ps(float(kSubpixel)), guard = _mm256_set1_ps(kGuardBand);
    const __m256 size = _mm256_set1_ps(float(resolution)), zero = _mm256_setzero_ps();
    const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
    const __m256 limit = _mm256_set1_ps(float(kCompactLimit)), limit_y = _mm256_set1_ps(float(int32_t(1) << 30));
    const __m256i top_row = _mm256_set1_epi32(int32_t(int64_t(resolution - 1) * kSubpixel));
    const __m256i special = _mm256_set1_epi32(kSpecialVertex);
    const __m256i low = _mm256_set1_epi32(-int32_t(kCompactLimit)), high = _mm256_set1_epi32(int32_t(kCompactLimit));
    const float* p = reinterpret_cast<const float*>(source.clip);
    __m256 m[16];  // kCentred: VertexSource's matrix, an entry a vector
    if constexpr (kCentred)
        for (int i = 0; i < 16; ++i) m[i] = _mm256_set1_ps(source.m[i]);
    size_t v = 0;
    for (; v + 8 <= count; v += 8) {
        __m256 x, y, z, w;
        if constexpr (kCentred) {  // VertexSource's transform, its operations in its order
            const __m256 px = _mm256_loadu_ps(source.x + v), py = _mm256_loadu_ps(source.y + v);
            const __m256 pz = _mm256_loadu_ps(source.z + v);
            x = transform_row_avx2(m, 0, px, py, pz), y = transform_row_avx2(m, 1, px, py, pz);
            z = transform_row_avx2(m, 2, px, py, pz), w = transform_row_avx2(m, 3, px, py, pz);
        } else {
            // Vertices 0-3 in the low halves, 4-7 in the high ones: the transpose leaves them in order.
            const float* q = p + 4 * v;
            const __m256 r0 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(q)), _mm_loadu_ps(q + 16), 1);
            const __m256 r1 =
                _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(q + 4)), _mm_loadu_ps(q + 20), 1);
            const __m256 r2 =
                _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(q + 8)), _mm_loadu_ps(q + 24), 1);
            const __m256 r3 =
                _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(q + 12)), _mm_loadu_ps(q + 28), 1);
            const __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpackhi_ps(r0, r1);
            const __m256 t2 = _mm256_unpacklo_ps(r2, r3), t3 = _mm256_unpackhi_ps(r2, r3);
            x = _mm256_shuffle_ps(t0, t2, 0x44), y = _mm256_shuffle_ps(t0, t2, 0xEE);
            z = _mm256_shuffle_ps(t1, t3, 0x44), w = _mm256_shuffle_ps(t1, t3, 0xEE);
        }
        // inside_all
        const __m256 w2 = _mm256_mul_ps(guard, w);
        const __m256 inside = _mm256_and_ps(
            _mm256_and_ps(
                _mm256_cmp_ps(z, _mm256_xor_ps(w, _mm256_castsi256_ps(_mm256_set1_epi32(INT32_MIN))), _CMP_GE_OQ),
                _mm256_cmp_ps(z, w, _CMP_LE_OQ)),
            _mm256_and_ps(_mm256_cmp_ps(_mm256_and_ps(x, abs_mask), w2, _CMP_LE_OQ),
                          _mm256_cmp_ps(_mm256_and_ps(y, abs_mask), w2, _CMP_LE_OQ)));
        // project
        const __m256 inv_w = _mm256_div_ps(_mm256_set1_ps(1.0f), w);
        const __m256 wx = _mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(x, inv_w), half), half);
        const __m256 wy = _mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(y, inv_w), half), half);
        const __m256 wz = _mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(z, inv_w), point5), point5);
        const __m256 cx = _mm256_sub_ps(wx, point5), cy = _mm256_sub_ps(wy, point5);
        const __m256 sx = _mm256_mul_ps(cx, subpixel), sy = _mm256_mul_ps(cy, subpixel);
        const __m256 tx =
            _mm256_blendv_ps(_mm256_sub_ps(sx, point5), _mm256_add_ps(sx, point5), _mm256_cmp_ps(sx, zero, _CMP_GE_OQ));
        const __m256 ty =
            _mm256_blendv_ps(_mm256_sub_ps(sy, point5), _mm256_add_ps(sy, point5), _mm256_cmp_ps(sy, zero, _CMP_GE_OQ));
        const __m256i X = _mm256_cvttps_epi32(tx);
        const __m256i Y = _mm256_sub_epi32(top_row, _mm256_cvttps_epi32(ty));
        const __m256i compact_x = _mm256_castps_si256(_mm256_cmp_ps(_mm256_and_ps(tx, abs_mask), limit, _CMP_LT_OQ));
        const __m256i compact_y =
            _mm256_and_si256(_mm256_castps_si256(_mm256_cmp_ps(_mm256_and_ps(ty, abs_mask), limit_y, _CMP_LT_OQ)),
                             _mm256_and_si256(_mm256_cmpgt_epi32(Y, low), _mm256_cmpgt_epi32(high, Y)));
        const __m256i compact = _mm256_and_si256(_mm256_and_si256(compact_x, compact_y), _mm256_castps_si256(inside));
        const __m256 fx = _mm256_and_ps(cx, inside);
        const __m256 fy = _mm256_and_ps(_mm256_sub_ps(_mm256_sub_ps(size, wy), point5), inside);
        const __m256 fz = _mm256_and_ps(wz, inside);
        const __m256 FX = _mm256_castsi256_ps(_mm256_blendv_epi8(special, X, compact));
        const __m256 FY = _mm256_castsi256_ps(_mm256_blendv_epi8(special, Y, compact));
        // flags: 0 compact, kWideVertex inside but not compact, kClippedVertex outside
        const __m256i in = _mm256_castps_si256(inside);  // compact implies inside
        const __m256i flag =
            _mm256_or_si256(_mm256_andnot_si256(in, _mm256_set1_epi32(kClippedVertex)),
                            _mm256_andnot_si256(compact, _mm256_and_si256(in, _mm256_set1_epi32(kWideVertex))));
        const __m128i flag16 = _mm_packus_epi32(_mm256_castsi256_si128(flag), _mm256_extracti128_si256(flag, 1));
        _mm_storel_epi64(reinterpret_cast<__m128i*>(flags + v), _mm_packus_epi16(flag16, flag16));
        // Snapped pairs: X and Y interleaved; records: the 8 × 4 transpose of (x, y, z, 0).
        const __m256 u0 = _mm256_unpacklo_ps(FX, FY), u1 = _mm256_unpackhi_ps(FX, FY);
        float* o = reinterpret_cast<float*>(snapped + v);
        _mm256_storeu_ps(o + 0, _mm256_permute2f128_ps(u0, u1, 0x20));
        _mm256_storeu_ps(o + 8, _mm256_permute2f128_ps(u0, u1, 0x31));
        const __m256 u2 = _mm256_unpacklo_ps(fx, fy), u3 = _mm256_unpackhi_ps(fx, fy);
        const __m256 u4 = _mm256_unpacklo_ps(fz, zero), u5 = _mm256_unpackhi_ps(fz, zero);
        const __m256 q0 = _mm256_shuffle_ps(u2, u4, 0x44), q1 = _mm256_shuffle_ps(u2, u4, 0xEE);
        const __m256 q2 = _mm256_shuffle_ps(u3, u5, 0x44), q3 = _mm256_shuffle_ps(u3, u5, 0xEE);
        float* r = reinterpret_cast<float*>(out + v);
        _mm256_storeu_ps(r + 0, _mm256_permute2f128_ps(q0, q1, 0x20));
        _mm256_storeu_ps(r + 8, _mm256_permute2f128_ps(q2, q3, 0x20));
        _mm256_storeu_ps(r + 16, _mm256_permute2f128_ps(q0, q1, 0x31));
        _mm256_storeu_ps(r + 24, _mm256_permute2f128_ps(q2, q3, 0x31));
    }
    return v;
}

// The drawn triangles' places in the batch (those with keep[i] = 1), 8 at a time: the lanes packed
// to the front with one permutation and stored (8 slots written). Returns how many of the n it
// did (a multiple of 8); the caller's scalar loop does the rest, m counting on.
template <NodeRasterizer::Copy>  // one instance a wide copy: each inlines its own
__attribute__((target("avx2,popcnt"))) size_t pack_drawn_avx2(size_t n, const int32_t* keep, uint32_t* draw,
                                                              size_t& m) {
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        const __m256i kept =
            _mm256_cmpgt_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(keep + i)), _mm256_setzero_si256());
        const int mask = _mm256_movemask_ps(_mm256_castsi256_ps(kept));
        const __m256i order = _mm256_load_si256(reinterpret_cast<const __m256i*>(kLanePacking.lanes[mask]));
        const __m256i places = _mm256_add_epi32(_mm256_set1_epi32(int32_t(i)), lane);
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(draw + m), _mm256_permutevar8x32_epi32(places, order));
        m += size_t(__builtin_popcount(unsigned(mask)));
    }
    return i;
}

// The batch's snapped corners (rasterize_node's gather), 8 triangles at a time: each corner's
// 8-byte (X, Y) record loaded whole, two to a 128-bit half, then split into the X and the Y row
// by one shuffle each: two vector stores per corner where the scalar loop stores 16 values one by
// one. The same values. Returns how many of the n it did (a multiple of 8); the scalar loop does
// the rest.
template <NodeRasterizer::Copy>  // one instance a wide copy: each inlines its own
__attribute__((target("avx2"))) size_t gather_corners_avx2(size_t n, const uint32_t* id, const uint32_t* indices,
                                                           const NodeRasterizer::State::Snapped* corner,
                                                           int32_t* const (&x)[3], int32_t* const (&y)[3]) {
    static_assert(sizeof(NodeRasterizer::State::Snapped) == 8, "an (X, Y) record is 8 bytes");
    const auto record = [corner](uint32_t v) { return reinterpret_cast<const double*>(corner + v); };
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        const uint32_t* tri[8];
        for (int t = 0; t < 8; ++t) tri[t] = indices + 3 * size_t(id[i + size_t(t)]);
        for (int k = 0; k < 3; ++k) {
            // Halves: triangles (0, 1 | 4, 5) and (2, 3 | 6, 7), each as X, Y, X, Y.
            __m128d pair[4];
            for (int h = 0; h < 4; ++h)
                pair[h] = _mm_loadh_pd(_mm_load_sd(record(tri[2 * h][k])), record(tri[2 * h + 1][k]));
            const __m256 a = _mm256_castpd_ps(_mm256_insertf128_pd(_mm256_castpd128_pd256(pair[0]), pair[2], 1));
            const __m256 b = _mm256_castpd_ps(_mm256_insertf128_pd(_mm256_castpd128_pd256(pair[1]), pair[3], 1));
            _mm256_storeu_ps(reinterpret_cast<float*>(x[k] + i), _mm256_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0)));
            _mm256_storeu_ps(reinterpret_cast<float*>(y[k] + i), _mm256_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1)));
        }
    }
    return i;
}

// The depth planes' inputs of rasterize_node for the drawn triangles, 4 at a time: each corner's
// 16-byte record loaded whole, the differences taken in float lanes, the 4 triangles' (x, y, z)
// turned into one vector per coordinate and widened to double: the same float subtractions and
// exact widenings as the scalar loop, so the same bits (a triangle of an exact path gets zeros
// there, as there). Returns how many of the m it did (a multiple of 4); the scalar loop does the rest.
template <NodeRasterizer::Copy>  // one instance a wide copy: each inlines its own
__attribute__((target("avx2"))) size_t plane_inputs_avx2(size_t m, const uint32_t* draw, const int32_t* special,
                                                         const int64_t* areas, const uint32_t* id,
                                                         const uint32_t* indices,
                                                         const NodeRasterizer::State::VertexRecord* vertex,
                                                         BatchSetup& setup) {
    size_t j = 0;
    for (; j + 4 <= m; j += 4) {
        __m128 a[4], b[4], o[4];
        for (int t = 0; t < 4; ++t) {
            const size_t i = draw[j + size_t(t)];
            const bool front = areas[i] < 0;
            const uint32_t* tri = indices + 3 * size_t(id[i]);
            const __m128 w0 = _mm_load_ps(&vertex[tri[0]].x);
            const __m128 w1 = _mm_load_ps(&vertex[tri[front ? 2 : 1]].x);
            const __m128 w2 = _mm_load_ps(&vertex[tri[front ? 1 : 2]].x);
            const __m128 fast = _mm_castsi128_ps(_mm_set1_epi32(special[i] == 1 ? -1 : 0));
            a[t] = _mm_and_ps(_mm_sub_ps(w1, w0), fast);
            b[t] = _mm_and_ps(_mm_sub_ps(w2, w0), fast);
            o[t] = _mm_and_ps(w0, fast);
        }
        _MM_TRANSPOSE4_PS(a[0], a[1], a[2], a[3]);
        _MM_TRANSPOSE4_PS(b[0], b[1], b[2], b[3]);
        _MM_TRANSPOSE4_PS(o[0], o[1], o[2], o[3]);
        _mm256_storeu_pd(setup.ax + j, _mm256_cvtps_pd(a[0]));
        _mm256_storeu_pd(setup.ay + j, _mm256_cvtps_pd(a[1]));
        _mm256_storeu_pd(setup.az + j, _mm256_cvtps_pd(a[2]));
        _mm256_storeu_pd(setup.bx + j, _mm256_cvtps_pd(b[0]));
        _mm256_storeu_pd(setup.by + j, _mm256_cvtps_pd(b[1]));
        _mm256_storeu_pd(setup.bz + j, _mm256_cvtps_pd(b[2]));
        _mm256_storeu_pd(setup.x + j, _mm256_cvtps_pd(o[0]));
        _mm256_storeu_pd(setup.y + j, _mm256_cvtps_pd(o[1]));
        _mm256_storeu_pd(setup.z + j, _mm256_cvtps_pd(o[2]));
    }
    return j;
}
#endif

// One node after the checks: project the vertices, pre-pass and set up the triangles in
// batches, draw them, group the fragments (group_fragments inlined too, so each copy compiles it
// for its own instructions). Inlined into the three copies below; kAvx2: the AVX2 and AVX-512
// copies, whose boxes take the emit_*_avx2 paths.
template <NodeRasterizer::Copy kCopy>
ANIMORDER_ALWAYS_INLINE void rasterize_node(NodeRasterizer::State& s, const VertexSource& cv, size_t vertex_count,
                                            const uint32_t* indices, size_t index_count, unsigned resolution,
                                            const uint8_t* modes, const uint32_t* candidates, size_t candidate_count) {
    constexpr bool kAvx2 = kCopy != NodeRasterizer::Copy::Portable;
    s.snapped.resize(vertex_count);
    s.vertices.resize(vertex_count);
    s.vertex_flags.resize(vertex_count);
    size_t first_vertex = 0;
#ifdef ANIMORDER_RASTER_AVX2
    if constexpr (kAvx2)
        first_vertex = cv.clip ? project_vertices_avx2<kCopy, false>(cv, vertex_count, resolution, s.snapped.data(),
                                                                     s.vertices.data(), s.vertex_flags.data())
                               : project_vertices_avx2<kCopy, true>(cv, vertex_count, resolution, s.snapped.data(),
                                                                    s.vertices.data(), s.vertex_flags.data());
#endif
    for (size_t v = first_vertex; v < vertex_count; ++v) {
        const ClipVertex c = cv[v];
        if (!inside_all(c)) {
            s.vertex_flags[v] = kClippedVertex;
            s.snapped[v] = {kSpecialVertex, kSpecialVertex};
            s.vertices[v] = {0.0f, 0.0f, 0.0f, 0.0f};
            continue;
        }
        WindowVertex w;
        project(c, resolution, w);
        const bool compact = w.X > -kCompactLimit && w.X < kCompactLimit && w.Y > -kCompactLimit && w.Y < kCompactLimit;
        s.vertex_flags[v] = compact ? 0 : kWideVertex;
        s.snapped[v] = {compact ? int32_t(w.X) : kSpecialVertex, compact ? int32_t(w.Y) : kSpecialVertex};
        s.vertices[v] = {w.x, w.y, w.z, 0.0f};
    }

    // The candidates stand for every triangle only when every corner took the fast path (the
    // facing filter's guarantee is about those); otherwise every triangle is drawn.
    bool listed = candidates != nullptr;
    if (listed) {
        uint8_t any = 0;
        for (size_t v = 0; v < vertex_count; ++v) any |= s.vertex_flags[v];  // vectorised
        listed = any == 0;
    }

    // Triangles in batches: gather the snapped corners, test area and box for the whole batch at
    // once, then draw the survivors in triangle order (the order of the fragments is unchanged).
    FragmentSink sink{s.raw_pixel, s.raw_triangle, s.raw_depth};
    const size_t triangle_count = listed ? candidate_count : index_count / 3;
    const NodeRasterizer::State::Snapped* corner = s.snapped.data();
    const NodeRasterizer::State::VertexRecord* vertex = s.vertices.data();
    const uint8_t* flags = s.vertex_flags.data();
    alignas(16) int32_t x0[kBatch], y0[kBatch], x1[kBatch], y1[kBatch], x2[kBatch], y2[kBatch], keep[kBatch];
    int32_t two[kBatch], cover[kBatch], edged[kBatch];
    uint32_t general[kBatch + 8];  // the drawn triangles that need the edge functions' set-up
    int32_t boxes[kBatch][4];
    int64_t areas[kBatch];
    int32_t special[kBatch];
    uint32_t draw[kBatch + 8], every[kBatch];  // draw: 8 slots past the batch for the wide copies' stores
    uint8_t listed_modes[kBatch];
    static constexpr uint8_t kNoModes[kBatch] = {};  // every triangle drawn, back faces culled
    BatchSetup& setup = s.setup;
    for (size_t first = 0; first < triangle_count; first += kBatch) {
        const size_t n = std::min(kBatch, triangle_count - first);
        // The batch's triangles (id) and their modes (mode): the index list's own, or the
        // candidates'. Triangle id's corners are indices[3 · id ...].
        const uint8_t* mode = modes ? modes + first : kNoModes;
        const uint32_t* id = every;
        if (listed) {
            id = candidates + first;
            if (modes) {
                for (size_t i = 0; i < n; ++i) listed_modes[i] = modes[id[i]];
                mode = listed_modes;
            }
        } else {
            for (size_t i = 0; i < n; ++i) every[i] = uint32_t(first + i);
        }
        size_t gathered = 0;
#ifdef ANIMORDER_RASTER_AVX2
        if constexpr (kAvx2) gathered = gather_corners_avx2<kCopy>(n, id, indices, corner, {x0, x1, x2}, {y0, y1, y2});
#endif
        for (size_t i = gathered; i < n; ++i) {
            const uint32_t* tri = indices + 3 * size_t(id[i]);
            const uint32_t a = tri[0], b = tri[1], c = tri[2];
            x0[i] = corner[a].X;
            y0[i] = corner[a].Y;
            x1[i] = corner[b].X;
            y1[i] = corner[b].Y;
            x2[i] = corner[c].X;
            y2[i] = corner[c].Y;
        }
        for (size_t i = 0; i < n; ++i) {  // vectorised
            const int32_t m = mode[i];
            two[i] = m & kDrawBothFaces;
            // Skipped: never drawn (0); a clipped or wide corner: an exact path below (2).
            const int32_t exact =
                int32_t(x0[i] == kSpecialVertex) | int32_t(x1[i] == kSpecialVertex) | int32_t(x2[i] == kSpecialVertex);
            special[i] = (m & kSkipTriangle) ? 0 : 1 + exact;
        }
        batch_box_test(n, x0, y0, x1, y1, x2, y2, int32_t(resolution - 1), keep, boxes, cover);
        for (size_t i = 0; i < n; ++i) {  // int32 and int64 lanes only: vectorised
            // As triangle_box: y points down, so OpenGL's counter-clockwise front faces have
            // negative area; |coordinates| < 2^24 keeps the int64 products exact.
            const int64_t area = int64_t(x1[i] - x0[i]) * (y2[i] - y0[i]) - int64_t(x2[i] - x0[i]) * (y1[i] - y0[i]);
            const int32_t drawn = int32_t(area < 0) | (int32_t(area > 0) & two[i]);
            areas[i] = area;
            keep[i] = int32_t(special[i] > 1) | (int32_t(special[i] == 1) & drawn & keep[i]);
            edged[i] = keep[i] & (int32_t(special[i] != 1) | int32_t(cover[i] == 0));
        }
        size_t m = 0, packed = 0, edges = 0, edges_packed = 0;
#ifdef ANIMORDER_RASTER_AVX2
        if constexpr (kAvx2) {
            packed = pack_drawn_avx2<kCopy>(n, keep, draw, m);
            edges_packed = pack_drawn_avx2<kCopy>(n, edged, general, edges);
        }
#endif
        for (size_t i = packed; i < n; ++i) {
            draw[m] = uint32_t(i);
            m += size_t(keep[i]);
        }
        for (size_t i = edges_packed; i < n; ++i) {
            general[edges] = uint32_t(i);
            edges += size_t(edged[i]);
        }
        // The set-up of rasterize_window_triangle for every drawn triangle of the batch at once:
        // the depth plane of each (entry j), the edge functions of those that the small-box test
        // did not decide (entry g, in the same order). Corners in positive order: 0, 2, 1 for a
        // front face (negative area), else 0, 1, 2.
        for (size_t g = 0; g < edges; ++g) {
            const size_t i = general[g];
            const bool front = areas[i] < 0;
            setup.X[0][g] = x0[i];
            setup.Y[0][g] = y0[i];
            setup.X[1][g] = front ? x2[i] : x1[i];
            setup.Y[1][g] = front ? y2[i] : y1[i];
            setup.X[2][g] = front ? x1[i] : x2[i];
            setup.Y[2][g] = front ? y1[i] : y2[i];
            setup.px0[g] = boxes[i][0];
            setup.py0[g] = boxes[i][2];
        }
        size_t planes_done = 0;
#ifdef ANIMORDER_RASTER_AVX2
        if constexpr (kAvx2)
            planes_done = plane_inputs_avx2<kCopy>(m, draw, special, areas, id, indices, vertex, setup);
#endif
        for (size_t j = planes_done; j < m; ++j) {
            const size_t i = draw[j];
            const bool fast = special[i] == 1, front = areas[i] < 0;
            const uint32_t* tri = indices + 3 * size_t(id[i]);
            const auto* w0 = vertex + tri[0];
            const auto* w1 = vertex + tri[front ? 2 : 1];
            const auto* w2 = vertex + tri[front ? 1 : 2];
            // As rasterize_window_triangle: differences in float, then widened.
            setup.ax[j] = fast ? w1->x - w0->x : 0.0f;
            setup.ay[j] = fast ? w1->y - w0->y : 0.0f;
            setup.az[j] = fast ? w1->z - w0->z : 0.0f;
            setup.bx[j] = fast ? w2->x - w0->x : 0.0f;
            setup.by[j] = fast ? w2->y - w0->y : 0.0f;
            setup.bz[j] = fast ? w2->z - w0->z : 0.0f;
            setup.x[j] = fast ? w0->x : 0.0f;
            setup.y[j] = fast ? w0->y : 0.0f;
            setup.z[j] = fast ? w0->z : 0.0f;
        }
        setup.compute(edges, m);
        size_t g = 0;
        for (size_t j = 0; j < m; ++j) {
            const size_t t = id[draw[j]];
            const uint32_t* tri = indices + 3 * t;
            const uint32_t a = tri[0], b = tri[1], c = tri[2];
            const bool two_sided = two[draw[j]] != 0;
            if (!edged[draw[j]]) {                  // the small-box test found its covered centres
                if (setup.det[j] == 0.0) continue;  // float-degenerate sliver: no defined depth
                const int32_t* known = boxes[draw[j]];
#ifdef ANIMORDER_RASTER_AVX2
                if (kAvx2) {
                    emit_covered_box_avx2(cover[draw[j]], setup.dzdx[j], setup.dzdy[j], setup.z_origin[j], known[0],
                                          known[2], uint32_t(t), resolution, sink);
                    continue;
                }
#endif
                emit_covered_box(cover[draw[j]], setup.dzdx[j], setup.dzdy[j], setup.z_origin[j], known[0], known[2],
                                 uint32_t(t), resolution, sink);
                continue;
            }
            const size_t k = g++;                   // its edge functions' entry
            if (special[draw[j]] == 1) {            // passed the pre-pass: its box and set-up are known
                if (setup.det[j] == 0.0) continue;  // float-degenerate sliver: no fragment has a defined depth
                const int32_t* known = boxes[draw[j]];
                const TriangleBox box{areas[draw[j]], known[0], known[1], known[2], known[3]};
#ifdef ANIMORDER_RASTER_AVX2
                if (kAvx2) {  // the set-up's doubles as they are: no conversion to int64
                    const double e[3] = {setup.e[0][k], setup.e[1][k], setup.e[2][k]};
                    const double sx[3] = {setup.sx[0][k], setup.sx[1][k], setup.sx[2][k]};
                    const double sy[3] = {setup.sy[0][k], setup.sy[1][k], setup.sy[2][k]};
                    if (box.px1 - box.px0 < 2 && box.py1 - box.py0 < 2)
                        emit_small_box_avx2(e, sx, sy, setup.dzdx[j], setup.dzdy[j], setup.z_origin[j], box,
                                            uint32_t(t), resolution, sink);
                    else
                        emit_box_avx2<kCopy>(e, sx, sy, setup.dzdx[j], setup.dzdy[j], setup.z_origin[j], box,
                                             uint32_t(t), resolution, sink);
                    continue;
                }
#endif
                const int64_t e[3] = {int64_t(setup.e[0][k]), int64_t(setup.e[1][k]), int64_t(setup.e[2][k])};
                const int64_t sx[3] = {int64_t(setup.sx[0][k]), int64_t(setup.sx[1][k]), int64_t(setup.sx[2][k])};
                const int64_t sy[3] = {int64_t(setup.sy[0][k]), int64_t(setup.sy[1][k]), int64_t(setup.sy[2][k])};
                if (box.px1 - box.px0 < 2 && box.py1 - box.py0 < 2)
                    emit_small_box(e, sx, sy, setup.dzdx[j], setup.dzdy[j], setup.z_origin[j], box, uint32_t(t),
                                   resolution, sink);
                else
                    emit_box(e, sx, sy, setup.dzdx[j], setup.dzdy[j], setup.z_origin[j], box, uint32_t(t), resolution,
                             sink);
            } else if (!((flags[a] | flags[b] | flags[c]) & kClippedVertex)) {
                WindowVertex va, vb, vc;  // projected again: the same bits as the vertex pass
                project(cv[a], resolution, va);
                project(cv[b], resolution, vb);
                project(cv[c], resolution, vc);
                TriangleBox box;
                if (triangle_box(va, vb, vc, resolution, two_sided, box))
                    rasterize_window_triangle(va, vb, vc, box, uint32_t(t), resolution, sink);
            } else {
                const ClipVertex v[3] = {cv[a], cv[b], cv[c]};
                rasterize_clipped_triangle(v, uint32_t(t), resolution, sink, two_sided);
            }
        }
    }
    s.raw_count = sink.count;  // the arrays keep their size: no re-zeroing on the next node

    group_fragments(s);
}

}  // namespace
}  // namespace raster
}  // namespace animorder
