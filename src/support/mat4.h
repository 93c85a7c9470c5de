// Private to src/ (not installed): the column-major 4×4 matrix product (OpenGL and glTF layout,
// element [column · 4 + row]) shared by the camera (camera.cpp), the loaders' node transforms
// (src/io/transform.h) and the procedural character's skeleton. Sums in T, left to right over k,
// so a float matrix multiplies in float and a double one in double.
#pragma once

#include <array>

namespace animorder {

template <typename T>
std::array<T, 16> multiply_mat4(const std::array<T, 16>& a, const std::array<T, 16>& b) {
    std::array<T, 16> r{};
    for (int column = 0; column < 4; ++column)
        for (int row = 0; row < 4; ++row) {
            T s = 0;
            for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[column * 4 + k];
            r[column * 4 + row] = s;
        }
    return r;
}

}  // namespace animorder
