// Linear blend skinning (the glTF 2.0 skinning model): each vertex is the weighted sum of its
// bind position transformed by its joints' skinning matrices (joint world · inverse bind).
//
// Weights that do not sum to one (glTF allows, exporters produce them) are normalised rather than
// trusted, so a character never shrinks towards the origin; a vertex without weight keeps its
// bind position. Invalid joints and non-finite weights are errors, never silent garbage.
#include "animorder/skinning.h"

#include "animorder/invalid_input.h"

#include <cmath>
#include <string>

namespace animorder {

void skin_positions(float* out_positions, const float* bind_positions, size_t vertex_count, const uint16_t* joints,
                    const float* weights, size_t influences_per_vertex, const Mat4* joint_matrices,
                    size_t joint_count) {
    for (size_t v = 0; v < vertex_count; ++v) {
        const float* p = bind_positions + 3 * v;
        double sum = 0, x = 0, y = 0, z = 0;
        for (size_t i = 0; i < influences_per_vertex; ++i) {
            const size_t slot = v * influences_per_vertex + i;
            const float w = weights[slot];
            if (!std::isfinite(w) || w < 0)
                throw InvalidInput("vertex " + std::to_string(v) + " has an invalid skin weight");
            // A zero-weight slot's joint is never read: glTF only says unused joints SHOULD be 0,
            // and exporters pad with arbitrary ones, so only influences that count are checked.
            if (w == 0) continue;
            if (joints[slot] >= joint_count)
                throw InvalidInput("vertex " + std::to_string(v) + " names joint " + std::to_string(joints[slot]) +
                                   ", but the skin has " + std::to_string(joint_count));
            const Mat4& m = joint_matrices[joints[slot]];
            x += w * (double(m[0]) * p[0] + double(m[4]) * p[1] + double(m[8]) * p[2] + m[12]);
            y += w * (double(m[1]) * p[0] + double(m[5]) * p[1] + double(m[9]) * p[2] + m[13]);
            z += w * (double(m[2]) * p[0] + double(m[6]) * p[1] + double(m[10]) * p[2] + m[14]);
            sum += w;
        }
        float* out = out_positions + 3 * v;
        if (sum <= 0) {
            out[0] = p[0], out[1] = p[1], out[2] = p[2];
        } else {
            out[0] = float(x / sum), out[1] = float(y / sum), out[2] = float(z / sum);
        }
    }
}

}  // namespace animorder
