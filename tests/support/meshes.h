// Small helpers shared by the tests: mesh fixtures and order checks.
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/animorder.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <random>
#include <vector>

namespace animorder::test {

// A deterministic Fisher–Yates shuffle of the triangles (std::shuffle's sequence is
// implementation-defined; this one is not).
inline std::vector<uint32_t> shuffled_triangles(const std::vector<uint32_t>& indices, uint32_t seed) {
    const size_t n = indices.size() / 3;
    std::vector<uint32_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = uint32_t(i);
    std::mt19937 rng(seed);
    for (size_t i = n; i > 1; --i) std::swap(order[i - 1], order[rng() % i]);
    std::vector<uint32_t> out(indices.size());
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) out[3 * i + c] = indices[3 * order[i] + c];
    return out;
}

// True when `reordered` holds exactly the triangles of `original`, each with its corners in the
// same cyclic sequence (same winding), as a multiset.
inline bool same_triangles_same_winding(const std::vector<uint32_t>& original, const std::vector<uint32_t>& reordered) {
    if (original.size() != reordered.size()) return false;
    auto canonical = [](const std::vector<uint32_t>& ib) {
        std::vector<std::array<uint32_t, 3>> tris(ib.size() / 3);
        for (size_t t = 0; t < tris.size(); ++t) {
            std::array<uint32_t, 3> tri{ib[3 * t], ib[3 * t + 1], ib[3 * t + 2]};
            // Rotate so the smallest index comes first: rotation keeps winding, swapping would not.
            while (tri[0] > tri[1] || tri[0] > tri[2]) tri = {tri[1], tri[2], tri[0]};
            tris[t] = tri;
        }
        std::sort(tris.begin(), tris.end());
        return tris;
    };
    return canonical(original) == canonical(reordered);
}

inline bool is_permutation_of_iota(const std::vector<uint32_t>& order) {
    std::vector<uint32_t> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    for (size_t i = 0; i < sorted.size(); ++i)
        if (sorted[i] != i) return false;
    return true;
}

inline std::vector<uint32_t> applied(const std::vector<uint32_t>& indices, const std::vector<uint32_t>& order) {
    std::vector<uint32_t> out(indices.size());
    apply_triangle_order(out.data(), indices.data(), order.data(), order.size());
    return out;
}

}  // namespace animorder::test
