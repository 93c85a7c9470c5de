// animorder — a whole animated mesh as a new glTF file (gltf_animated_writer.cpp).
#pragma once

#include "animorder/animated_mesh.h"

#include <string>

namespace animorder {

// A new glTF file holding the whole animated mesh (what `animorder subdivide` writes): one node
// and mesh, one glTF primitive per Primitive (its vertices, uint32 indices), POSITION = keyframe 0, one morph target per keyframe (deltas from keyframe 0), and
// one animation per clip driving the morph weights (LINEAR, keys at j / sample_rate, one-hot on
// the clip's keyframe), so load_gltf at the clip's rate gives the keyframes back. Deterministic.
// Returns GLB bytes when `binary`, else glTF JSON text with the buffer embedded. Throws
// InvalidInput for an invalid mesh, LoadError when serialising fails.
std::string gltf_animated_mesh(const AnimatedMesh& mesh, bool binary);

}  // namespace animorder
