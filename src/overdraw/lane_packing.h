// Private to src/overdraw: the table that packs the chosen lanes of an 8-lane vector to its
// front with one permutation (AVX2's vpermd), used where a vectorised loop keeps some of its
// elements (facing_filter.cpp's candidates, rasterize_node.h's drawn triangles).
#pragma once

#include <cstdint>

namespace animorder {

// For each 8-bit mask of lanes, those lanes in order (the rest zero).
struct LanePacking {
    alignas(32) int32_t lanes[256][8] = {};
    constexpr LanePacking() {
        for (int mask = 0; mask < 256; ++mask) {
            int n = 0;
            for (int lane = 0; lane < 8; ++lane)
                if (mask >> lane & 1) lanes[mask][n++] = lane;
        }
    }
};
inline constexpr LanePacking kLanePacking;

}  // namespace animorder
