// Triangle identity by vertex indices (a hash of the rotation-normalised triple) and by corner
// data (a uniform grid over the corners' first three values, the triangle's centroid); the
// nearest triangle by centroid through nanoflann's k-d tree (Blanco & Rai, 2014; Friedman,
// Bentley & Finkel, "An algorithm for finding best matches in logarithmic expected time", 1977).
#include "animorder/triangle_matching.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <unordered_map>

#include <nanoflann.hpp>

namespace animorder {
namespace {

// The triple rotated so that its smallest index comes first: equal for the three rotations of a
// triangle, different for its mirror image.
std::array<uint32_t, 3> rotated(const uint32_t* t) {
    const int r = t[0] <= t[1] && t[0] <= t[2] ? 0 : (t[1] <= t[2] ? 1 : 2);
    return {t[r], t[(r + 1) % 3], t[(r + 2) % 3]};
}

}  // namespace

std::vector<uint32_t> triangle_permutation(const uint32_t* base, const uint32_t* order, size_t triangle_count) {
    std::map<std::array<uint32_t, 3>, std::vector<uint32_t>> where;
    for (size_t t = triangle_count; t-- > 0;)
        where[rotated(base + 3 * t)].push_back(uint32_t(t));  // popped in sequence
    std::vector<uint32_t> result(triangle_count);
    for (size_t t = 0; t < triangle_count; ++t) {
        const auto it = where.find(rotated(order + 3 * t));
        if (it == where.end() || it->second.empty()) return {};
        result[t] = it->second.back();
        it->second.pop_back();
    }
    return result;
}

TriangleMatch match_triangles(const std::vector<float>& from, const std::vector<float>& to, size_t dims,
                              float tolerance) {
    TriangleMatch m;
    const size_t per = 3 * dims;
    if (dims < 3 || per == 0) return m;
    const size_t from_count = from.size() / per, to_count = to.size() / per;
    m.from_of_to.assign(to_count, -1);
    const double cell = std::max(double(tolerance), 1e-12) * 2;
    auto centroid = [&](const std::vector<float>& v, size_t t, int axis) {
        return (double(v[t * per + size_t(axis)]) + v[t * per + dims + size_t(axis)] +
                v[t * per + 2 * dims + size_t(axis)]) /
               3;
    };
    struct Key {
        int64_t x, y, z;
        bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
    };
    struct Hash {
        size_t operator()(const Key& k) const {
            return size_t(uint64_t(k.x) * 73856093u ^ uint64_t(k.y) * 19349663u ^ uint64_t(k.z) * 83492791u);
        }
    };
    auto key = [&](const std::vector<float>& v, size_t t) {
        return Key{int64_t(std::floor(centroid(v, t, 0) / cell)), int64_t(std::floor(centroid(v, t, 1) / cell)),
                   int64_t(std::floor(centroid(v, t, 2) / cell))};
    };
    std::unordered_map<Key, std::vector<uint32_t>, Hash> grid;
    for (size_t s = 0; s < from_count; ++s) grid[key(from, s)].push_back(uint32_t(s));
    std::vector<bool> used(from_count, false);
    for (size_t t = 0; t < to_count; ++t) {
        const Key k = key(to, t);
        double best = INFINITY;
        int64_t best_s = -1;
        for (int64_t dx = -1; dx <= 1; ++dx)
            for (int64_t dy = -1; dy <= 1; ++dy)
                for (int64_t dz = -1; dz <= 1; ++dz) {
                    const auto it = grid.find(Key{k.x + dx, k.y + dy, k.z + dz});
                    if (it == grid.end()) continue;
                    for (uint32_t s : it->second) {
                        if (used[s]) continue;
                        for (size_t r = 0; r < 3; ++r) {
                            double worst = 0;
                            for (size_t c = 0; c < 3 && worst <= tolerance; ++c)
                                for (size_t d = 0; d < dims; ++d)
                                    worst = std::max(worst, std::fabs(double(to[t * per + c * dims + d]) -
                                                                      from[s * per + ((c + r) % 3) * dims + d]));
                            if (worst <= tolerance && (worst < best || (worst == best && int64_t(s) < best_s))) {
                                best = worst;
                                best_s = int64_t(s);
                            }
                        }
                    }
                }
        if (best_s >= 0) {
            used[size_t(best_s)] = true;
            m.from_of_to[t] = best_s;
            ++m.matched;
        }
    }
    return m;
}

namespace {

// The centroids of the triangles, `dims` doubles each, as nanoflann's dataset.
struct Centroids {
    std::vector<double> values;
    size_t dims = 0;
    Centroids(const std::vector<float>& corners, size_t d) : dims(d) {
        const size_t count = d == 0 ? 0 : corners.size() / (3 * d);
        values.resize(count * d);
        for (size_t t = 0; t < count; ++t)
            for (size_t i = 0; i < d; ++i)
                values[t * d + i] =
                    (double(corners[(3 * t) * d + i]) + corners[(3 * t + 1) * d + i] + corners[(3 * t + 2) * d + i]) /
                    3;
    }
    size_t kdtree_get_point_count() const { return dims == 0 ? 0 : values.size() / dims; }
    double kdtree_get_pt(size_t t, size_t i) const { return values[t * dims + i]; }
    template <typename Box>
    bool kdtree_get_bbox(Box&) const {
        return false;
    }
};

}  // namespace

NearestTriangles nearest_triangles(const std::vector<float>& from, const std::vector<float>& to, size_t dims) {
    NearestTriangles n;
    const Centroids a(from, dims), b(to, dims);
    const size_t from_count = a.kdtree_get_point_count(), to_count = b.kdtree_get_point_count();
    if (from_count == 0) return n;
    using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Centroids>, Centroids, -1,
                                                     uint32_t>;
    Tree tree(int(dims), a, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    n.from_of_to.resize(to_count);
    n.distance.resize(to_count);
    for (size_t t = 0; t < to_count; ++t) {
        uint32_t index = 0;
        double squared = 0;
        tree.knnSearch(&b.values[t * dims], 1, &index, &squared);
        n.from_of_to[t] = index;
        n.distance[t] = std::sqrt(squared);
    }
    return n;
}

}  // namespace animorder
