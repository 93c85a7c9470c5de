// Small helpers shared by the tests: mesh fixtures and order checks.
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/triangle_order.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
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

// Every unit's triangles (unit u: cache_order[unit_starts[u] .. unit_starts[u + 1])) drawn one after
// another in `order`, in the unit's own inner order.
inline bool keeps_units_whole(const std::vector<uint32_t>& order, const std::vector<uint32_t>& unit_starts,
                              const std::vector<uint32_t>& cache_order) {
    std::vector<size_t> position(order.size());
    for (size_t i = 0; i < order.size(); ++i) position[order[i]] = i;
    for (size_t u = 0; u + 1 < unit_starts.size(); ++u)
        for (uint32_t j = unit_starts[u] + 1; j < unit_starts[u + 1]; ++j)
            if (position[cache_order[j]] != position[cache_order[j - 1]] + 1) return false;
    return true;
}

inline std::vector<uint32_t> applied(const std::vector<uint32_t>& indices, const std::vector<uint32_t>& order) {
    std::vector<uint32_t> out(indices.size());
    apply_triangle_order(out.data(), indices.data(), order.data(), order.size());
    return out;
}

// Edge length at keyframe b over edge length at keyframe a, for every corner edge of every
// triangle whose edge has non-zero length at a.
inline std::vector<double> edge_stretch(const AnimatedMesh& m, size_t a, size_t b) {
    std::vector<double> ratios;
    for (size_t t = 0; t < m.indices.size(); t += 3)
        for (int i = 0; i < 3; ++i) {
            const uint32_t u = m.indices[t + size_t(i)], v = m.indices[t + size_t(i + 1) % 3];
            auto length = [&](size_t k) {
                const float *p = m.keyframe(k) + 3 * u, *q = m.keyframe(k) + 3 * v;
                return std::sqrt(double(p[0] - q[0]) * (p[0] - q[0]) + double(p[1] - q[1]) * (p[1] - q[1]) +
                                 double(p[2] - q[2]) * (p[2] - q[2]));
            };
            const double base = length(a);
            if (base > 0) ratios.push_back(length(b) / base);
        }
    return ratios;
}

inline double median(std::vector<double> values) {
    if (values.empty()) return 0.0;
    std::nth_element(values.begin(), values.begin() + ptrdiff_t(values.size() / 2), values.end());
    return values[values.size() / 2];
}

// Vertex v of keyframe `keyframe` is at (x, y, z) within `tolerance` on each axis.
inline void expect_position(const AnimatedMesh& m, size_t keyframe, size_t v, double x, double y, double z,
                            double tolerance = 1e-4) {
    const float* p = m.keyframe(keyframe) + 3 * v;
    EXPECT_NEAR(p[0], x, tolerance) << "keyframe " << keyframe << " vertex " << v;
    EXPECT_NEAR(p[1], y, tolerance) << "keyframe " << keyframe << " vertex " << v;
    EXPECT_NEAR(p[2], z, tolerance) << "keyframe " << keyframe << " vertex " << v;
}

// The mesh flat-shaded: every corner its own vertex (three per triangle), at the same positions
// in every keyframe; no two faces share a vertex.
inline AnimatedMesh flat_shaded(const AnimatedMesh& m) {
    AnimatedMesh flat = m;
    flat.vertex_count = m.indices.size();
    flat.keyframe_positions.assign(m.keyframe_count() * flat.vertex_count * 3, 0.0f);
    for (size_t k = 0; k < m.keyframe_count(); ++k)
        for (size_t i = 0; i < m.indices.size(); ++i)
            std::copy(m.keyframe(k) + 3 * m.indices[i], m.keyframe(k) + 3 * m.indices[i] + 3, flat.keyframe(k) + 3 * i);
    for (size_t i = 0; i < flat.indices.size(); ++i) flat.indices[i] = uint32_t(i);
    return flat;
}

}  // namespace animorder::test
