// animorder — Loop subdivision of a whole animated mesh (subdivide_animated_mesh.cpp): the paper's
// Table 1 measures Ganfaul after one and two levels (Δ1, Δ2).
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/loop_subdivision.h"

#include <functional>

namespace animorder {

// The mesh after `levels` levels of Loop subdivision (src/assets/subdivide_animated_mesh.cpp):
// the operator is built on keyframe 0's welded topology and applied to every keyframe; clips,
// keyframe counts and names, joint_count and morph_target_count (as information) are kept; each
// child triangle stays in its parent's primitive, and primitives keep tiling the index buffer in
// order (their index ranges × 4^levels; the vertices are generated, so source_mesh = −1).
// levels 0 returns a copy. Throws InvalidInput for an invalid mesh, levels > 4 or more than 2^31
// indices in the result. `before_building`, when given, is called with the result's vertex and
// keyframe counts once they are known and before the keyframes are allocated (a caller's size
// checks: it may throw).
AnimatedMesh subdivide_animated_mesh(
    const AnimatedMesh& mesh, unsigned levels,
    const std::function<void(size_t vertex_count, size_t keyframes)>& before_building = nullptr);

}  // namespace animorder
