// Patches of a whole character: Tipsify and fast linear clustering (Sander, Nehab & Barczak 2007,
// §3–4) per primitive, as step 1 of Han & Sander 2017 (§3.1), and the patch centroids that the
// k-means distances need.
//
// A character's primitives are separate draws (own materials), so a patch never straddles two of
// them and every order keeps the primitives in file order: a cluster's buffer is one patch order
// per primitive. Centroids are area-weighted (a patch's surface centre, not its vertex average,
// which over-weights finely tessellated corners) and framed per keyframe.
#include "animorder/mesh_patches.h"

#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/patches.h"
#include "animorder/planar_clusters.h"
#include "animorder/tipsify.h"
#include "animorder/triangle_order.h"
#include "animorder/viewpoints.h"

#include "joined_vertices.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace animorder {

namespace {

// λ patches of every primitive over `indices` (the mesh's, or the same triangles with other
// vertex ids): Tipsify, then Sander 2007's patch cutting.
MeshPatches patches_over(const AnimatedMesh& mesh, const uint32_t* indices, double lambda, unsigned cache_size) {
    MeshPatches result;
    result.cache_order.reserve(mesh.triangle_count());
    result.patch_starts.push_back(0);
    for (size_t prim = 0; prim < mesh.primitives.size(); ++prim) {
        const Primitive& primitive = mesh.primitives[prim];
        const uint32_t* source = indices + primitive.first_index;
        const size_t triangles = primitive.index_count / 3;
        std::vector<uint32_t> order(triangles);
        const TipsifyResult tipsified =
            tipsify(order.data(), source, primitive.index_count, mesh.vertex_count, cache_size);
        std::vector<uint32_t> cache_indices(primitive.index_count);
        apply_triangle_order(cache_indices.data(), source, order.data(), triangles);
        const std::vector<uint32_t> starts =
            build_patches(cache_indices.data(), cache_indices.size(), mesh.vertex_count,
                          tipsified.hard_boundaries.data(), tipsified.hard_boundaries.size(), lambda, cache_size);
        const uint32_t base = uint32_t(result.cache_order.size());
        const uint32_t first_triangle = uint32_t(primitive.first_index / 3);
        for (uint32_t t : order) result.cache_order.push_back(first_triangle + t);
        for (size_t p = 1; p < starts.size(); ++p) {
            result.patch_starts.push_back(base + starts[p]);
            result.patch_primitive.push_back(uint32_t(prim));
        }
    }
    return result;
}

}  // namespace

MeshPatches build_mesh_patches(const AnimatedMesh& mesh, double lambda, unsigned cache_size) {
    validate_mesh_topology(mesh);  // Tipsify and the patches read the indices only
    return patches_over(mesh, mesh.indices.data(), lambda, cache_size);
}

std::vector<uint32_t> joined_vertices(const AnimatedMesh& mesh) {
    validate_animated_mesh(mesh, std::vector<uint32_t>{0});
    return first_vertex_at_each_position(mesh.keyframe(0), mesh.vertex_count);
}

MeshPatches build_welded_patches(const AnimatedMesh& mesh, double lambda, size_t max_triangles,
                                 unsigned cache_size) {
    // Each vertex replaced by the first one at its coordinates: a face then shares the vertices
    // of its neighbours across a hard edge (flat shading) or a UV seam, as Tipsify's adjacency
    // needs.
    const std::vector<uint32_t> first = joined_vertices(mesh);
    std::vector<uint32_t> welded(mesh.indices.size());
    for (size_t i = 0; i < welded.size(); ++i) welded[i] = first[mesh.indices[i]];
    MeshPatches patches = patches_over(mesh, welded.data(), lambda, cache_size);
    if (max_triangles == 0) return patches;
    return patch_pieces(std::move(patches), max_triangles);
}

MeshPatches patch_pieces(MeshPatches patches, size_t max_triangles) {
    if (max_triangles == 0) throw InvalidInput("patch pieces: at most 0 triangles a piece");
    // Pieces along the cache order: a patch of max_triangles or more cut into the fewest pieces
    // of at most max_triangles, sized as equally as can be; smaller patches of one primitive
    // that follow each other packed together while the pack stays within max_triangles.
    const uint64_t most = max_triangles;
    MeshPatches pieces;
    pieces.cache_order = std::move(patches.cache_order);
    pieces.patch_starts.push_back(0);
    const auto cut = [&](uint32_t end, uint32_t primitive) {
        pieces.patch_starts.push_back(end);
        pieces.patch_primitive.push_back(primitive);
    };
    for (size_t p = 0; p < patches.patch_count(); ++p) {
        const uint32_t begin = patches.patch_starts[p], end = patches.patch_starts[p + 1];
        const uint32_t primitive = patches.patch_primitive[p];
        const bool packing = pieces.patch_starts.back() < begin;  // smaller patches wait in a pack
        if (end - begin >= most) {
            if (packing) cut(begin, patches.patch_primitive[p - 1]);
            const uint64_t count = (end - begin + most - 1) / most;
            for (uint64_t i = 1; i <= count; ++i) cut(uint32_t(begin + uint64_t(end - begin) * i / count), primitive);
            continue;
        }
        if (packing && (patches.patch_primitive[p - 1] != primitive || end - pieces.patch_starts.back() > most))
            cut(begin, patches.patch_primitive[p - 1]);
        if (p + 1 == patches.patch_count()) cut(end, primitive);
    }
    return pieces;
}

MeshPatches build_planar_units(const AnimatedMesh& mesh, const MeshPatches& like, size_t keyframe,
                               unsigned cache_size) {
    validate_animated_mesh(mesh);
    if (keyframe >= mesh.keyframe_count())
        throw InvalidInput("planar units: keyframe " + std::to_string(keyframe) + " does not exist");
    std::vector<size_t> count(mesh.primitives.size(), 0);
    for (uint32_t p : like.patch_primitive) ++count[p];
    MeshPatches result;
    result.patch_starts.push_back(0);
    for (size_t prim = 0; prim < mesh.primitives.size(); ++prim) {
        const Primitive& primitive = mesh.primitives[prim];
        const uint32_t* source = mesh.indices.data() + primitive.first_index;
        const size_t triangles = primitive.index_count / 3;
        if (triangles == 0) continue;
        const size_t clusters = std::max<size_t>(1, std::min(count[prim], triangles));
        const std::vector<uint32_t> cluster_of =
            cluster_by_normals(source, primitive.index_count, mesh.keyframe(keyframe), mesh.vertex_count, clusters);
        std::vector<uint32_t> order(triangles);
        const std::vector<uint32_t> starts = tipsify_clusters(
            order.data(), source, primitive.index_count, mesh.vertex_count, cluster_of.data(), clusters, cache_size);
        const uint32_t base = uint32_t(result.cache_order.size());
        const uint32_t first_triangle = uint32_t(primitive.first_index / 3);
        for (uint32_t t : order) result.cache_order.push_back(first_triangle + t);
        for (size_t c = 1; c < starts.size(); ++c) {
            if (starts[c] == starts[c - 1]) continue;  // an empty cluster is no unit
            result.patch_starts.push_back(base + starts[c]);
            result.patch_primitive.push_back(uint32_t(prim));
        }
    }
    return result;
}

std::vector<uint32_t> patch_order_to_triangle_order(const MeshPatches& patches,
                                                    const std::vector<uint32_t>& patch_order) {
    if (patch_order.size() != patches.patch_count())
        throw InvalidInput("patch order has " + std::to_string(patch_order.size()) + " entries, there are " +
                           std::to_string(patches.patch_count()) + " patches");
    validate_triangle_order(patch_order.data(), patch_order.size());
    // Primitives in file order: bucket the patch order by primitive, keeping its sequence.
    size_t primitive_count = 0;
    for (uint32_t prim : patches.patch_primitive) primitive_count = std::max<size_t>(primitive_count, prim + 1);
    std::vector<std::vector<uint32_t>> by_primitive(primitive_count);
    for (uint32_t p : patch_order) by_primitive[patches.patch_primitive[p]].push_back(p);
    std::vector<uint32_t> order;
    order.reserve(patches.cache_order.size());
    for (const auto& list : by_primitive)
        for (uint32_t p : list)
            for (uint32_t i = patches.patch_starts[p]; i < patches.patch_starts[p + 1]; ++i)
                order.push_back(patches.cache_order[i]);
    return order;
}

std::vector<float> patch_centroids(const AnimatedMesh& mesh, const MeshPatches& patches, const Framing& framing,
                                   const std::vector<uint32_t>& keyframes) {
    const size_t patch_count = patches.patch_count();
    std::vector<float> centroids(keyframes.size() * patch_count * 3);
    for (size_t i = 0; i < keyframes.size(); ++i) {
        const uint32_t k = keyframes[i];
        if (k >= mesh.keyframe_count()) throw InvalidInput("keyframe " + std::to_string(k) + " does not exist");
        const float* positions = mesh.keyframe(k);
        const float* centre = &framing.centres[3 * size_t(k)];
        for (size_t p = 0; p < patch_count; ++p) {
            double sum[3] = {0, 0, 0}, plain[3] = {0, 0, 0}, area = 0;
            const uint32_t begin = patches.patch_starts[p], end = patches.patch_starts[p + 1];
            for (uint32_t j = begin; j < end; ++j) {
                const uint32_t* tri = mesh.indices.data() + 3 * size_t(patches.cache_order[j]);
                const float* a = positions + 3 * size_t(tri[0]);
                const float* b = positions + 3 * size_t(tri[1]);
                const float* c = positions + 3 * size_t(tri[2]);
                const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                             v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
                const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
                const double w = 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                for (int d = 0; d < 3; ++d) {
                    const double centre_t = (double(a[d]) + b[d] + c[d]) / 3.0;
                    sum[d] += w * centre_t;
                    plain[d] += centre_t;
                }
                area += w;
            }
            float* out = &centroids[(i * patch_count + p) * 3];
            for (int d = 0; d < 3; ++d)
                out[d] = float((area > 0 ? sum[d] / area : plain[d] / double(end - begin)) - centre[d]);
        }
    }
    return centroids;
}

}  // namespace animorder
