// animorder — reading characters from files into the AnimatedMesh every algorithm takes.
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/evaluation.h"
#include "animorder/overdraw.h"

#include <stdexcept>
#include <string>
#include <vector>

namespace animorder {

// Thrown for a file that cannot be read as asked: what() starts with the file name and says
// what is wrong, in one line.
class LoadError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct LoadOptions {
    double sample_rate = 30;  // keyframes per second of every clip (DESIGN.md)
    // Budget for the sampled animation: keyframes × vertices × 12 bytes of positions. A file
    // whose clips would need more fails with a LoadError naming the need and this budget before
    // anything that size is allocated (`--max-memory` raises it).
    size_t max_keyframe_bytes = size_t(4) << 30;
};

// glTF 2.0 (.gltf with its buffers, or .glb): every TRIANGLES (strips and fans converted)
// primitive of every mesh node of the default scene, in node then primitive order, with their own
// vertex arrays concatenated (vertex identity is kept: primitive p's vertex i is mesh vertex
// base(p) + i). Each animation is a clip, sampled from its first to its last key time at
// sample_rate: node TRS (LINEAR with slerp, STEP, CUBICSPLINE), skins (linear blend skinning with
// inverse bind matrices, weights normalised), morph target weights (default, node, animated;
// sparse accessors). A file without animation is one clip "static" of one keyframe.
AnimatedMesh load_gltf(const std::string& path, const LoadOptions& options = {});

// Any format assimp reads (FBX, Collada, .X, .b3d, MD5, OBJ, …): meshes in node order with their
// own vertices (identical vertices joined), bones (8 strongest weights, normalised), node
// animations sampled at sample_rate. clip_files: Mixamo-style animation-only files whose
// channels drive the character's joints by node name; each adds its animations as clips (named
// after the file), and a file none of whose joints the character has is an error.
AnimatedMesh load_assimp(const std::string& path, const std::vector<std::string>& clip_files = {},
                         const LoadOptions& options = {});

// Quake II MD2 with every frame (assimp reads only the first): frames grouped into clips by name
// ("run1".."run6" → "run"), played at MD2's 10 frames per second and resampled at sample_rate.
AnimatedMesh load_md2(const std::string& path, const LoadOptions& options = {});

// Inter-Quake Models (IQM v2) with their skeletal animations (assimp reads only the mesh).
AnimatedMesh load_iqm(const std::string& path, const LoadOptions& options = {});

// By extension: .gltf/.glb → load_gltf, .md2 → load_md2, .iqm → load_iqm (no clip files),
// anything else → load_assimp. A folder in
// clip_files stands for the files in it, in name order.
AnimatedMesh load_character(const std::string& path, const std::vector<std::string>& clip_files = {},
                            const LoadOptions& options = {});

// The glTF file `input_path` (which `mesh` was loaded from) with the method's orders: each
// primitive's `indices` holds buffer `fallback`, `extras.animorder.orders` lists an accessor per
// buffer, and the root `extras.animorder` holds the clips' lookup tables and frame centres as
// accessors. All other content is written back unchanged; buffers are embedded; relative image
// URIs are rewritten to point, from output_path's folder, at the same files. Returns GLB bytes
// when `binary`, else glTF JSON text.
std::string gltf_with_orders(const std::string& input_path, const std::string& output_path, const AnimatedMesh& mesh,
                             const MethodBuffers& buffers, uint32_t fallback, const Framing& framing,
                             const std::string& method, bool binary);

// A new glTF file holding the whole animated mesh (gltf_animated_writer.cpp; what `animorder
// subdivide` writes): one node and mesh, one glTF primitive per Primitive (its vertices, uint32
// indices), POSITION = keyframe 0, one morph target per keyframe (deltas from keyframe 0), and
// one animation per clip driving the morph weights (LINEAR, keys at j / sample_rate, one-hot on
// the clip's keyframe), so load_gltf at the clip's rate gives the keyframes back. Deterministic.
// Returns GLB bytes when `binary`, else glTF JSON text with the buffer embedded. Throws
// InvalidInput for an invalid mesh, LoadError when serialising fails.
std::string gltf_animated_mesh(const AnimatedMesh& mesh, bool binary);

}  // namespace animorder
