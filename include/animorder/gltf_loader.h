// animorder — the glTF 2.0 loader (gltf_loader.cpp).
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/load.h"

#include <string>

namespace animorder {

// glTF 2.0 (.gltf with its buffers, or .glb): every TRIANGLES (strips and fans converted)
// primitive of every mesh node of the default scene, in node then primitive order, with their own
// vertex arrays concatenated (vertex identity is kept: primitive p's vertex i is mesh vertex
// base(p) + i). Each animation is a clip, sampled from its first to its last key time at
// sample_rate: node TRS (LINEAR with slerp, STEP, CUBICSPLINE), skins (linear blend skinning with
// inverse bind matrices, weights normalised), morph target weights (default, node, animated;
// sparse accessors). A file without animation is one clip "static" of one keyframe.
AnimatedMesh load_gltf(const std::string& path, const LoadOptions& options = {});

}  // namespace animorder
