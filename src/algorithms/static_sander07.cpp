// static-sander07: view-independent patch sorting by approximate occlusion potential.
//
// This follows: Sander, Nehab & Barczak, "Fast Triangle Reordering for Vertex Locality and
// Reduced Overdraw", SIGGRAPH 2007, §5, equation 4:  O'(P, M) = (C(P) − C(M)) · N(P).
//
// A patch far out along its own normal is likely to occlude the rest of the model from the
// views that see it, so patches are drawn by descending O'. The value is not the occlusion
// integral (it can be negative) but orders patches much like it, and it costs one pass.
// C is the area-weighted surface centroid, N(P) the area-weighted average of the triangles' unit
// normals (Σ a_t n_t / Σ a_t, i.e. Σ cross/2 / Σ area: large flat patches weigh more than
// crumpled ones). Accumulation is in double so the order does not depend on summation noise;
// ties keep patch id order, so the result is deterministic.
#include "animorder/static_sander07.h"

#include "animorder/invalid_input.h"
#include "animorder/patches.h"
#include "animorder/tipsify.h"
#include "animorder/triangle_order.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

namespace animorder {
namespace {

struct Vec3 {
    double x = 0, y = 0, z = 0;
};
Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec3 operator*(Vec3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

Vec3 load(const float* positions, size_t stride, uint32_t v) {
    const float* p = reinterpret_cast<const float*>(reinterpret_cast<const char*>(positions) + v * stride);
    return {p[0], p[1], p[2]};
}

// Area-weighted sums over a run of triangles; falls back to plain means when the area is zero.
struct SurfaceMoments {
    double area = 0;
    Vec3 weighted_centroid;  // Σ a_t c_t
    Vec3 cross_sum;          // Σ 2 a_t n_t
    Vec3 centroid_sum;       // Σ c_t
    size_t triangles = 0;

    void add(Vec3 a, Vec3 b, Vec3 c) {
        const Vec3 n = cross(b - a, c - a);
        const double area_t = 0.5 * std::sqrt(dot(n, n));
        const Vec3 centre = (a + b + c) * (1.0 / 3.0);
        area += area_t;
        weighted_centroid = weighted_centroid + centre * area_t;
        cross_sum = cross_sum + n;
        centroid_sum = centroid_sum + centre;
        ++triangles;
    }
    Vec3 centroid() const {
        if (area > 0) return weighted_centroid * (1.0 / area);
        return triangles ? centroid_sum * (1.0 / double(triangles)) : Vec3{};
    }
    Vec3 average_normal() const { return area > 0 ? cross_sum * (0.5 / area) : Vec3{}; }
};

void validate_positions(const float* positions, size_t vertex_count, size_t stride) {
    if (vertex_count == 0) return;
    if (positions == nullptr) throw InvalidInput("positions are null");
    if (stride < 3 * sizeof(float) || stride % sizeof(float) != 0)
        throw InvalidInput("position stride " + std::to_string(stride) +
                           " bytes must be a multiple of 4 and at least 12");
    for (size_t v = 0; v < vertex_count; ++v) {
        const Vec3 p = load(positions, stride, uint32_t(v));
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw InvalidInput("position of vertex " + std::to_string(v) + " is not finite");
    }
}

}  // namespace

void sort_patches_sander07(uint32_t* patch_order, const uint32_t* indices, size_t index_count, const float* positions,
                           size_t vertex_count, size_t position_stride, const uint32_t* patch_starts,
                           size_t patch_count) {
    validate_indices(indices, index_count, vertex_count);
    validate_positions(positions, vertex_count, position_stride);
    const size_t triangle_count = index_count / 3;
    if (patch_count == 0) return;
    if (patch_starts[0] != 0 || patch_starts[patch_count] != triangle_count)
        throw InvalidInput("patch starts must begin at 0 and end at the triangle count");

    std::vector<SurfaceMoments> patches(patch_count);
    SurfaceMoments mesh;
    for (size_t p = 0; p < patch_count; ++p) {
        if (patch_starts[p + 1] <= patch_starts[p])
            throw InvalidInput("patch " + std::to_string(p) + " is empty or patch starts are not ascending");
        for (size_t t = patch_starts[p]; t < patch_starts[p + 1]; ++t) {
            const uint32_t* tri = indices + 3 * t;
            const Vec3 a = load(positions, position_stride, tri[0]);
            const Vec3 b = load(positions, position_stride, tri[1]);
            const Vec3 c = load(positions, position_stride, tri[2]);
            patches[p].add(a, b, c);
        }
        mesh.area += patches[p].area;
        mesh.weighted_centroid = mesh.weighted_centroid + patches[p].weighted_centroid;
        mesh.centroid_sum = mesh.centroid_sum + patches[p].centroid_sum;
        mesh.triangles += patches[p].triangles;
    }

    const Vec3 mesh_centroid = mesh.centroid();
    std::vector<double> rank(patch_count);
    for (size_t p = 0; p < patch_count; ++p)
        rank[p] = dot(patches[p].centroid() - mesh_centroid, patches[p].average_normal());

    std::iota(patch_order, patch_order + patch_count, 0u);
    std::stable_sort(patch_order, patch_order + patch_count, [&](uint32_t a, uint32_t b) { return rank[a] > rank[b]; });
}

StaticOrderResult order_static_sander07(uint32_t* order, const uint32_t* indices, size_t index_count,
                                        const float* positions, size_t vertex_count, size_t position_stride,
                                        double lambda, unsigned cache_size) {
    validate_positions(positions, vertex_count, position_stride);
    const size_t triangle_count = index_count / 3;
    const TipsifyResult tipsified = tipsify(order, indices, index_count, vertex_count, cache_size);
    StaticOrderResult result;
    result.hard_boundary_count = tipsified.hard_boundaries.size();
    if (triangle_count == 0) return result;

    std::vector<uint32_t> cache_order(order, order + triangle_count);
    std::vector<uint32_t> cache_indices(index_count);
    apply_triangle_order(cache_indices.data(), indices, cache_order.data(), triangle_count);

    const std::vector<uint32_t> starts =
        build_patches(cache_indices.data(), index_count, vertex_count, tipsified.hard_boundaries.data(),
                      tipsified.hard_boundaries.size(), lambda, cache_size);
    result.patch_count = starts.size() - 1;

    std::vector<uint32_t> patch_order(result.patch_count);
    sort_patches_sander07(patch_order.data(), cache_indices.data(), index_count, positions, vertex_count,
                          position_stride, starts.data(), result.patch_count);
    std::vector<uint32_t> within(triangle_count);
    expand_patch_order(within.data(), patch_order.data(), starts.data(), result.patch_count);
    compose_triangle_orders(order, cache_order.data(), within.data(), triangle_count);
    return result;
}

}  // namespace animorder
