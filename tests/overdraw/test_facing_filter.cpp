// The facing filter (facing_filter.cpp) against the rasteriser it stands in front of: from its
// candidates the rasteriser draws exactly the fragments it draws from every triangle, on the
// bundled character and on random triangles small and slanted enough that snapping turns some
// of them over; hand-worked cases for what is left out.
#include "animorder/camera.h"
#include "animorder/facing_filter.h"
#include "animorder/invalid_input.h"
#include "animorder/overdraw.h"
#include "animorder/procedural_character.h"
#include "animorder/rasterizer.h"
#include "animorder/viewpoints.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <tuple>
#include <vector>

using namespace animorder;

namespace {

using Fragments = std::vector<std::tuple<uint32_t, uint32_t, float>>;

Fragments fragments_of(const NodeRasterizer& r) {
    Fragments out;
    r.visit_fragments([&](uint32_t p, uint32_t t, float z) { out.emplace_back(p, t, z); });
    return out;
}

struct NodeCheck {
    size_t nodes = 0, left_out = 0, triangles = 0, differing_nodes = 0;
};

// Every view of one keyframe at one resolution: the rasteriser from the candidates against the
// rasteriser from every triangle, fragment for fragment. Also counts the triangles left out and
// checks that the portable and the AVX2 copies of the filter list the same candidates.
void compare_views(const float* positions, size_t vertex_count, const std::vector<uint32_t>& indices,
                   const float centre[3], float radius, unsigned resolution, const uint8_t* modes,
                   const std::vector<float>& directions, NodeCheck& check) {
    FacingFilter filter, portable;
    filter.build(positions, vertex_count, indices.data(), indices.size(), centre, radius, resolution, modes);
    portable.build(positions, vertex_count, indices.data(), indices.size(), centre, radius, resolution, modes);
    portable.set_portable(true);
    ASSERT_TRUE(filter.usable());
    NodeRasterizer all, some;
    std::vector<float> clip(4 * vertex_count);
    for (size_t v = 0; v < directions.size() / 3; ++v) {
        const float* d = &directions[3 * v];
        transform_to_clip(clip.data(), positions, vertex_count, centre, node_view_projection(d, radius));
        all.rasterize(clip.data(), vertex_count, indices.data(), indices.size(), resolution, modes);
        const FacingFilter::Candidates c = filter.candidates(d);
        const std::vector<uint32_t> listed(c.ids, c.ids + c.count);
        const FacingFilter::Candidates p = portable.candidates(d);
        ASSERT_EQ(listed, std::vector<uint32_t>(p.ids, p.ids + p.count)) << "view " << v;
        some.rasterize_validated(clip.data(), vertex_count, indices.data(), indices.size(), resolution, modes,
                                 listed.data(), listed.size());
        const bool same = fragments_of(all) == fragments_of(some);
        EXPECT_TRUE(same) << "view " << v << " at " << resolution << "²";
        check.differing_nodes += !same;
        ++check.nodes;
        check.triangles += indices.size() / 3;
        check.left_out += indices.size() / 3 - listed.size();
    }
}

// n random triangles inside the unit ball (sizes log-uniform from 1e-4 to 0.3, each a right angle
// at a random point with random orientation), then slivers nearly edge-on from each of the 42
// views the test uses.
std::vector<float> random_triangles(size_t n, uint32_t seed, std::vector<uint32_t>& indices) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), exponent(-4.0, std::log10(0.3));
    std::vector<float> positions;
    const auto random_direction = [&] {
        double v[3];
        do {
            for (double& x : v) x = unit(rng);
        } while (v[0] * v[0] + v[1] * v[1] + v[2] * v[2] > 1.0 || v[0] * v[0] + v[1] * v[1] + v[2] * v[2] < 1e-6);
        const double r = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        return std::array<double, 3>{v[0] / r, v[1] / r, v[2] / r};
    };
    for (size_t t = 0; t < n; ++t) {
        const double size = std::pow(10.0, exponent(rng));
        std::array<double, 3> centre = random_direction();
        const double reach = 0.7 * std::cbrt(std::abs(unit(rng)));
        for (double& x : centre) x *= reach;
        const std::array<double, 3> a = random_direction(), b = random_direction();
        const double corners[3][2] = {{0, 0}, {1, 0}, {0, 1}};
        for (const auto& k : corners)
            for (int i = 0; i < 3; ++i) positions.push_back(float(centre[i] + size * (k[0] * a[i] + k[1] * b[i])));
        indices.insert(indices.end(), {uint32_t(3 * t), uint32_t(3 * t + 1), uint32_t(3 * t + 2)});
    }
    // Slivers edge-on from a view, give or take a tilt of 1e-7 to 1e-4: snapping decides which
    // way they face there.
    const std::vector<float> views = icosphere_directions(icosphere_subdivisions_for(42));
    std::uniform_real_distribution<double> tilt(-7.0, -4.0), sign(-1.0, 1.0);
    for (size_t v = 0; v < views.size() / 3; ++v)
        for (int i = 0; i < 100; ++i) {
            std::array<double, 3> a = random_direction();
            for (double& x : a) x *= 0.5;
            double e[3], to_eye[3];
            for (int k = 0; k < 3; ++k) e[k] = 3.0 * views[3 * v + k] - a[k];
            const double r = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
            for (int k = 0; k < 3; ++k) to_eye[k] = e[k] / r;
            const std::array<double, 3> any = random_direction();
            double t[3] = {any[1] * to_eye[2] - any[2] * to_eye[1], any[2] * to_eye[0] - any[0] * to_eye[2],
                           any[0] * to_eye[1] - any[1] * to_eye[0]};
            const double tn = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
            for (double& x : t) x /= tn;
            const double m[3] = {t[1] * to_eye[2] - t[2] * to_eye[1], t[2] * to_eye[0] - t[0] * to_eye[2],
                                 t[0] * to_eye[1] - t[1] * to_eye[0]};
            const double eta = (sign(rng) < 0 ? -1.0 : 1.0) * std::pow(10.0, tilt(rng));
            const uint32_t first = uint32_t(positions.size() / 3);
            for (int k = 0; k < 3; ++k) positions.push_back(float(a[k]));
            for (int k = 0; k < 3; ++k) positions.push_back(float(a[k] + 0.3 * t[k]));
            for (int k = 0; k < 3; ++k) positions.push_back(float(a[k] + 0.15 * t[k] + 0.02 * to_eye[k] + eta * m[k]));
            indices.insert(indices.end(), {first, first + 1, first + 2});
        }
    // A corner at distance 1 (the framing radius) so the sphere is the one the views fit.
    const uint32_t last = uint32_t(positions.size() / 3);
    positions.insert(positions.end(), {1.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f});
    indices.insert(indices.end(), {last, last + 1, last + 2});
    return positions;
}

}  // namespace

TEST(FacingFilter, TheBundledCharacterDrawsTheSameFragmentsFromTheCandidates) {
    const AnimatedMesh mesh = make_procedural_character();
    const Framing framing = frame_animated_mesh(mesh);
    const std::vector<uint8_t> modes = opaque_pass_modes(mesh);
    const std::vector<float> directions = icosphere_directions(icosphere_subdivisions_for(162));
    NodeCheck check;
    for (size_t k = 0; k < mesh.keyframe_count(); k += mesh.keyframe_count() / 3)
        for (const unsigned resolution : {256u, 61u})
            compare_views(mesh.keyframe(uint32_t(k)), mesh.vertex_count, mesh.indices, &framing.centres[3 * k],
                          framing.radius, resolution, modes.empty() ? nullptr : modes.data(), directions, check);
    EXPECT_EQ(check.differing_nodes, 0u);
    // It must leave out a good share, or it is not worth having: most of the back faces.
    EXPECT_GT(double(check.left_out) / double(check.triangles), 0.3) << check.left_out << " of " << check.triangles;
}

TEST(FacingFilter, AnyScaleOfTheCharacterGivesTheSameFragments) {
    // The filter works in units of the framing radius: far from 1 its floats neither overflow nor
    // lose the small triangles to underflow.
    const AnimatedMesh mesh = make_procedural_character();
    const std::vector<float> directions = icosphere_directions(icosphere_subdivisions_for(42));
    for (const float scale : {1e-15f, 1e15f}) {
        std::vector<float> positions(mesh.keyframe(0), mesh.keyframe(0) + 3 * mesh.vertex_count);
        for (float& p : positions) p *= scale;
        const Framing framing =
            frame_keyframes(positions.data(), 1, mesh.vertex_count, mesh.indices.data(), mesh.indices.size());
        NodeCheck check;
        compare_views(positions.data(), mesh.vertex_count, mesh.indices, framing.centres.data(), framing.radius, 256,
                      nullptr, directions, check);
        EXPECT_EQ(check.differing_nodes, 0u) << "scale " << scale;
        EXPECT_GT(double(check.left_out) / double(check.triangles), 0.3) << "scale " << scale;
    }
    // Beyond 2^±100 float clip coordinates overflow or underflow: the framing refuses such a model,
    // and the filter alone would not vouch for it.
    for (const float scale : {1e31f, 1e-31f}) {
        std::vector<float> positions(mesh.keyframe(0), mesh.keyframe(0) + 3 * mesh.vertex_count);
        for (float& p : positions) p *= scale;
        EXPECT_THROW(frame_keyframes(positions.data(), 1, mesh.vertex_count, mesh.indices.data(), mesh.indices.size()),
                     InvalidInput)
            << "scale " << scale;
        const float centre[3] = {0, 0, 0};
        FacingFilter filter;
        filter.build(positions.data(), mesh.vertex_count, mesh.indices.data(), mesh.indices.size(), centre,
                     scale * 2.0f, 256, nullptr);
        EXPECT_FALSE(filter.usable()) << "scale " << scale;
    }
}

TEST(FacingFilter, TinySlantedTrianglesThatSnappingTurnsOverAreKept) {
    std::vector<uint32_t> indices;
    const std::vector<float> positions = random_triangles(6000, 7, indices);
    const float centre[3] = {0, 0, 0};
    const std::vector<float> directions = icosphere_directions(icosphere_subdivisions_for(42));
    NodeCheck check;
    for (const unsigned resolution : {256u, 64u, 1024u})
        compare_views(positions.data(), positions.size() / 3, indices, centre, 1.0f, resolution, nullptr, directions,
                      check);
    EXPECT_EQ(check.differing_nodes, 0u);
    EXPECT_GT(check.left_out, check.triangles / 4);

    // The scene is hard enough to tell: leaving out every triangle that faces away in exact
    // arithmetic (no margin) loses fragments of triangles that snapping turned to face the eye.
    size_t naive_differences = 0;
    NodeRasterizer all, some;
    std::vector<float> clip(positions.size() / 3 * 4);
    const size_t vertex_count = positions.size() / 3;
    for (size_t v = 0; v < directions.size() / 3; ++v) {
        const float* d = &directions[3 * v];
        const double norm = std::sqrt(double(d[0]) * d[0] + double(d[1]) * d[1] + double(d[2]) * d[2]);
        const double eye[3] = {3.0 * d[0] / norm, 3.0 * d[1] / norm, 3.0 * d[2] / norm};
        std::vector<uint32_t> naive;
        for (size_t t = 0; t < indices.size() / 3; ++t) {
            const float* a = &positions[3 * indices[3 * t]];
            const float* b = &positions[3 * indices[3 * t + 1]];
            const float* c = &positions[3 * indices[3 * t + 2]];
            const double u[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
            const double w[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
            const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
            if (n[0] * (eye[0] - a[0]) + n[1] * (eye[1] - a[1]) + n[2] * (eye[2] - a[2]) >= 0)
                naive.push_back(uint32_t(t));
        }
        transform_to_clip(clip.data(), positions.data(), vertex_count, centre, node_view_projection(d, 1.0f));
        all.rasterize(clip.data(), vertex_count, indices.data(), indices.size(), 256);
        some.rasterize_validated(clip.data(), vertex_count, indices.data(), indices.size(), 256, nullptr, naive.data(),
                                 naive.size());
        naive_differences += fragments_of(all) != fragments_of(some);
    }
    EXPECT_GT(naive_differences, 0u);
}

// Slivers that snapping turns to face the eye by nearly as much as it can: each has a pixel
// centre on an edge (so it draws), a snapped doubled area of a few subpixel² on the front side,
// and corners moved up to 0.49 subpixel against the area's gradient before snapping, so that in
// exact arithmetic it faces away. Built in window space and taken back through the camera, near
// the middle of the screen and elsewhere, at the sphere's front, middle and back.
std::vector<float> turned_slivers(const float* direction, unsigned resolution, std::mt19937& rng,
                                  std::vector<uint32_t>& indices) {
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    // The six ends of the axes at distance 1: the framing's centre is the origin, its radius a hair
    // above 1 (the camera the slivers are built for).
    std::vector<float> positions = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
    indices = {0, 1, 0, 2, 3, 2, 4, 5, 4};
    const Framing axes = frame_keyframes(positions.data(), 1, 6, indices.data(), indices.size());
    const Mat4d vp = node_view_projection(direction, axes.radius);
    const double half = 0.5 * resolution;
    // A window position (pixels, y up) at clip w: the point of the framed space (rows x, y, w of vp).
    const auto back = [&](double xw, double yw, double w_in_radii, float* out) {
        const double w = w_in_radii * axes.radius;
        double A[3][4] = {{vp[0], vp[4], vp[8], (xw - half) / half * w - vp[12]},
                          {vp[1], vp[5], vp[9], (yw - half) / half * w - vp[13]},
                          {vp[3], vp[7], vp[11], w - vp[15]}};
        for (int i = 0; i < 3; ++i) {
            int pivot = i;
            for (int r = i + 1; r < 3; ++r)
                if (std::fabs(A[r][i]) > std::fabs(A[pivot][i])) pivot = r;
            for (int c = 0; c < 4; ++c) std::swap(A[i][c], A[pivot][c]);
            for (int r = 0; r < 3; ++r)
                if (r != i)
                    for (int c = 3; c >= i; --c) A[r][c] -= A[r][i] / A[i][i] * A[i][c];
        }
        for (int i = 0; i < 3; ++i) out[i] = float(A[i][3] / A[i][i]);
    };
    for (int t = 0; t < 400; ++t) {
        const double w = t % 3 == 0 ? 3.0 : t % 3 == 1 ? 3.9 : 2.1, spread = t % 2 ? 0.02 : 0.5;
        const int64_t ax = 256 * int64_t(half + (u01(rng) - 0.5) * spread * half);
        const int64_t ay = 256 * int64_t(half + (u01(rng) - 0.5) * spread * half);
        const int p = 2 + int(u01(rng) * (resolution >= 256 ? 8 : 3)), q = p - 1;  // near 45 degrees
        const int64_t k = 257 + int64_t(u01(rng) * 40);  // the centre a + 256 (p, q) lies on edge a b
        const int64_t sx = u01(rng) < 0.5 ? 1 : -1, sy = u01(rng) < 0.5 ? 1 : -1;
        const int64_t bx = ax + sx * k * p, by = ay + sy * k * q;
        int64_t corner[3][2] = {{ax, ay}, {bx, by}, {0, 0}}, best = INT64_MAX;
        for (int64_t i = -8; i <= 8; ++i)
            for (int64_t j = -8; j <= 8; ++j) {  // c: the smallest positive (front) snapped area
                const int64_t cx = (ax + bx) / 2 + i, cy = (ay + by) / 2 + j;
                const int64_t area = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay);
                if (area > 0 && area < best) best = area, corner[2][0] = cx, corner[2][1] = cy;
            }
        const uint32_t first = uint32_t(positions.size() / 3);
        bool outside = false;
        for (int i = 0; i < 3; ++i) {
            const int64_t* b = corner[(i + 1) % 3];
            const int64_t* c = corner[(i + 2) % 3];
            const double gradient[2] = {double(b[1] - c[1]), double(c[0] - b[0])};  // of the area at corner i
            const double move = 0.49 - 0.1 * u01(rng);
            const auto against = [&](double g) { return g > 0 ? -move : g < 0 ? move : 0.0; };
            float point[3];
            back((double(corner[i][0]) + against(gradient[0])) / 256.0 + 0.5,
                 (double(corner[i][1]) + against(gradient[1])) / 256.0 + 0.5, w + 0.01 * (u01(rng) - 0.5), point);
            positions.insert(positions.end(), point, point + 3);
            outside |= double(point[0]) * point[0] + double(point[1]) * point[1] + double(point[2]) * point[2] > 0.99;
        }
        if (outside) {
            positions.resize(3 * first);
            continue;
        }
        indices.insert(indices.end(), {first, first + 1, first + 2});
    }
    return positions;
}

TEST(FacingFilter, SliversThatSnappingTurnsToTheEyeAreKept) {
    const std::vector<float> directions = icosphere_directions(0);
    std::mt19937 rng(12345);
    size_t turned = 0;
    for (const unsigned resolution : {61u, 256u}) {
        for (size_t v = 0; v < directions.size() / 3; ++v) {
            const float* d = &directions[3 * v];
            std::vector<uint32_t> indices;
            const std::vector<float> positions = turned_slivers(d, resolution, rng, indices);
            const size_t vertex_count = positions.size() / 3;
            const Framing framing = frame_keyframes(positions.data(), 1, vertex_count, indices.data(), indices.size());
            NodeCheck check;
            compare_views(positions.data(), vertex_count, indices, framing.centres.data(), framing.radius, resolution,
                          nullptr, std::vector<float>(d, d + 3), check);
            EXPECT_EQ(check.differing_nodes, 0u) << "view " << v << " at " << resolution << "²";

            // How many of them draw although they face away in exact arithmetic: the scene must
            // hold such triangles for the comparison to tell a margin too small.
            std::vector<float> clip(4 * vertex_count);
            transform_to_clip(clip.data(), positions.data(), vertex_count, framing.centres.data(),
                              node_view_projection(d, framing.radius));
            NodeRasterizer all;
            all.rasterize(clip.data(), vertex_count, indices.data(), indices.size(), resolution);
            std::vector<uint8_t> drew(indices.size() / 3, 0);
            all.visit_fragments([&](uint32_t, uint32_t t, float) { drew[t] = 1; });
            for (size_t t = 3; t < indices.size() / 3; ++t) {
                double q[3][3];
                for (int c = 0; c < 3; ++c)
                    for (int k = 0; k < 3; ++k)
                        q[c][k] = double(positions[3 * indices[3 * t + c] + k]) - framing.centres[k];
                const double u[3] = {q[1][0] - q[0][0], q[1][1] - q[0][1], q[1][2] - q[0][2]};
                const double w[3] = {q[2][0] - q[0][0], q[2][1] - q[0][1], q[2][2] - q[0][2]};
                const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
                double facing = 0;
                for (int k = 0; k < 3; ++k) facing += n[k] * (3.0 * framing.radius * d[k] - q[0][k]);
                turned += drew[t] && facing < 0;
            }
        }
    }
    EXPECT_GT(turned, 100u);
}

TEST(FacingFilter, HandWorkedTriangles) {
    // Seen from +z (eye at (0, 0, 3)), a triangle counter-clockwise in x, y faces the eye.
    const std::vector<float> positions = {
        -0.5f, -0.5f, 0.0f, 0.5f, -0.5f, 0.0f, 0.0f, 0.5f,  0.0f,  // 0: faces +z
        -0.5f, -0.5f, 0.0f, 0.0f, 0.5f,  0.0f, 0.5f, -0.5f, 0.0f,  // 1: the same, wound the other way
        -0.5f, -0.5f, 0.0f, 0.0f, 0.5f,  0.0f, 0.5f, -0.5f, 0.0f,  // 2: as 1, double-sided
        0.0f,  -0.5f, 0.0f, 0.0f, 0.5f,  0.0f, 0.0f, 0.0f,  0.5f,  // 3: in the plane x = 0: edge-on from +z
        1.0f,  0.0f,  0.0f, 1.0f, 0.0f,  0.0f, 1.0f, 0.0f,  0.0f,  // 4: a point on the framing sphere
    };
    std::vector<uint32_t> indices(15);
    for (uint32_t i = 0; i < 15; ++i) indices[i] = i;
    const uint8_t modes[5] = {0, 0, kDrawBothFaces, 0, 0};
    const float centre[3] = {0, 0, 0}, from_z[3] = {0, 0, 1}, from_minus_z[3] = {0, 0, -1};
    FacingFilter filter;
    filter.build(positions.data(), 15, indices.data(), 15, centre, 1.0f, 256, modes);
    ASSERT_TRUE(filter.usable());
    FacingFilter::Candidates c = filter.candidates(from_z);
    EXPECT_EQ(std::vector<uint32_t>(c.ids, c.ids + c.count), (std::vector<uint32_t>{0, 2, 3, 4}));
    c = filter.candidates(from_minus_z);
    EXPECT_EQ(std::vector<uint32_t>(c.ids, c.ids + c.count), (std::vector<uint32_t>{1, 2, 3, 4}));

    // A corner outside the framing sphere voids the guarantee: every triangle is a candidate.
    std::vector<float> outside = positions;
    outside[0] = -2.0f;
    filter.build(outside.data(), 15, indices.data(), 15, centre, 1.0f, 256, modes);
    EXPECT_FALSE(filter.usable());
    c = filter.candidates(from_z);
    EXPECT_EQ(c.ids, nullptr);
    EXPECT_EQ(c.count, 5u);
    // So does a value that is not a number.
    outside[0] = std::nanf("");
    filter.build(outside.data(), 15, indices.data(), 15, centre, 1.0f, 256, modes);
    EXPECT_FALSE(filter.usable());
    // And a mesh all double-sided has nothing to leave out.
    const uint8_t both[5] = {kDrawBothFaces, kDrawBothFaces, kDrawBothFaces, kDrawBothFaces, kDrawBothFaces};
    filter.build(positions.data(), 15, indices.data(), 15, centre, 1.0f, 256, both);
    EXPECT_FALSE(filter.usable());
}
