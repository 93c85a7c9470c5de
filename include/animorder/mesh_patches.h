// animorder — the patches of a whole character (mesh_patches.cpp): every primitive Tipsified and
// cut into patches on its own (Han & Sander 2017, §3.1).
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/vertex_cache.h"
#include "animorder/viewpoints.h"

#include <cstdint>
#include <vector>

namespace animorder {

// Every primitive Tipsified and cut into patches on its own; patches never straddle primitives.
struct MeshPatches {
    std::vector<uint32_t> cache_order;      // face permutation: primitives in file order, each Tipsified
    std::vector<uint32_t> patch_starts;     // positions in cache_order; patch_count() + 1 entries
    std::vector<uint32_t> patch_primitive;  // primitive of each patch
    size_t patch_count() const { return patch_primitive.size(); }
};

MeshPatches build_mesh_patches(const AnimatedMesh& mesh, double lambda, unsigned cache_size = kDefaultCacheSize);

// Each vertex's first vertex (lowest id) at bit-identical coordinates in keyframe 0: the mesh's
// surface, whatever its vertex buffer splits (flat shading, hard edges, UV seams). A flat-shaded
// mesh, three vertices per triangle, has about one sixth as many distinct ones.
std::vector<uint32_t> joined_vertices(const AnimatedMesh& mesh);

// The same patches over the surface rather than the vertex buffer: the vertices joined as
// joined_vertices says, so faces that share no vertex but a position are neighbours, as they
// are on screen (on a flat-shaded mesh build_mesh_patches gives one patch per triangle: no face
// shares a vertex). The cache order inside a patch is Tipsify's over the joined vertices.
// max_triangles > 0 makes pieces along that cache order: a patch of max_triangles or more cut
// into the fewest pieces of at most max_triangles, sized as equally as can be, and smaller
// patches of one primitive that follow each other packed while the pack stays within
// max_triangles (so at λ >= 3, single-triangle patches, runs of max_triangles). (`measured`'s
// units on flat-shaded meshes: methods.h.)
MeshPatches build_welded_patches(const AnimatedMesh& mesh, double lambda, size_t max_triangles = 0,
                                 unsigned cache_size = kDefaultCacheSize);

// Patches made into pieces along their cache order, as build_welded_patches' max_triangles says
// (max_triangles > 0; throws InvalidInput for 0).
MeshPatches patch_pieces(MeshPatches patches, size_t max_triangles);

// Nehab, Barczak & Sander 2006's planar clusters as the units instead of λ patches (the measured
// method's alternative units): each primitive's triangles clustered by normal (cluster_by_normals,
// positions of `keyframe`) into as many clusters as `like` has patches there, each Tipsified on
// its own (tipsify_clusters). Throws InvalidInput for a keyframe out of range.
MeshPatches build_planar_units(const AnimatedMesh& mesh, const MeshPatches& like, size_t keyframe,
                               unsigned cache_size = kDefaultCacheSize);

// A face permutation of the whole mesh from a patch permutation: primitives stay in file order
// (patches of a primitive keep their relative order from patch_order), triangles inside a patch
// keep their Tipsify order.
std::vector<uint32_t> patch_order_to_triangle_order(const MeshPatches& patches,
                                                    const std::vector<uint32_t>& patch_order);

// Area-weighted centroid of every patch at every keyframe of the list, after framing (the
// keyframe's centre subtracted): centroids[(i · patch_count + p) · 3 + c] for keyframes[i].
std::vector<float> patch_centroids(const AnimatedMesh& mesh, const MeshPatches& patches, const Framing& framing,
                                   const std::vector<uint32_t>& keyframes);

}  // namespace animorder
