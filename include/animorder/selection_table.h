// animorder — the runtime lookup table (selection_table.cpp; DESIGN.md "Runtime selection").
#pragma once

#include "animorder/clustering.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace animorder {

// Per keyframe of the clip, a grid over the view direction's polar angle θ ∈ [0, π] (from +Y)
// and azimuth φ ∈ [0, 2π) (from +Z towards +X). Cell (f, i, j) stands for θ = i·π/(theta_steps−1)
// and φ = j·2π/phi_steps, and holds the buffer of the clustering viewpoint nearest to it at
// keyframe f. Lookup rounds f, θ and φ to the nearest cell (φ wraps around).
struct SelectionTable {
    uint32_t keyframes = 0;
    uint32_t theta_steps = 0;
    uint32_t phi_steps = 0;
    std::vector<uint8_t> cells;  // [(f · theta_steps + i) · phi_steps + j]
};

// With theta_steps = phi_steps = 0 the grid is chosen from the viewpoint count: 5° cells for up
// to 162 viewpoints (37 × 72), 2.5° for 642, 1.25° beyond. A cell is then always much closer to
// its rounding viewpoint than neighbouring viewpoints are (162: 15.9° apart), so a clustering
// viewpoint looks up exactly its own node.
SelectionTable build_selection_table(const ClusteringResult& clustering, size_t keyframe_begin, size_t keyframe_count,
                                     uint32_t theta_steps = 0, uint32_t phi_steps = 0);

// The buffer for keyframe f (clip-local) and a unit view direction (from the frame's centre
// to the camera, in the mesh's space).
uint32_t select_buffer(const SelectionTable& table, size_t keyframe, const float direction[3]);

}  // namespace animorder
