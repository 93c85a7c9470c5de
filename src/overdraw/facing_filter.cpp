// Back faces left out before rasterising: a conservative, exact form of the rasteriser's culling.
//
// Not from the papers; it serves Han & Sander, "Triangle Reordering for Efficient Rendering in
// Complex Scenes" (JCGT 2017), whose every node is one rasterisation of the whole mesh, and whose
// meshes are mostly single-sided, so about half the triangles of a node are back faces. The
// rasteriser (rasterizer.cpp) finds them only after gathering and snapping their corners; this
// finds most of them from the keyframe's geometry, one dot product per triangle and node.
//
// Why it is exact. In the framed space (positions minus the keyframe's centre, in float as
// transform_to_clip computes them), the camera sits at e = 3R·d looking at the origin with
// cot(fovy/2) = 2√2 (camera.cpp). For a triangle a, b, c with n = (b − a) × (c − a) and
// s = n · (e − a), the doubled signed area of its exact projection in OpenGL window space (y up,
// pixels) is
//     2A = (res/2)² · cot² · s / (w_a · w_b · w_c),
// w the distance along the view axis (the clip w): s > 0 is a front face. When every corner of
// the keyframe lies within ρ ≤ R of the origin (inside the sphere the field of view fits), so
// does every point of a triangle whose corners lie within ρ_t, and w lies in [3R − ρ_t, 3R + ρ_t].
// The rasteriser's corners are these projections moved by at most δ per coordinate: half a
// subpixel of snapping plus float rounding in the vertex transform, the projection and the
// snapping (below 1e-6 · res pixels when ρ ≤ R; δ allows four times that). Moving corner i by
// ε_i changes the doubled area by a term linear in the ε_i, each times the length of the edge
// opposite corner i, plus the cross product of two corner differences: at most √2·δ·P + 8δ², P
// the projected perimeter. The projection's gradient on the triangle bounds P: P ≤ p · (res/2) ·
// cot · √(1 + g²) / (3R − ρ_t), p the perimeter in the framed space, ρ_t the triangle's largest
// corner distance, g = ρ_t / √(9R² − ρ_t²) the largest view-space radial distance over w on the
// ball of radius ρ_t. (R itself lies a hair above the farthest corner, frame_keyframes; a
// keyframe with a corner beyond 1.001 R gets no filtering.)
// So if
//     −s · (res/2)² · cot² / (3R + ρ_t)³ > √2·δ·P + 8δ²,
// the rasteriser's area has the back-face sign (or is zero) and a single-sided triangle is
// culled: such a triangle is left out. The threshold per triangle adds the float rounding of the
// per-node dot product (below 1e-6 · (|n|·|e| + |n·a|)) and a 1% margin.
#include "animorder/facing_filter.h"

#include "animorder/camera.h"
#include "animorder/rasterizer.h"

#include "always_inline.h"
#include "lane_packing.h"

#include <algorithm>
#include <cmath>

#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
#include <immintrin.h>
#endif

namespace animorder {
namespace {

struct BoundConstants {
    double unit, eye, half, delta;
};

// build's scratch: a block of triangles' corners in columns and what bounds works out from them.
struct BoundBlock {
    static constexpr size_t kSize = 256;
    float x[3][kSize], y[3][kSize], z[3][kSize];  // corner k of each triangle, framed
    double r[3][kSize];                           // its distance from the centre
    float nx[kSize], ny[kSize], nz[kSize];        // out: the normal
    double bound[kSize];                          // out: offset − threshold
};

// The test for one triangle, in this order of float operations in every copy (no fused
// multiply-add: the build turns contraction off), so every copy gives the same candidates.
inline bool may_draw(float nx, float ny, float nz, float limit, float ex, float ey, float ez) {
    return !(((nx * ex + ny * ey) + nz * ez) < limit);
}

size_t candidates_portable(const float* nx, const float* ny, const float* nz, const float* limit, size_t triangles,
                           float ex, float ey, float ez, uint32_t* out) {
    size_t m = 0;
    for (size_t t = 0; t < triangles; ++t) {
        out[m] = uint32_t(t);
        m += may_draw(nx[t], ny[t], nz[t], limit[t], ex, ey, ez);
    }
    return m;
}

#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
#define ANIMORDER_FACING_AVX2 1
// Eight triangles a step: the test in float lanes (may_draw's operations), then the ids of the
// lanes that pass packed to the front with one permutation and stored (8 slots written, the
// count advanced by those that pass).
__attribute__((target("avx2,popcnt"))) size_t candidates_avx2(const float* nx, const float* ny, const float* nz,
                                                              const float* limit, size_t triangles, float ex, float ey,
                                                              float ez, uint32_t* out) {
    const __m256 x = _mm256_set1_ps(ex), y = _mm256_set1_ps(ey), z = _mm256_set1_ps(ez);
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    size_t m = 0, t = 0;
    for (; t + 8 <= triangles; t += 8) {
        const __m256 dot = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(nx + t), x), _mm256_mul_ps(_mm256_loadu_ps(ny + t), y)),
            _mm256_mul_ps(_mm256_loadu_ps(nz + t), z));
        const int mask = _mm256_movemask_ps(_mm256_cmp_ps(dot, _mm256_loadu_ps(limit + t), _CMP_NLT_UQ));
        const __m256i ids = _mm256_add_epi32(_mm256_set1_epi32(int32_t(t)), lane);
        const __m256i order = _mm256_load_si256(reinterpret_cast<const __m256i*>(kLanePacking.lanes[mask]));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + m), _mm256_permutevar8x32_epi32(ids, order));
        m += size_t(__builtin_popcount(unsigned(mask)));
    }
    for (; t < triangles; ++t) {
        out[m] = uint32_t(t);
        m += may_draw(nx[t], ny[t], nz[t], limit[t], ex, ey, ez);
    }
    return m;
}
#endif

// The bound of one triangle (the file's opening comment): from its framed corners (x, y, z[k] in
// float, as transform_to_clip has them) and their distances from the centre (r[k]), in units of
// R: the normal n and offset − threshold. Columns of a block, one function per copy below so
// that each compiles the loop for its own lanes.
ANIMORDER_ALWAYS_INLINE void bounds(BoundBlock& b, size_t count, const BoundConstants& k) {
    const double unit = k.unit, eye = k.eye, half = k.half, delta = k.delta;
    for (size_t i = 0; i < count; ++i) {
        const double a[3] = {unit * b.x[0][i], unit * b.y[0][i], unit * b.z[0][i]};
        const double u[3] = {unit * (double(b.x[1][i]) - b.x[0][i]), unit * (double(b.y[1][i]) - b.y[0][i]),
                             unit * (double(b.z[1][i]) - b.z[0][i])};
        const double w[3] = {unit * (double(b.x[2][i]) - b.x[0][i]), unit * (double(b.y[2][i]) - b.y[0][i]),
                             unit * (double(b.z[2][i]) - b.z[0][i])};
        const double v[3] = {unit * (double(b.x[2][i]) - b.x[1][i]), unit * (double(b.y[2][i]) - b.y[1][i]),
                             unit * (double(b.z[2][i]) - b.z[1][i])};
        const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
        const double offset = n[0] * a[0] + n[1] * a[1] + n[2] * a[2];
        const double perimeter = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]) +
                                 std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) +
                                 std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        // This triangle's bounds (every point of it lies within ρ_t of the origin): w in
        // [3R − ρ_t, 3R + ρ_t], and the view-space radial distance over w at most
        // g = ρ_t / √(9R² − ρ_t²) (the cone around the ball), so the projection's gradient is at
        // most (res/2)·cot·√(1 + g²) / w. The distances are finite (build checked): max's order
        // of comparison does not matter.
        const double r01 = b.r[0][i] < b.r[1][i] ? b.r[1][i] : b.r[0][i];
        const double rho_t = unit * (r01 < b.r[2][i] ? b.r[2][i] : r01);
        const double w_min = eye - rho_t, w_max = eye + rho_t;
        const double slope = 1.0001 * rho_t / std::sqrt(eye * eye - rho_t * rho_t);
        const double P = perimeter * half * kCotHalfFov * std::sqrt(1.0 + slope * slope) / w_min;
        const double area_scale = half * half * kCotHalfFov * kCotHalfFov / (w_max * w_max * w_max);
        const double rounding = 1e-6 * (std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) * eye + std::fabs(offset));
        const double threshold = 1.01 * (std::sqrt(2.0) * delta * P + 8.0 * delta * delta) / area_scale + rounding;
        b.nx[i] = float(n[0]);
        b.ny[i] = float(n[1]);
        b.nz[i] = float(n[2]);
        b.bound[i] = offset - threshold;
    }
}

void bounds_portable(BoundBlock& b, size_t count, const BoundConstants& k) { bounds(b, count, k); }

#ifdef ANIMORDER_FACING_AVX2
__attribute__((target("avx2"))) void bounds_avx2(BoundBlock& b, size_t count, const BoundConstants& k) {
    bounds(b, count, k);
}
#endif

}  // namespace

void FacingFilter::build(const float* positions, size_t vertex_count, const uint32_t* indices, size_t index_count,
                         const float centre[3], float radius, unsigned resolution, const uint8_t* modes) {
    const size_t triangles = index_count / 3;
    usable_ = built_ = false;
    nx_.resize(triangles);
    ny_.resize(triangles);
    nz_.resize(triangles);
    limit_.resize(triangles);
    out_.resize(triangles + 8);  // candidates_avx2 writes 8 slots a step
    // R within 2^±100 (frame_keyframes refuses others): clip coordinates then stay far from float
    // overflow (w ≤ 4.01 R) and underflow, which the error budget δ below assumes.
    const double R = radius;
    if (!(R >= 0x1p-100 && R <= 0x1p100) || resolution == 0) return;
    // The corners as transform_to_clip has them (float differences), their distances from the
    // centre, and ρ over the corners drawn.
    corners_.resize(3 * vertex_count);
    float* q = corners_.data();
    for (size_t v = 0; v < vertex_count; ++v)
        for (int k = 0; k < 3; ++k) q[3 * v + k] = positions[3 * v + k] - centre[k];
    radii_.resize(vertex_count);
    for (size_t v = 0; v < vertex_count; ++v) {
        const float* p = q + 3 * v;
        radii_[v] = std::sqrt(double(p[0]) * p[0] + double(p[1]) * p[1] + double(p[2]) * p[2]);
    }
    const double* radius_of = radii_.data();
    double rho = 0;
    for (size_t i = 0; i < 3 * triangles; ++i) {
        const double r = radius_of[indices[i]];
        if (!std::isfinite(r)) return;
        rho = std::max(rho, r);
    }
    if (rho > 1.001 * R) return;  // the framing's radius is a hair above its farthest corner; not ours: no guarantee
    const double half = 0.5 * double(resolution);
    const double delta = 1.0 / 512.0 + 4e-6 * double(resolution);
    // In units of R from here on (the test and its threshold scale alike): the eye at distance 3,
    // and every value between about 1e-38 and 5, which floats hold; the threshold's 8δ² part
    // outweighs any rounding of a value that small.
    const double unit = 1.0 / R, eye = 3.0;
    // In blocks of triangles: their corners and corner distances gathered into columns, then the
    // bounds worked out over the columns in lanes (`bounds`, above: its square roots and
    // divisions are most of build's time; the same operations per lane, so the same bits), then
    // the limits.
    const BoundConstants constants{unit, eye, half, delta};
    bool can_leave_out = false;
    BoundBlock b;  // 20 KB on the stack
    for (size_t first = 0; first < triangles; first += BoundBlock::kSize) {
        const size_t count = std::min(BoundBlock::kSize, triangles - first);
        for (size_t i = 0; i < count; ++i) {
            const uint32_t* corner = indices + 3 * (first + i);
            for (int k = 0; k < 3; ++k) {
                const float* c = q + 3 * size_t(corner[k]);
                b.x[k][i] = c[0];
                b.y[k][i] = c[1];
                b.z[k][i] = c[2];
                b.r[k][i] = radius_of[corner[k]];
            }
        }
#ifdef ANIMORDER_FACING_AVX2
        static const bool avx2 = __builtin_cpu_supports("avx2");
        if (avx2 && !portable_)
            bounds_avx2(b, count, constants);
        else
#endif
            bounds_portable(b, count, constants);
        for (size_t i = 0; i < count; ++i) {
            const size_t t = first + i;
            nx_[t] = b.nx[i];
            ny_[t] = b.ny[i];
            nz_[t] = b.nz[i];
            // Left out when n · e < offset − threshold: the limit rounded down (the float nearest may
            // lie above). A double-sided triangle is never left out.
            const bool never = modes && (modes[t] & kDrawBothFaces);
            limit_[t] = never ? -INFINITY : std::nextafter(float(b.bound[i]), -INFINITY);
            can_leave_out |= !never;
        }
    }
    usable_ = can_leave_out;  // a mesh all double-sided: nothing to gain, the rasteriser's plain path
}

FacingFilter::Candidates FacingFilter::candidates(const float view_direction[3]) {
    const size_t triangles = limit_.size();
    uint32_t* out = out_.data();
    if (!usable_) return {nullptr, triangles};
    // The eye as node_view_projection places it, in units of R.
    const double d[3] = {view_direction[0], view_direction[1], view_direction[2]};
    const double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    const float ex = float(3.0 * (d[0] / norm)), ey = float(3.0 * (d[1] / norm)), ez = float(3.0 * (d[2] / norm));
#ifdef ANIMORDER_FACING_AVX2
    static const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("popcnt");
    if (avx2 && !portable_)
        return {out, candidates_avx2(nx_.data(), ny_.data(), nz_.data(), limit_.data(), triangles, ex, ey, ez, out)};
#endif
    return {out, candidates_portable(nx_.data(), ny_.data(), nz_.data(), limit_.data(), triangles, ex, ey, ez, out)};
}

}  // namespace animorder
