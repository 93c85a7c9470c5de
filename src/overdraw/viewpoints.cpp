// Viewpoints and framing, as Han & Sander 2017 §3 and §4 use them.
//
// Clustering viewpoints are the vertices of a subdivided icosahedron (12, 42, 162, 642; the
// paper's default 162), nearly uniform and identical on every run. Evaluation viewpoints are
// random directions from a fixed seed (the paper's protocol), drawn with std::mt19937_64, whose
// sequence the C++ standard fixes, and an explicit mapping to [0, 1) (the standard
// distributions' algorithms are implementation-defined), so they are the same everywhere.
// Framing moves each keyframe's bounding-box centre to the origin so that the camera at 3R sees
// the whole character at every keyframe; it never rotates.
#include "animorder/viewpoints.h"

#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/triangle_order.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <utility>

namespace animorder {
namespace {

struct Dir {
    double x, y, z;
};

Dir normalized(Dir d) {
    const double n = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    return {d.x / n, d.y / n, d.z / n};
}

}  // namespace

std::vector<float> icosphere_directions(unsigned subdivisions) {
    if (subdivisions > 6)
        throw InvalidInput("icosphere subdivision level " + std::to_string(subdivisions) + " is too large (max 6)");
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Dir> vertices = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    for (Dir& v : vertices) v = normalized(v);
    std::vector<std::array<uint32_t, 3>> faces = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                                  {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                                  {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                                  {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (unsigned level = 0; level < subdivisions; ++level) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;  // ordered: deterministic ids
        auto midpoint = [&](uint32_t a, uint32_t b) {
            const auto key = std::minmax(a, b);
            auto [it, inserted] = midpoints.try_emplace({key.first, key.second}, uint32_t(vertices.size()));
            if (inserted) {
                const Dir& p = vertices[a];
                const Dir& q = vertices[b];
                vertices.push_back(normalized({p.x + q.x, p.y + q.y, p.z + q.z}));
            }
            return it->second;
        };
        std::vector<std::array<uint32_t, 3>> finer;
        finer.reserve(faces.size() * 4);
        for (const auto& f : faces) {
            const uint32_t ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]), ca = midpoint(f[2], f[0]);
            finer.push_back({f[0], ab, ca});
            finer.push_back({f[1], bc, ab});
            finer.push_back({f[2], ca, bc});
            finer.push_back({ab, bc, ca});
        }
        faces = std::move(finer);
    }
    std::vector<float> out;
    out.reserve(vertices.size() * 3);
    for (const Dir& v : vertices) out.insert(out.end(), {float(v.x), float(v.y), float(v.z)});
    return out;
}

unsigned icosphere_subdivisions_for(size_t count) {
    size_t n = 12;
    for (unsigned level = 0; level <= 6; ++level, n = (n - 2) * 4 + 2)
        if (n == count) return level;
    throw InvalidInput("an icosphere has 12, 42, 162, 642, 2562, ... vertices, not " + std::to_string(count));
}

std::vector<float> random_sphere_directions(size_t count, uint64_t seed) {
    std::mt19937_64 rng(seed);
    auto uniform = [&rng] { return double(rng() >> 11) * (1.0 / 9007199254740992.0); };  // 53 bits → [0,1)
    std::vector<float> out;
    out.reserve(count * 3);
    for (size_t i = 0; i < count; ++i) {
        // Archimedes: z uniform in [−1, 1] and azimuth uniform give a uniform point on the sphere.
        const double z = 2.0 * uniform() - 1.0;
        const double phi = 2.0 * M_PI * uniform();
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        out.insert(out.end(), {float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)});
    }
    return out;
}

Framing frame_keyframes(const float* keyframe_positions, size_t keyframe_count, size_t vertex_count,
                        const uint32_t* indices, size_t index_count) {
    validate_indices(indices, index_count, vertex_count);
    // Only referenced vertices count: an unused vertex must not inflate the view radius.
    std::vector<uint8_t> referenced(vertex_count, 0);
    for (size_t i = 0; i < index_count; ++i) referenced[indices[i]] = 1;

    Framing framing;
    framing.centres.assign(keyframe_count * 3, 0.0f);
    framing.radii.assign(keyframe_count, 0.0f);
    double radius = 0;
    for (size_t k = 0; k < keyframe_count; ++k) {
        const float* p = keyframe_positions + k * vertex_count * 3;
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t v = 0; v < vertex_count; ++v) {
            if (!referenced[v]) continue;
            for (int c = 0; c < 3; ++c) {
                if (!std::isfinite(p[3 * v + c]))
                    throw InvalidInput("keyframe " + std::to_string(k) + ": position of vertex " + std::to_string(v) +
                                       " is not finite");
                lo[c] = std::min(lo[c], double(p[3 * v + c]));
                hi[c] = std::max(hi[c], double(p[3 * v + c]));
            }
        }
        if (index_count == 0) continue;
        double centre[3];
        for (int c = 0; c < 3; ++c) centre[c] = float(0.5 * (lo[c] + hi[c]));  // the float the camera uses
        double frame_radius = 0;
        for (size_t v = 0; v < vertex_count; ++v) {
            if (!referenced[v]) continue;
            const double dx = p[3 * v] - centre[0], dy = p[3 * v + 1] - centre[1], dz = p[3 * v + 2] - centre[2];
            frame_radius = std::max(frame_radius, std::sqrt(dx * dx + dy * dy + dz * dz));
        }
        // A hair larger than the farthest vertex, so float rounding cannot push it out of view.
        framing.radii[k] = float(frame_radius * (1.0 + 1e-6));
        radius = std::max(radius, frame_radius);
        for (int c = 0; c < 3; ++c) framing.centres[3 * k + c] = float(centre[c]);
    }
    framing.radius = float(radius * (1.0 + 1e-6));
    // Clip coordinates are floats of the order of R (w up to 4R): a model beyond 2^100 would
    // overflow them, one below 2^-100 would lose them to underflow. Neither is a model in any unit.
    if (radius > 0 && !(radius >= 0x1p-100 && radius <= 0x1p100)) {
        char extent[32];
        std::snprintf(extent, sizeof extent, "%g", radius);
        throw InvalidInput(std::string("the model's extent (framing radius ") + extent +
                           ") is outside 2^-100 to 2^100: float clip coordinates cannot hold it");
    }
    return framing;
}

Framing frame_animated_mesh(const AnimatedMesh& mesh) {
    return frame_keyframes(mesh.keyframe_positions.data(), mesh.keyframe_count(), mesh.vertex_count,
                           mesh.indices.data(), mesh.indices.size());
}

Framing frame_subset(const Framing& framing, const std::vector<uint32_t>& keyframes) {
    Framing subset = framing;
    subset.radius = 0;
    for (uint32_t k : keyframes) {
        if (k >= framing.radii.size()) throw InvalidInput("keyframe " + std::to_string(k) + " is not framed");
        subset.radius = std::max(subset.radius, framing.radii[k]);
    }
    return subset;
}

}  // namespace animorder
