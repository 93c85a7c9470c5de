// Static procedural test meshes: a UV sphere and a (p, q) torus knot tube, closed, watertight and
// wound counter-clockwise outward, at a requested triangle count. Vertices come in generation
// order (ring after ring), which is the "input order" the vertex-cache tests start from.
#include "animorder/procedural_shapes.h"

#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "lathe.h"

#include <cmath>
#include <string>

namespace animorder {
namespace {

AnimatedMesh static_mesh(const std::string& name, const std::vector<double>& positions, std::vector<uint32_t> indices) {
    AnimatedMesh mesh;
    mesh.name = name;
    mesh.vertex_count = positions.size() / 3;
    mesh.indices = std::move(indices);
    mesh.keyframe_positions.assign(positions.begin(), positions.end());
    mesh.primitives.push_back({name, 0, mesh.indices.size()});
    mesh.clips.push_back({"static", 0.0, 30.0, 0, 1});
    return mesh;
}

}  // namespace

AnimatedMesh make_uv_sphere(size_t target_triangles) {
    // 2·S·(R − 1) triangles for R rings between the poles and S = 2(R − 1) segments.
    const int gaps = std::max(2, int(std::lround(std::sqrt(double(target_triangles) / 4.0))));
    std::vector<procedural::Ring> rings;
    for (int i = 1; i < gaps; ++i) {
        const double theta = M_PI * i / gaps;
        rings.push_back({-std::cos(theta), std::sin(theta)});
    }
    std::vector<double> positions, along;
    std::vector<uint32_t> indices;
    procedural::add_lathe(positions, along, indices, {0, 0, 0}, {0, 1, 0}, -1.0, rings, 1.0, 2 * gaps);
    return static_mesh("sphere", positions, std::move(indices));
}

AnimatedMesh make_torus_knot(size_t target_triangles, int p, int q) {
    if (p < 1 || q < 1) throw InvalidInput("torus knot needs p, q >= 1");
    // 2·N·S triangles: N rings along the curve, S = N/8 around the tube.
    const int segments = std::max(3, int(std::lround(std::sqrt(double(target_triangles) / 16.0))));
    const int rings = std::max(8, int(std::lround(double(target_triangles) / (2.0 * segments))));
    using procedural::Vec3;
    auto curve = [&](double t) {
        const double r = 2.0 + std::cos(q * t);
        return Vec3{r * std::cos(p * t), r * std::sin(p * t), -std::sin(q * t)};
    };
    // Parallel-transported frames along the closed curve; the twist left at the seam is spread
    // evenly over the rings so the tube closes on itself without a jump.
    std::vector<Vec3> centre(rings), tangent(rings), normal(rings);
    for (int i = 0; i < rings; ++i) {
        const double t = 2.0 * M_PI * i / rings, h = 1e-4;
        centre[i] = curve(t);
        tangent[i] = procedural::normalize(curve(t + h) - curve(t - h));
    }
    normal[0] = procedural::normalize(procedural::cross(tangent[0], {0, 0, 1}));
    for (int i = 1; i < rings; ++i) {
        const Vec3 n = normal[i - 1] - tangent[i] * procedural::dot(normal[i - 1], tangent[i]);
        normal[i] = procedural::normalize(n);
    }
    const Vec3 end =
        procedural::normalize(normal[rings - 1] - tangent[0] * procedural::dot(normal[rings - 1], tangent[0]));
    const double twist =
        std::atan2(procedural::dot(procedural::cross(end, normal[0]), tangent[0]), procedural::dot(end, normal[0]));

    const double tube = 0.4;
    std::vector<double> positions;
    for (int i = 0; i < rings; ++i) {
        const Vec3 b = procedural::cross(tangent[i], normal[i]);
        const double correction = twist * i / rings;
        for (int s = 0; s < segments; ++s) {
            const double phi = 2.0 * M_PI * s / segments + correction;
            const Vec3 v = centre[i] + normal[i] * (tube * std::cos(phi)) + b * (tube * std::sin(phi));
            positions.insert(positions.end(), {v.x, v.y, v.z});
        }
    }
    std::vector<uint32_t> indices;
    auto vertex = [&](int i, int s) { return uint32_t((i % rings) * segments + (s % segments)); };
    for (int i = 0; i < rings; ++i)
        for (int s = 0; s < segments; ++s) {
            const uint32_t a = vertex(i, s), b = vertex(i + 1, s), c = vertex(i + 1, s + 1), d = vertex(i, s + 1);
            indices.insert(indices.end(), {a, d, c, a, c, b});  // outward: (around) × (along) = normal
        }
    return static_mesh("torus-knot", positions, std::move(indices));
}

}  // namespace animorder
