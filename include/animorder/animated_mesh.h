// animorder — the animated mesh every command works on (DESIGN.md "Animated mesh").
//
// One fixed triangle-list index buffer over V vertices (front faces counter-clockwise), one
// index range per primitive, and F keyframes, each a full array of V positions. Clips own
// contiguous runs of keyframes. Loaders (glTF, assimp, procedural) produce this; algorithms read
// its arrays. No file I/O here.
#pragma once

#include "animorder/invalid_input.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace animorder {

// How a primitive's material composites (glTF's material.alphaMode; DESIGN.md "Materials").
// Opaque and Mask write depth and are ordered for least overdraw; Blend is drawn after the opaque
// scene with depth test on and depth writes off, and is ordered for back-to-front correctness.
enum class AlphaMode { Opaque, Mask, Blend };

// "OPAQUE", "MASK", "BLEND" (glTF's spelling).
const char* alpha_mode_name(AlphaMode mode);

struct Primitive {
    std::string name;
    size_t first_index = 0;  // into AnimatedMesh::indices
    size_t index_count = 0;  // multiple of 3
    // Where it came from, for writers: the file's mesh and primitive, and the mesh vertex of its
    // vertex 0 (its vertices are vertex_base .. vertex_base + vertex_count − 1). −1: generated.
    int source_mesh = -1;
    int source_primitive = -1;
    size_t vertex_base = 0;
    size_t vertex_count = 0;
    // Its material: both faces drawn (glTF doubleSided; no back-face culling) and how it blends.
    // Formats without materials (MD2, IQM, procedural shapes) give single-sided opaque.
    bool double_sided = false;
    AlphaMode alpha_mode = AlphaMode::Opaque;
    // The file's node transform mirrors it (a negative determinant), so the file's front faces are
    // clockwise (glTF 2.0: "the determinant of the node's global transform defines the winding
    // order"; engines flip their culling for it): the loader swaps the last two
    // corners of each of its triangles, so that `indices` keeps counter-clockwise front faces, and
    // writers of the file's own index data swap them back (to_file_winding).
    bool mirrored = false;
};

struct Clip {
    std::string name;
    double duration_s = 0;      // last key time − first key time
    double sample_rate = 30;    // keyframes per second (DESIGN.md default 30)
    size_t first_keyframe = 0;  // into AnimatedMesh keyframes
    size_t keyframe_count = 0;
    int source_animation = -1;  // glTF input: the animation it was sampled from; −1 otherwise
    double start_time_s = 0;    // glTF input: the animation time of keyframe 0 (first key time)
    // A clip file made for a differently proportioned skeleton: how it was retargeted onto the
    // character, naming the largest difference (assimp_loader.h); empty when applied as it is.
    std::string retargeted = {};
};

struct AnimatedMesh {
    std::string name;
    size_t vertex_count = 0;
    std::vector<uint32_t> indices;      // triangle list, CCW front faces
    std::vector<Primitive> primitives;  // cover indices in order, without gaps
    std::vector<Clip> clips;
    std::vector<float> keyframe_positions;  // keyframe_count() × vertex_count × xyz
    size_t joint_count = 0;                 // 0 for vertex-keyframe or static meshes
    size_t morph_target_count = 0;

    size_t triangle_count() const { return indices.size() / 3; }
    size_t keyframe_count() const { return vertex_count ? keyframe_positions.size() / (3 * vertex_count) : 0; }
    const float* keyframe(size_t k) const { return keyframe_positions.data() + k * vertex_count * 3; }
    float* keyframe(size_t k) { return keyframe_positions.data() + k * vertex_count * 3; }
};

// Throws InvalidInput (animorder.h) when the mesh breaks its own invariants: indices out of
// range or not a multiple of 3, primitives that do not tile the index buffer, clips outside the
// keyframes, a keyframe array of the wrong size, or a non-finite position.
void validate_animated_mesh(const AnimatedMesh& mesh);

// validate_animated_mesh for code that reads the positions of `keyframes` only (cluster_nodes of
// one clip's keyframes): the same checks, the positions of those keyframes alone, and each
// keyframe must exist. A character's clips are then scanned once between them, not once each.
void validate_animated_mesh(const AnimatedMesh& mesh, const std::vector<uint32_t>& keyframes);

// validate_animated_mesh without the positions, for code that reads none (Tipsify's patches).
void validate_mesh_topology(const AnimatedMesh& mesh);

// Per triangle of mesh.indices: 1 where its primitive is double-sided (drawn without culling).
// Empty when no primitive is, so that callers pass nullptr and keep the culling-only path.
std::vector<uint8_t> double_sided_triangles(const AnimatedMesh& mesh);

// Swaps the last two corners of every triangle of the mirrored primitives in `indices` (a triangle
// list as long as mesh.indices, each primitive's triangles within its own range, as every order
// keeps them): from mesh.indices' counter-clockwise front faces to the file's winding, and back.
void to_file_winding(const AnimatedMesh& mesh, uint32_t* indices);
// True when some primitive is mirrored.
bool has_mirrored_primitives(const AnimatedMesh& mesh);

// True when some primitive blends (AlphaMode::Blend).
bool has_blended_primitives(const AnimatedMesh& mesh);

// The mesh with only the named clips (in the order named; several clips of one name all, in the
// mesh's order) and their keyframes. Throws
// InvalidInput naming a clip that does not exist and the clips that do.
AnimatedMesh select_clips(const AnimatedMesh& mesh, const std::vector<std::string>& names);

}  // namespace animorder
