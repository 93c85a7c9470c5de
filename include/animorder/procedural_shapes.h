// animorder — static test meshes made in code (procedural_shapes.cpp).
#pragma once

#include "animorder/animated_mesh.h"

#include <cstddef>

namespace animorder {

// Static test meshes (one clip of one keyframe), closed and consistently wound (CCW outward).
// The triangle count is close to target_triangles (within a few percent).
AnimatedMesh make_uv_sphere(size_t target_triangles);
AnimatedMesh make_torus_knot(size_t target_triangles, int p = 2, int q = 3);

}  // namespace animorder
