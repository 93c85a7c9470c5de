// Loop subdivision as an operator: hand-worked positions from Loop's rules (tetrahedron,
// octahedron, a lone triangle's boundary rules, a planar grid), topology kept (closed stays
// closed, winding, Euler characteristic), UV seams watertight in every keyframe, and the operator
// against an independent direct implementation, against itself built afresh, and composed.
#include "animorder/animated_mesh.h"
#include "animorder/camera.h"
#include "animorder/invalid_input.h"
#include "animorder/loop_subdivision.h"
#include "animorder/procedural_character.h"
#include "animorder/procedural_shapes.h"
#include "animorder/rasterizer.h"
#include "animorder/subdivide_animated_mesh.h"
#include "animorder/viewpoints.h"

#include <gtest/gtest.h>

#include <tbb/task_arena.h>

#include <array>
#include <cmath>
#include <map>
#include <set>
#include <vector>

using namespace animorder;

namespace {

struct Mesh {
    std::vector<float> positions;
    std::vector<uint32_t> indices;
    size_t vertex_count() const { return positions.size() / 3; }
};

Mesh tetrahedron() {
    // Regular, centred at the origin; faces counter-clockwise seen from outside.
    return {{1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1}, {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2}};
}

Mesh octahedron() {
    Mesh m;
    m.positions = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};  // ±x, ±y, ±z
    for (int sx = 0; sx < 2; ++sx)
        for (int sy = 0; sy < 2; ++sy)
            for (int sz = 0; sz < 2; ++sz) {
                const uint32_t x = uint32_t(sx), y = uint32_t(2 + sy), z = uint32_t(4 + sz);
                if ((sx + sy + sz) % 2 == 0)
                    m.indices.insert(m.indices.end(), {x, y, z});
                else
                    m.indices.insert(m.indices.end(), {x, z, y});
            }
    return m;
}

// Every triangle with its own three vertices: a "seam" along every edge.
Mesh split_every_vertex(const Mesh& m) {
    Mesh out;
    for (uint32_t v : m.indices) {
        out.indices.push_back(uint32_t(out.positions.size() / 3));
        out.positions.insert(out.positions.end(), m.positions.begin() + 3 * v, m.positions.begin() + 3 * v + 3);
    }
    return out;
}

std::vector<float> subdivided(const SubdivisionOperator& op, const std::vector<float>& positions) {
    std::vector<float> out(op.output_vertex_count * 3);
    apply_subdivision(out.data(), op, positions.data(), 12);
    return out;
}

SubdivisionOperator build(const Mesh& m, unsigned levels, bool weld = true) {
    return build_loop_subdivision(m.indices.data(), m.indices.size(), weld ? m.positions.data() : nullptr,
                                  m.vertex_count(), 12, levels);
}

std::array<float, 3> at(const std::vector<float>& p, uint32_t v) { return {p[3 * v], p[3 * v + 1], p[3 * v + 2]}; }

// Welds identical positions; returns the welded triangle list.
std::vector<uint32_t> welded(const std::vector<float>& positions, const std::vector<uint32_t>& indices) {
    std::map<std::array<float, 3>, uint32_t> ids;
    std::vector<uint32_t> out;
    for (uint32_t v : indices) out.push_back(ids.emplace(at(positions, v), uint32_t(ids.size())).first->second);
    return out;
}

struct Topology {
    bool closed_and_consistent = true;  // each directed edge once, its reverse once
    long euler = 0;                     // V − E + F
};

Topology topology(const std::vector<uint32_t>& ib) {
    std::map<std::pair<uint32_t, uint32_t>, int> directed;
    std::set<uint32_t> vertices;
    for (size_t t = 0; t < ib.size(); t += 3)
        for (int i = 0; i < 3; ++i) {
            ++directed[{ib[t + size_t(i)], ib[t + size_t(i + 1) % 3]}];
            vertices.insert(ib[t + size_t(i)]);
        }
    Topology r;
    std::set<std::pair<uint32_t, uint32_t>> undirected;
    for (const auto& [edge, count] : directed) {
        const auto reverse = directed.find({edge.second, edge.first});
        if (count != 1 || reverse == directed.end() || reverse->second != 1) r.closed_and_consistent = false;
        undirected.insert({std::min(edge.first, edge.second), std::max(edge.first, edge.second)});
    }
    r.euler = long(vertices.size()) - long(undirected.size()) + long(ib.size() / 3);
    return r;
}

// An independent, direct Loop subdivision of a closed manifold mesh without seams (positions in
// double, maps instead of the operator): the same rules and the same child layout.
void direct_loop(std::vector<double>& p, std::vector<uint32_t>& ib) {
    const double pi = 3.14159265358979323846;
    std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> opposite;
    std::map<uint32_t, std::set<uint32_t>> ring;
    for (size_t t = 0; t < ib.size(); t += 3)
        for (int i = 0; i < 3; ++i) {
            const uint32_t a = ib[t + size_t(i)], b = ib[t + size_t(i + 1) % 3], c = ib[t + size_t(i + 2) % 3];
            opposite[{std::min(a, b), std::max(a, b)}].push_back(c);
            ring[a].insert(b);
            ring[b].insert(a);
        }
    const size_t n = p.size() / 3;
    std::vector<double> q(p);
    for (uint32_t v = 0; v < n; ++v) {
        const double k = double(ring[v].size());
        const double beta = (5.0 / 8 - std::pow(3.0 / 8 + std::cos(2 * pi / k) / 4, 2)) / k;
        for (int c = 0; c < 3; ++c) {
            double sum = 0;
            for (uint32_t u : ring[v]) sum += p[3 * u + size_t(c)];
            q[3 * v + size_t(c)] = (1 - k * beta) * p[3 * v + size_t(c)] + beta * sum;
        }
    }
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> made;
    auto mid = [&](uint32_t a, uint32_t b) {
        const auto key = std::make_pair(std::min(a, b), std::max(a, b));
        const auto found = made.find(key);
        if (found != made.end()) return found->second;
        const std::vector<uint32_t>& o = opposite.at(key);
        EXPECT_EQ(o.size(), 2u);
        for (int c = 0; c < 3; ++c)
            q.push_back(3.0 / 8 * (p[3 * a + size_t(c)] + p[3 * b + size_t(c)]) +
                        1.0 / 8 * (p[3 * o[0] + size_t(c)] + p[3 * o[1] + size_t(c)]));
        return made[key] = uint32_t(q.size() / 3 - 1);
    };
    std::vector<uint32_t> out;
    for (size_t t = 0; t < ib.size(); t += 3) {
        const uint32_t a = ib[t], b = ib[t + 1], c = ib[t + 2];
        const uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
        out.insert(out.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
    }
    p = std::move(q);
    ib = std::move(out);
}

// A smooth non-rigid deformation (a twist about y and a bulge), the same for every copy of a point.
std::vector<float> deformed(const std::vector<float>& p, float amount) {
    std::vector<float> out(p.size());
    for (size_t v = 0; v < p.size() / 3; ++v) {
        const float x = p[3 * v], y = p[3 * v + 1], z = p[3 * v + 2];
        const float angle = amount * y, s = 1 + 0.3f * amount * x * x;
        out[3 * v] = s * (std::cos(angle) * x - std::sin(angle) * z);
        out[3 * v + 1] = y + 0.2f * amount * z;
        out[3 * v + 2] = std::sin(angle) * x + std::cos(angle) * z;
    }
    return out;
}

void expect_near3(const std::array<float, 3>& a, const std::array<double, 3>& b, double tolerance = 1e-6) {
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[size_t(i)], b[size_t(i)], tolerance) << "component " << i;
}

}  // namespace

TEST(LoopSubdivision, TetrahedronByHand) {
    const Mesh m = tetrahedron();
    const SubdivisionOperator op = build(m, 1);
    EXPECT_EQ(op.output_vertex_count, 4u + 6u);  // V + E
    EXPECT_EQ(op.indices.size(), 4u * 12u);      // 4F triangles
    const std::vector<float> p = subdivided(op, m.positions);
    // Valence 3: β = 3/16 (Loop's β equals Warren's here). Even vertex (1,1,1):
    // 7/16·(1,1,1) + 3/16·(sum of the other three = −(1,1,1)) = (1/4, 1/4, 1/4).
    expect_near3(at(p, 0), {0.25, 0.25, 0.25});
    // Odd vertex of edge (0,1), the first new vertex: 3/8·(v0+v1) + 1/8·(v2+v3) = 1/4·(v0+v1) = (1/2, 0, 0).
    expect_near3(at(p, 4), {0.5, 0, 0});
    // Children of triangle 0 (0,1,2): (0, e01, e20), (e01, 1, e12), (e20, e12, 2), (e01, e12, e20).
    const uint32_t e01 = 4, e12 = 5, e20 = 6;
    EXPECT_EQ(std::vector<uint32_t>(op.indices.begin(), op.indices.begin() + 12),
              (std::vector<uint32_t>{0, e01, e20, e01, 1, e12, e20, e12, 2, e01, e12, e20}));
}

TEST(LoopSubdivision, OctahedronUsesLoopsBetaNotWarrens) {
    const Mesh m = octahedron();
    const SubdivisionOperator op = build(m, 1);
    EXPECT_EQ(op.output_vertex_count, 6u + 12u);
    EXPECT_EQ(op.indices.size(), 4u * 24u);
    const std::vector<float> p = subdivided(op, m.positions);
    // Valence 4: Loop's β = (5/8 − (3/8 + cos(π/2)/4)²)/4 = 31/256; the neighbours of +x sum to 0,
    // so +x → (1 − 4·31/256)·(1,0,0) = (33/64, 0, 0). (Warren's 3/32 would give 5/8.)
    expect_near3(at(p, 0), {33.0 / 64, 0, 0});
    // First triangle (+x, +y, +z): edge (+x,+y) has opposite vertices +z and −z:
    // 3/8·(1,1,0) + 1/8·((0,0,1) + (0,0,−1)) = (3/8, 3/8, 0).
    expect_near3(at(p, op.indices[1]), {3.0 / 8, 3.0 / 8, 0});
    // Row of that odd vertex: exactly the four weights.
    const size_t r = op.indices[1];
    ASSERT_EQ(op.row_starts[r + 1] - op.row_starts[r], 4u);
    std::map<uint32_t, double> row;
    for (size_t k = op.row_starts[r]; k < op.row_starts[r + 1]; ++k) row[op.columns[k]] = op.weights[k];
    EXPECT_EQ(row, (std::map<uint32_t, double>{{0, 0.375}, {2, 0.375}, {4, 0.125}, {5, 0.125}}));
}

TEST(LoopSubdivision, SingleTriangleUsesOnlyBoundaryRules) {
    const Mesh m{{0, 0, 0, 4, 0, 0, 0, 8, 0}, {0, 1, 2}};
    const std::vector<float> p = subdivided(build(m, 1), m.positions);
    ASSERT_EQ(p.size(), 6u * 3u);
    // Corners: 3/4 v + 1/8 of each boundary neighbour.
    expect_near3(at(p, 0), {0.5, 1, 0});
    expect_near3(at(p, 1), {3.0, 1, 0});
    expect_near3(at(p, 2), {0.5, 6, 0});
    // Edge points: midpoints.
    expect_near3(at(p, 3), {2, 0, 0});
    expect_near3(at(p, 4), {2, 4, 0});
    expect_near3(at(p, 5), {0, 4, 0});
}

TEST(LoopSubdivision, FlatOpenGridStaysPlanarAndRegularInteriorPointsStay) {
    // 6×6 quads on the plane z = 0.3x − 0.2y + 1, each split by the same diagonal (valence 6 inside).
    Mesh m;
    const int n = 6;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i)
            m.positions.insert(m.positions.end(), {float(i), float(j), 0.3f * i - 0.2f * j + 1});
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
            m.indices.insert(m.indices.end(), {a, b, d, a, d, c});
        }
    for (unsigned levels : {1u, 2u}) {
        const SubdivisionOperator op = build(m, levels);
        const std::vector<float> p = subdivided(op, m.positions);
        for (size_t v = 0; v < op.output_vertex_count; ++v)
            EXPECT_NEAR(p[3 * v + 2], 0.3 * p[3 * v] - 0.2 * p[3 * v + 1] + 1, 1e-5) << "vertex " << v;
        // Interior vertex (3,3): its six neighbours are symmetric about it, so it does not move.
        const uint32_t centre = 3 * (n + 1) + 3;
        expect_near3(at(p, centre), {3, 3, 0.3 * 3 - 0.2 * 3 + 1}, 1e-5);
        // Every row is an affine combination.
        for (size_t r = 0; r < op.output_vertex_count; ++r) {
            double sum = 0;
            for (size_t k = op.row_starts[r]; k < op.row_starts[r + 1]; ++k) sum += op.weights[k];
            EXPECT_NEAR(sum, 1.0, 1e-12);
        }
    }
}

TEST(LoopSubdivision, ClosedStaysClosedWithWindingAndEulerCharacteristic) {
    const AnimatedMesh sphere = make_uv_sphere(400), knot = make_torus_knot(600);
    for (const AnimatedMesh* input : {&sphere, &knot}) {
        const Mesh m{std::vector<float>(input->keyframe(0), input->keyframe(0) + 3 * input->vertex_count),
                     input->indices};
        const Topology before = topology(welded(m.positions, m.indices));
        ASSERT_TRUE(before.closed_and_consistent);
        EXPECT_EQ(before.euler, input == &sphere ? 2 : 0);
        for (unsigned levels : {1u, 2u}) {
            const SubdivisionOperator op = build(m, levels);
            EXPECT_EQ(op.indices.size(), m.indices.size() << (2 * levels));
            const Topology after = topology(welded(subdivided(op, m.positions), op.indices));
            EXPECT_TRUE(after.closed_and_consistent) << "levels " << levels;
            EXPECT_EQ(after.euler, before.euler) << "levels " << levels;
        }
    }
}

TEST(LoopSubdivision, SeamCopiesCoincideInEveryKeyframeAndMatchTheWeldedSurface) {
    const Mesh whole = octahedron(), split = split_every_vertex(whole);
    const SubdivisionOperator op_whole = build(whole, 2), op_split = build(split, 2);
    ASSERT_EQ(op_split.indices.size(), op_whole.indices.size());
    // Split stays split: each copy of an edge gets its own vertex. Level 1: 24 corners + 2·12
    // edges = 48; level 2: those 48 + 9 edges inside each of the 8 separate faces = 120.
    EXPECT_EQ(op_split.output_vertex_count, 48u + 72u);
    EXPECT_EQ(op_whole.output_vertex_count, 66u);
    for (float amount : {0.0f, 0.7f, -1.3f}) {  // keyframes: rest, then deformations
        const std::vector<float> p_whole = subdivided(op_whole, deformed(whole.positions, amount));
        std::vector<float> split_frame(split.positions.size());
        split_frame = deformed(split.positions, amount);
        const std::vector<float> p_split = subdivided(op_split, split_frame);
        std::map<std::array<float, 3>, std::set<uint32_t>> copies;  // identical positions → distinct whole vertices
        for (size_t i = 0; i < op_whole.indices.size(); ++i) {
            const auto a = at(p_split, op_split.indices[i]), b = at(p_whole, op_whole.indices[i]);
            expect_near3(a, {b[0], b[1], b[2]}, 1e-6);
            copies[a].insert(op_whole.indices[i]);
        }
        // Copies are bit-identical: exactly as many distinct split positions as welded vertices.
        EXPECT_EQ(copies.size(), op_whole.output_vertex_count) << "amount " << amount;
        for (const auto& [position, vertices] : copies) EXPECT_EQ(vertices.size(), 1u);
    }
    // Without welding the split mesh is 8 separate triangles: boundary rules, a different surface.
    const std::vector<float> unwelded = subdivided(build(split, 1, false), split.positions);
    EXPECT_NEAR(unwelded[0], 0.75, 1e-6);  // corner +x of its own triangle: 3/4·1 + 1/8·0 + 1/8·0
}

TEST(LoopSubdivision, OperatorMatchesADirectImplementation) {
    const AnimatedMesh knot = make_torus_knot(500);
    const Mesh m{deformed(std::vector<float>(knot.keyframe(0), knot.keyframe(0) + 3 * knot.vertex_count), 0.4f),
                 knot.indices};
    std::vector<double> p(m.positions.begin(), m.positions.end());
    std::vector<uint32_t> ib = m.indices;
    for (unsigned levels = 1; levels <= 2; ++levels) {
        direct_loop(p, ib);
        const SubdivisionOperator op = build(m, levels);
        ASSERT_EQ(op.indices.size(), ib.size());
        const std::vector<float> q = subdivided(op, m.positions);
        double worst = 0;
        for (size_t i = 0; i < ib.size(); ++i)
            for (int c = 0; c < 3; ++c)
                worst = std::max(worst, std::fabs(q[3 * op.indices[i] + size_t(c)] - p[3 * ib[i] + size_t(c)]));
        EXPECT_LT(worst, 1e-5) << "levels " << levels;
    }
}

TEST(LoopSubdivision, ReusedOperatorEqualsAFreshOneAndLevelsCompose) {
    const AnimatedMesh sphere = make_uv_sphere(300);
    const Mesh rest{std::vector<float>(sphere.keyframe(0), sphere.keyframe(0) + 3 * sphere.vertex_count),
                    sphere.indices};
    const SubdivisionOperator op = build(rest, 2);
    for (float amount : {0.5f, 1.5f}) {
        // Keyframe f through the operator built at rest, and through one built at keyframe f.
        const Mesh frame{deformed(rest.positions, amount), rest.indices};
        const SubdivisionOperator fresh = build(frame, 2);
        EXPECT_EQ(fresh.indices, op.indices);
        EXPECT_EQ(subdivided(op, frame.positions), subdivided(fresh, frame.positions));
        // Two levels at once = one level applied to the result of one level.
        const SubdivisionOperator first = build(frame, 1);
        const Mesh once{subdivided(first, frame.positions), first.indices};
        const SubdivisionOperator second = build(once, 1);
        const std::vector<float> twice = subdivided(second, once.positions), both = subdivided(op, frame.positions);
        ASSERT_EQ(second.indices, op.indices);
        ASSERT_EQ(twice.size(), both.size());
        for (size_t i = 0; i < both.size(); ++i) EXPECT_NEAR(twice[i], both[i], 1e-5) << i;
    }
}

TEST(LoopSubdivision, ZeroLevelsIsTheIdentity) {
    const Mesh m = tetrahedron();
    const SubdivisionOperator op = build(m, 0);
    EXPECT_EQ(op.indices, m.indices);
    EXPECT_EQ(subdivided(op, m.positions), m.positions);
}

TEST(LoopSubdivision, BadInputThrows) {
    const Mesh m = tetrahedron();
    EXPECT_THROW(build(m, 5), InvalidInput);
    const std::vector<uint32_t> bad = {0, 1, 7};
    EXPECT_THROW(build_loop_subdivision(bad.data(), 3, m.positions.data(), 4, 12, 1), InvalidInput);
    EXPECT_THROW(build_loop_subdivision(m.indices.data(), 4, m.positions.data(), 4, 12, 1), InvalidInput);
    std::vector<float> nan_positions = m.positions;
    nan_positions[4] = NAN;
    EXPECT_THROW(build_loop_subdivision(m.indices.data(), m.indices.size(), nan_positions.data(), 4, 12, 1),
                 InvalidInput);
    // 4 levels multiply by 256: 2^31 / 256 = 8,388,608 indices is the most.
    const std::vector<uint32_t> many(8388609, 0);  // 2^31 / 256 + 1, a multiple of 3
    try {
        build_loop_subdivision(many.data(), many.size(), nullptr, 1, 12, 4);
        ADD_FAILURE() << "no exception";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("2^31"), std::string::npos) << e.what();
    }
}

TEST(SubdivideAnimatedMesh, ProceduralCharacterCountsClipsAndFraming) {
    const AnimatedMesh character = make_procedural_character();
    ASSERT_EQ(character.triangle_count(), 11760u);  // with the blended hair cards and cape
    const Framing base = frame_animated_mesh(character);
    const size_t expected[] = {11760, 47040, 188160};
    for (unsigned levels = 1; levels <= 2; ++levels) {
        const AnimatedMesh s = subdivide_animated_mesh(character, levels);
        validate_animated_mesh(s);
        EXPECT_EQ(s.triangle_count(), expected[levels]);
        EXPECT_EQ(s.keyframe_count(), character.keyframe_count());
        EXPECT_EQ(s.joint_count, character.joint_count);
        ASSERT_EQ(s.clips.size(), character.clips.size());
        for (size_t c = 0; c < s.clips.size(); ++c) {
            EXPECT_EQ(s.clips[c].name, character.clips[c].name);
            EXPECT_EQ(s.clips[c].first_keyframe, character.clips[c].first_keyframe);
            EXPECT_EQ(s.clips[c].keyframe_count, character.clips[c].keyframe_count);
        }
        ASSERT_EQ(s.primitives.size(), character.primitives.size());
        for (size_t i = 0; i < s.primitives.size(); ++i) {
            EXPECT_EQ(s.primitives[i].first_index, character.primitives[i].first_index << (2 * levels));
            EXPECT_EQ(s.primitives[i].index_count, character.primitives[i].index_count << (2 * levels));
        }
        // The overdraw engine frames it: finite centres, radii a little inside the original's
        // (Loop's limit surface lies inside the control mesh's hull).
        const Framing f = frame_animated_mesh(s);
        ASSERT_EQ(f.radii.size(), base.radii.size());
        for (size_t k = 0; k < f.radii.size(); ++k) {
            ASSERT_TRUE(std::isfinite(f.radii[k]) && std::isfinite(f.centres[3 * k])) << k;
            EXPECT_LE(f.radii[k], base.radii[k] * 1.0001f);
            EXPECT_GT(f.radii[k], base.radii[k] * 0.8f);
        }
        // And rasterises it: about the same silhouette as the original from the front.
        auto coverage = [](const AnimatedMesh& mesh, const Framing& framing) {
            const float view[3] = {0.3f, 0.2f, 1.0f};
            const float norm = std::sqrt(0.09f + 0.04f + 1.0f);
            const float direction[3] = {view[0] / norm, view[1] / norm, view[2] / norm};
            std::vector<float> clip(mesh.vertex_count * 4);
            transform_to_clip(clip.data(), mesh.keyframe(0), mesh.vertex_count, framing.centres.data(),
                              node_view_projection(direction, framing.radius));
            NodeRasterizer r;
            r.rasterize(clip.data(), mesh.vertex_count, mesh.indices.data(), mesh.indices.size(), 128);
            return r.visible_pixels();
        };
        const double before = double(coverage(character, base)), after = double(coverage(s, f));
        EXPECT_GT(after, 0.85 * before);
        EXPECT_LT(after, 1.15 * before);
    }
}

TEST(SubdivideAnimatedMesh, ProceduralCharacterSeamsStayClosedInEveryKeyframe) {
    // Welded by position, the subdivided surface has exactly twice the boundary edges (each
    // boundary edge splits in two) and no new ones: a seam opening in any keyframe would add some.
    const AnimatedMesh character = make_procedural_character();
    const AnimatedMesh s = subdivide_animated_mesh(character, 1);
    auto boundary_edges = [](const std::vector<uint32_t>& ib) {
        std::map<std::pair<uint32_t, uint32_t>, int> count;
        for (size_t t = 0; t < ib.size(); t += 3)
            for (int i = 0; i < 3; ++i) {
                const uint32_t a = ib[t + size_t(i)], b = ib[t + size_t(i + 1) % 3];
                if (a != b) ++count[{std::min(a, b), std::max(a, b)}];
            }
        size_t n = 0;
        for (const auto& [edge, c] : count) n += c == 1;
        return n;
    };
    const std::vector<float> rest(character.keyframe(0), character.keyframe(0) + 3 * character.vertex_count);
    const size_t before = boundary_edges(welded(rest, character.indices));
    for (size_t k : {size_t(0), s.keyframe_count() / 2, s.keyframe_count() - 1}) {
        const std::vector<float> frame(s.keyframe(k), s.keyframe(k) + 3 * s.vertex_count);
        EXPECT_EQ(boundary_edges(welded(frame, s.indices)), 2 * before) << "keyframe " << k;
    }
}

TEST(SubdivideAnimatedMesh, SameBytesWhateverTheThreadCountAndZeroLevelsCopies) {
    AnimatedMesh sphere = make_uv_sphere(200);
    // Three keyframes in two clips.
    const std::vector<float> rest(sphere.keyframe(0), sphere.keyframe(0) + 3 * sphere.vertex_count);
    for (float amount : {0.6f, 1.2f}) {
        const std::vector<float> d = deformed(rest, amount);
        sphere.keyframe_positions.insert(sphere.keyframe_positions.end(), d.begin(), d.end());
    }
    sphere.clips = {{"a", 1.0 / 30, 30, 0, 2}, {"b", 0, 30, 2, 1}};
    const AnimatedMesh many = subdivide_animated_mesh(sphere, 2);
    AnimatedMesh one;
    tbb::task_arena(1).execute([&] { one = subdivide_animated_mesh(sphere, 2); });
    EXPECT_EQ(one.keyframe_positions, many.keyframe_positions);
    EXPECT_EQ(one.indices, many.indices);
    // Each keyframe is S · that keyframe.
    const SubdivisionOperator op = build_loop_subdivision(sphere.indices.data(), sphere.indices.size(),
                                                          sphere.keyframe(0), sphere.vertex_count, 12, 2);
    for (size_t k = 0; k < 3; ++k) {
        const std::vector<float> frame(sphere.keyframe(k), sphere.keyframe(k) + 3 * sphere.vertex_count);
        const std::vector<float> expected = subdivided(op, frame);
        EXPECT_EQ(std::vector<float>(many.keyframe(k), many.keyframe(k) + 3 * many.vertex_count), expected);
    }
    const AnimatedMesh copy = subdivide_animated_mesh(sphere, 0);
    EXPECT_EQ(copy.keyframe_positions, sphere.keyframe_positions);
    EXPECT_EQ(copy.indices, sphere.indices);
    EXPECT_THROW(subdivide_animated_mesh(sphere, 5), InvalidInput);
}
