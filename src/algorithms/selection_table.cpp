// The runtime lookup table: which of the k buffers to draw, from keyframe and view direction.
//
// This follows Han & Sander, JCGT 2017, §3.3: a table indexed by keyframe and the polar and
// azimuth angles (θ, φ) of the view direction relative to the framed model, each cell holding the
// buffer of the closest clustering viewpoint; lookup rounds f, θ and φ to the nearest cell. The
// (θ, φ) grid is less uniform than the icosphere, but its lookup is two atan-free roundings away.
// θ is measured from +Y (the usual up axis of characters), φ from +Z towards +X.
#include "animorder/selection_table.h"

#include "animorder/clustering.h"
#include "animorder/invalid_input.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace animorder {
namespace {

void cell_direction(uint32_t i, uint32_t j, uint32_t theta_steps, uint32_t phi_steps, double out[3]) {
    const double theta = theta_steps > 1 ? M_PI * double(i) / double(theta_steps - 1) : 0.5 * M_PI;
    const double phi = 2.0 * M_PI * double(j) / double(phi_steps);
    out[0] = std::sin(theta) * std::sin(phi);
    out[1] = std::cos(theta);
    out[2] = std::sin(theta) * std::cos(phi);
}

}  // namespace

SelectionTable build_selection_table(const ClusteringResult& clustering, size_t keyframe_begin, size_t keyframe_count,
                                     uint32_t theta_steps, uint32_t phi_steps) {
    const size_t views = clustering.directions.size() / 3;
    if (theta_steps == 0 && phi_steps == 0) {
        const double spacing_deg = views <= 162 ? 5.0 : views <= 642 ? 2.5 : 1.25;
        theta_steps = uint32_t(std::lround(180.0 / spacing_deg)) + 1;
        phi_steps = uint32_t(std::lround(360.0 / spacing_deg));
    }
    if (theta_steps < 2 || phi_steps < 1 || theta_steps > 4096 || phi_steps > 8192)
        throw InvalidInput("selection table grid must have 2..4096 polar and 1..8192 azimuth steps");
    SelectionTable table;
    table.keyframes = uint32_t(keyframe_count);
    table.theta_steps = theta_steps;
    table.phi_steps = phi_steps;
    table.cells.resize(size_t(keyframe_count) * theta_steps * phi_steps);

    // The nearest clustering viewpoint of every cell (the same for every keyframe).
    std::vector<uint32_t> nearest(size_t(theta_steps) * phi_steps);
    for (uint32_t i = 0; i < theta_steps; ++i)
        for (uint32_t j = 0; j < phi_steps; ++j) {
            double dir[3];
            cell_direction(i, j, theta_steps, phi_steps, dir);
            uint32_t best = 0;
            double best_dot = -2;
            for (size_t v = 0; v < views; ++v) {
                const float* d = &clustering.directions[3 * v];
                const double dot = dir[0] * d[0] + dir[1] * d[1] + dir[2] * d[2];
                if (dot > best_dot) best_dot = dot, best = uint32_t(v);
            }
            nearest[size_t(i) * phi_steps + j] = best;
        }

    for (size_t f = 0; f < keyframe_count; ++f) {
        const uint32_t global = uint32_t(keyframe_begin + f);
        const auto it = std::find(clustering.keyframes.begin(), clustering.keyframes.end(), global);
        if (it == clustering.keyframes.end())
            throw InvalidInput("keyframe " + std::to_string(global) + " was not clustered");
        const size_t row = size_t(it - clustering.keyframes.begin());
        for (size_t cell = 0; cell < nearest.size(); ++cell)
            table.cells[f * nearest.size() + cell] = uint8_t(clustering.assignment[row * views + nearest[cell]]);
    }
    return table;
}

uint32_t select_buffer(const SelectionTable& table, size_t keyframe, const float direction[3]) {
    if (table.keyframes == 0) throw InvalidInput("empty selection table");
    const size_t f = std::min<size_t>(keyframe, table.keyframes - 1);
    const double x = direction[0], y = direction[1], z = direction[2];
    const double length = std::sqrt(x * x + y * y + z * z);
    if (!(length > 0) || !std::isfinite(length)) throw InvalidInput("view direction must be non-zero and finite");
    const double theta = std::acos(std::clamp(y / length, -1.0, 1.0));
    double phi = std::atan2(x, z);
    if (phi < 0) phi += 2.0 * M_PI;
    const uint32_t i = uint32_t(std::lround(theta / M_PI * double(table.theta_steps - 1)));
    const uint32_t j = uint32_t(std::lround(phi / (2.0 * M_PI) * double(table.phi_steps))) % table.phi_steps;
    return table.cells[(f * table.theta_steps + i) * table.phi_steps + j];
}

}  // namespace animorder
