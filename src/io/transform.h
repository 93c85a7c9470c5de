// Column-major 4×4 transforms in double for the loaders (node hierarchies, bind poses). Internal
// to src/io.
#pragma once

#include "../support/mat4.h"

#include <array>
#include <cmath>

namespace animorder::io {

using Mat = std::array<double, 16>;  // column-major
using Quat = std::array<double, 4>;  // x, y, z, w

inline Mat identity() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }
inline Mat mul(const Mat& a, const Mat& b) { return multiply_mat4(a, b); }
inline Mat trs(const std::array<double, 3>& t, const Quat& q, const std::array<double, 3>& s) {
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    Mat m = {1 - 2 * (y * y + z * z),
             2 * (x * y + z * w),
             2 * (x * z - y * w),
             0,
             2 * (x * y - z * w),
             1 - 2 * (x * x + z * z),
             2 * (y * z + x * w),
             0,
             2 * (x * z + y * w),
             2 * (y * z - x * w),
             1 - 2 * (x * x + y * y),
             0,
             t[0],
             t[1],
             t[2],
             1};
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) m[c * 4 + r] *= s[c];
    return m;
}

// Determinant of the upper-left 3 × 3 block: negative for a transform that mirrors.
inline double determinant3(const Mat& m) {
    const double a = m[0], b = m[4], c = m[8], d = m[1], e = m[5], f = m[9], g = m[2], h = m[6], i = m[10];
    return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
}

// Inverse of an affine transform (rotation/scale/shear + translation), as bind poses are.
inline Mat invert_affine(const Mat& m) {
    const double a = m[0], b = m[4], c = m[8], d = m[1], e = m[5], f = m[9], g = m[2], h = m[6], i = m[10];
    const double det = determinant3(m);
    const double k = det != 0 ? 1.0 / det : 0.0;
    Mat r = identity();
    r[0] = (e * i - f * h) * k, r[4] = (c * h - b * i) * k, r[8] = (b * f - c * e) * k;
    r[1] = (f * g - d * i) * k, r[5] = (a * i - c * g) * k, r[9] = (c * d - a * f) * k;
    r[2] = (d * h - e * g) * k, r[6] = (b * g - a * h) * k, r[10] = (a * e - b * d) * k;
    for (int row = 0; row < 3; ++row) r[12 + row] = -(r[row] * m[12] + r[4 + row] * m[13] + r[8 + row] * m[14]);
    return r;
}

}  // namespace animorder::io
