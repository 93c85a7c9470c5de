// animorder — viewpoints and framing (viewpoints.cpp; DESIGN.md "Framing", "Viewpoints").
#pragma once

#include "animorder/animated_mesh.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace animorder {

// Unit directions at the vertices of an icosahedron subdivided `subdivisions` times
// (0 → 12, 1 → 42, 2 → 162, 3 → 642, ...): 10·4^s + 2 directions, xyz each. Deterministic.
std::vector<float> icosphere_directions(unsigned subdivisions);

// The subdivision level that gives `count` directions; throws InvalidInput if count is not
// 10·4^s + 2 (12, 42, 162, 642, 2562).
unsigned icosphere_subdivisions_for(size_t count);

// `count` directions uniform on the unit sphere from a seeded generator (DESIGN.md's evaluation
// viewpoints use 300 with a fixed seed). Same seed, same directions, on every platform.
std::vector<float> random_sphere_directions(size_t count, uint64_t seed);

// Framing (DESIGN.md): each keyframe's bounding box centre (of the vertices the index buffer
// references) moves to the origin; the view radius R is the largest distance from a keyframe's
// centre to one of its vertices, over all keyframes. Framing never rotates.
struct Framing {
    std::vector<float> centres;  // 3 per keyframe
    std::vector<float> radii;    // per keyframe: farthest vertex from its centre
    float radius = 0;            // the view radius R: the largest of radii

    // Every keyframe framed is a point (R = 0: a clip that hides the mesh by scale 0): nothing is
    // drawn from any view, and no camera can be placed at 3R. The methods and the evaluation
    // leave such keyframes' nodes unscored.
    bool shows_nothing() const { return !(radius > 0); }
};
Framing frame_keyframes(const float* keyframe_positions, size_t keyframe_count, size_t vertex_count,
                        const uint32_t* indices, size_t index_count);

// frame_keyframes of every keyframe of an animated mesh, over its whole index buffer.
Framing frame_animated_mesh(const AnimatedMesh& mesh);

// The same framing with R taken over a subset of keyframes (one clip is one animation).
Framing frame_subset(const Framing& framing, const std::vector<uint32_t>& keyframes);

}  // namespace animorder
