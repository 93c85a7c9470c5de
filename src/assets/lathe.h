// Closed surfaces of revolution for the procedural inputs: a profile of rings between two poles,
// swept around an axis, with pole fans (no degenerate triangles) and counter-clockwise-outward
// winding. Internal to src/assets.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

namespace animorder::procedural {

struct Vec3 {
    double x = 0, y = 0, z = 0;
};
inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(Vec3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline Vec3 normalize(Vec3 a) { return a * (1.0 / std::sqrt(dot(a, a))); }

// A ring of the profile: distance along the axis from the origin point, and its radius.
struct Ring {
    double along;
    double radius;
};

// Appends a closed surface: pole at `origin + axis·front.along`, the rings, pole at the back.
// side_scale stretches the cross-section along the frame's second direction (ellipses).
// Returns the first new vertex. positions: xyz; `along` receives each vertex's axial coordinate.
inline uint32_t add_lathe(std::vector<double>& positions, std::vector<double>& along, std::vector<uint32_t>& indices,
                          Vec3 origin, Vec3 axis, double front_pole, const std::vector<Ring>& rings, double back_pole,
                          int segments, double side_scale = 1.0) {
    axis = normalize(axis);
    const Vec3 helper = std::fabs(axis.y) < 0.9 ? Vec3{0, 1, 0} : Vec3{1, 0, 0};
    const Vec3 u = normalize(cross(axis, helper));
    const Vec3 v = cross(axis, u);
    const uint32_t base = uint32_t(positions.size() / 3);
    auto emit = [&](Vec3 p, double a) {
        positions.insert(positions.end(), {p.x, p.y, p.z});
        along.push_back(a);
    };
    emit(origin + axis * front_pole, front_pole);
    for (const Ring& r : rings)
        for (int s = 0; s < segments; ++s) {
            const double phi = 2.0 * M_PI * s / segments;
            emit(origin + axis * r.along + u * (r.radius * std::cos(phi)) + v * (r.radius * side_scale * std::sin(phi)),
                 r.along);
        }
    emit(origin + axis * back_pole, back_pole);
    const uint32_t front = base, back = base + 1 + uint32_t(rings.size() * segments);
    auto ring_vertex = [&](size_t ring, int s) { return base + 1 + uint32_t(ring * segments + (s % segments)); };
    // (u, v, axis) is right-handed, so going round with φ is counter-clockwise seen from +axis.
    for (int s = 0; s < segments; ++s) indices.insert(indices.end(), {front, ring_vertex(0, s + 1), ring_vertex(0, s)});
    for (size_t r = 0; r + 1 < rings.size(); ++r)
        for (int s = 0; s < segments; ++s) {
            const uint32_t a = ring_vertex(r, s), b = ring_vertex(r, s + 1), c = ring_vertex(r + 1, s + 1),
                           d = ring_vertex(r + 1, s);
            indices.insert(indices.end(), {a, b, c, a, c, d});
        }
    const size_t last = rings.size() - 1;
    for (int s = 0; s < segments; ++s)
        indices.insert(indices.end(), {back, ring_vertex(last, s), ring_vertex(last, s + 1)});
    return base;
}

// Rings of a capsule from 0 to length along the axis, radius r0 → r1, with hemispherical caps.
inline std::vector<Ring> capsule_rings(double length, double r0, double r1, int cap_rings, int body_rings) {
    std::vector<Ring> rings;
    for (int i = 1; i <= cap_rings; ++i) {  // front cap, from the pole towards the equator
        const double a = M_PI / 2 * (1.0 - double(i) / cap_rings);
        rings.push_back({-r0 * std::sin(a), r0 * std::cos(a)});
    }
    for (int i = 1; i < body_rings; ++i) {
        const double t = double(i) / body_rings;
        rings.push_back({length * t, r0 + (r1 - r0) * t});
    }
    for (int i = 0; i < cap_rings; ++i) {  // back cap, from the equator towards the pole
        const double a = M_PI / 2 * double(i) / cap_rings;
        rings.push_back({length + r1 * std::sin(a), r1 * std::cos(a)});
    }
    return rings;
}

}  // namespace animorder::procedural
