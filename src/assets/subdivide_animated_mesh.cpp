// Loop subdivision of a whole animated mesh (the paper's "Ganfaul, 1 and 2 levels of Loop
// subdivision" rows): the operator of loop_subdivision.cpp is built once on keyframe 0's welded
// topology, all primitives together, and applied to every keyframe.
#include "animorder/subdivide_animated_mesh.h"

#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/loop_subdivision.h"

#include <tbb/parallel_for.h>

#include <string>

namespace animorder {

AnimatedMesh subdivide_animated_mesh(const AnimatedMesh& mesh, unsigned levels,
                                     const std::function<void(size_t, size_t)>& before_building) {
    validate_animated_mesh(mesh);
    if (levels > kMaxSubdivisionLevels)
        throw InvalidInput("subdivision levels is " + std::to_string(levels) + "; at most " +
                           std::to_string(kMaxSubdivisionLevels) + " (each level multiplies the triangles by 4)");
    if (levels == 0) return mesh;
    if (mesh.keyframe_count() == 0) throw InvalidInput("the mesh has no keyframe to subdivide");

    const SubdivisionOperator op = build_loop_subdivision(mesh.indices.data(), mesh.indices.size(), mesh.keyframe(0),
                                                          mesh.vertex_count, 3 * sizeof(float), levels);
    AnimatedMesh out;
    out.name = mesh.name;
    out.vertex_count = op.output_vertex_count;
    out.indices = op.indices;
    out.clips = mesh.clips;
    out.joint_count = mesh.joint_count;
    out.morph_target_count = mesh.morph_target_count;
    const size_t growth = size_t(1) << (2 * levels);
    for (const Primitive& p : mesh.primitives) {
        Primitive q;
        q.name = p.name;
        q.first_index = p.first_index * growth;
        q.index_count = p.index_count * growth;
        q.double_sided = p.double_sided;
        q.alpha_mode = p.alpha_mode;
        out.primitives.push_back(q);  // generated vertices: source_mesh −1, no vertex range
    }
    const size_t keyframes = mesh.keyframe_count();
    if (before_building) before_building(out.vertex_count, keyframes);
    out.keyframe_positions.resize(keyframes * out.vertex_count * 3);
    // Each keyframe is written by one task only: the same bytes whatever the thread count.
    tbb::parallel_for(size_t(0), keyframes,
                      [&](size_t k) { apply_subdivision(out.keyframe(k), op, mesh.keyframe(k), 3 * sizeof(float)); });
    return out;
}

}  // namespace animorder
