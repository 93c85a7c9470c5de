// The camera of every node (DESIGN.md "Camera"), following Han & Sander 2017 §4: a perspective
// camera at distance 3R looking at the framed character, with a field of view that just contains
// the bounding sphere of radius R, so every keyframe fills the same square viewport.
//
// The matrices are the classic OpenGL lookAt and perspective (gluLookAt/gluPerspective), built
// in double. Vertices are transformed in float, like a vertex shader, and the same clip-space
// array feeds both our rasteriser and the OpenGL reference, so the two see identical input.
#include "animorder/camera.h"

#include <algorithm>

#include "animorder/invalid_input.h"

#include "../support/mat4.h"

#include <cmath>

namespace animorder {
namespace {

struct V3 {
    double x, y, z;
};
V3 sub(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 cross3(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double dot3(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 unit(V3 a) {
    const double n = std::sqrt(dot3(a, a));
    return {a.x / n, a.y / n, a.z / n};
}

}  // namespace

Mat4d node_view_projection(const float view_direction[3], float radius) {
    if (!(radius > 0) || !std::isfinite(radius)) throw InvalidInput("view radius must be positive and finite");
    const V3 d = unit({view_direction[0], view_direction[1], view_direction[2]});
    const V3 eye = {3.0 * radius * d.x, 3.0 * radius * d.y, 3.0 * radius * d.z};
    const V3 up = std::fabs(d.y) > 0.999 ? V3{0, 0, 1} : V3{0, 1, 0};

    // lookAt: forward f towards the origin, side s = f × up, true up u = s × f.
    const V3 f = unit(sub({0, 0, 0}, eye));
    const V3 s = unit(cross3(f, up));
    const V3 u = cross3(s, f);
    const Mat4d view = {s.x, u.x, -f.x, 0, s.y,           u.y,           -f.y,         0,
                        s.z, u.z, -f.z, 0, -dot3(s, eye), -dot3(u, eye), dot3(f, eye), 1};

    // perspective: tan(fovy/2) = tan(asin(1/3)) = 1/(2√2); near R, far 5R (the sphere spans 2R..4R).

    const double n = radius, fr = 5.0 * radius;
    const Mat4d projection = {
        kCotHalfFov, 0, 0, 0, 0, kCotHalfFov, 0, 0, 0, 0, (fr + n) / (n - fr), -1, 0, 0, 2.0 * fr * n / (n - fr), 0};
    return multiply_mat4(projection, view);
}

namespace {

// One block of up to kBlock vertices (n of them): positions moved to the frame's centre, then the
// four rows of m · (x, y, z, 1) for every lane at once, stored interleaved. Each output is
// ((m[row]·x + m[4+row]·y) + m[8+row]·z) + m[12+row] in float, the operations a vertex shader
// would do, in this order and without fused multiply-adds (the AVX2 copy has no FMA to contract
// into), so every copy gives the same bits. Lanes past n repeat vertex 0 and are not stored.
constexpr size_t kBlock = 8;

inline __attribute__((always_inline)) void transform_block(float* out, const float* positions, size_t n,
                                                           const float* centre, const float* m) {
    float x[kBlock], y[kBlock], z[kBlock];
    for (size_t i = 0; i < kBlock; ++i) {
        const size_t v = i < n ? i : 0;
        x[i] = positions[3 * v] - centre[0];
        y[i] = positions[3 * v + 1] - centre[1];
        z[i] = positions[3 * v + 2] - centre[2];
    }
    float clip[4][kBlock];
    for (int row = 0; row < 4; ++row)
        for (size_t i = 0; i < kBlock; ++i)
            clip[row][i] = clip_row(m, row, x[i], y[i], z[i]);
    for (size_t i = 0; i < n; ++i)
        for (int row = 0; row < 4; ++row) out[4 * i + row] = clip[row][i];
}

inline __attribute__((always_inline)) void transform_all(float* clip_xyzw, const float* positions, size_t vertex_count,
                                                         const float centre[3], const Mat4d& vp) {
    const std::array<float, 16> matrix = float_matrix(vp);
    const float* m = matrix.data();
    size_t v = 0;
    for (; v + kBlock <= vertex_count; v += kBlock)
        transform_block(clip_xyzw + 4 * v, positions + 3 * v, kBlock, centre, m);
    if (v < vertex_count) transform_block(clip_xyzw + 4 * v, positions + 3 * v, vertex_count - v, centre, m);
}

#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
#define ANIMORDER_CAMERA_AVX2 1
__attribute__((target("avx2"))) void transform_all_avx2(float* clip_xyzw, const float* positions, size_t vertex_count,
                                                        const float centre[3], const Mat4d& vp) {
    transform_all(clip_xyzw, positions, vertex_count, centre, vp);
}
#endif

}  // namespace

std::array<float, 16> float_matrix(const Mat4d& m) {
    std::array<float, 16> out;
    for (int i = 0; i < 16; ++i) out[size_t(i)] = float(m[size_t(i)]);
    return out;
}

void centre_positions(float* x, float* y, float* z, const float* positions, size_t vertex_count,
                      const float centre[3]) {
    for (size_t v = 0; v < vertex_count; ++v) {
        x[v] = positions[3 * v] - centre[0];
        y[v] = positions[3 * v + 1] - centre[1];
        z[v] = positions[3 * v + 2] - centre[2];
    }
}

void CentredKeyframe::centre(const float* positions, size_t vertex_count, const float centre[3]) {
    if (positions == positions_ && 3 * vertex_count == xyz_.size() && std::equal(centre, centre + 3, centre_)) return;
    xyz_.resize(3 * vertex_count);
    centre_positions(xyz_.data(), xyz_.data() + vertex_count, xyz_.data() + 2 * vertex_count, positions, vertex_count,
                     centre);
    positions_ = positions;
    std::copy(centre, centre + 3, centre_);
}

NodeRasterizer::CentredVertices CentredKeyframe::vertices(const Mat4d& view_projection) const {
    const size_t vertex_count = xyz_.size() / 3;
    NodeRasterizer::CentredVertices v;
    v.x = xyz_.data();
    v.y = xyz_.data() + vertex_count;
    v.z = xyz_.data() + 2 * vertex_count;
    const std::array<float, 16> m = float_matrix(view_projection);
    std::copy(m.begin(), m.end(), v.view_projection);
    return v;
}

void transform_to_clip_portable(float* clip_xyzw, const float* positions, size_t vertex_count, const float centre[3],
                                const Mat4d& vp) {
    transform_all(clip_xyzw, positions, vertex_count, centre, vp);
}

void transform_to_clip(float* clip_xyzw, const float* positions, size_t vertex_count, const float centre[3],
                       const Mat4d& vp) {
#ifdef ANIMORDER_CAMERA_AVX2
    static const bool avx2 = __builtin_cpu_supports("avx2");
    if (avx2) return transform_all_avx2(clip_xyzw, positions, vertex_count, centre, vp);
#endif
    transform_all(clip_xyzw, positions, vertex_count, centre, vp);
}

}  // namespace animorder
