// Loop subdivision as a sparse linear operator, built once per topology.
//
// This follows: Charles Loop. "Smooth Subdivision Surfaces Based on Triangles". M.S. thesis,
// University of Utah, 1987, §3 (the subdivision rules), with the boundary / crease rules of
// Hoppe et al., "Piecewise Smooth Surface Reconstruction", SIGGRAPH 1994, §3.2, for edges that
// do not have exactly two faces.
//
// Each level splits every triangle (a, b, c) into four, keeping counter-clockwise winding:
// (a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca), where ab is the new vertex of edge (a, b).
// Rules (weights of old vertices; they sum to 1):
//   odd (edge) vertex, interior edge (two faces, opposite vertices c and d):
//       3/8 a + 3/8 b + 1/8 c + 1/8 d
//   odd vertex, boundary or non-manifold edge (one face, or more than two): 1/2 a + 1/2 b
//   even (old) vertex v of valence n, no crease edge: (1 − nβ) v + β Σ neighbours, with Loop's
//       β(n) = (1/n) (5/8 − (3/8 + 1/4 cos(2π/n))²)   (not Warren's 3/(8n) simplification)
//   even vertex on exactly two crease edges (boundary neighbours b1, b2): 3/4 v + 1/8 b1 + 1/8 b2
//   even vertex on one or more than two crease edges (a corner): v stays where it is.
//
// Topology is built on *welded* vertices: vertices at bit-identical keyframe-0 positions (a UV
// seam splits one surface vertex into several) are one surface vertex, so seams are smoothed like
// the rest of the surface. The output keeps the split: each distinct (unwelded) edge gets its own
// new vertex, but every copy of a welded vertex or edge gets the same row, written on the
// smallest-index copy of each welded vertex, so copies coincide in every keyframe. Welding is
// carried from level to level combinatorially (an edge vertex of welded edge {A, B} is welded with
// every other edge vertex of {A, B}), so it never depends on later float positions.
//
// Levels compose: S = S_levels · … · S_1, accumulated in double.
#include "animorder/loop_subdivision.h"

#include "animorder/invalid_input.h"
#include "animorder/triangle_order.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <unordered_map>
#include <utility>

namespace animorder {
namespace {

using Row = std::vector<std::pair<uint32_t, double>>;  // (column, weight)

uint64_t pair_key(uint32_t a, uint32_t b) {
    if (a > b) std::swap(a, b);
    return (uint64_t(a) << 32) | b;
}

// Loop's β for an interior vertex of valence n (1987, §3.2).
double loop_beta(size_t n) {
    const double pi = 3.14159265358979323846;
    const double c = 3.0 / 8.0 + 0.25 * std::cos(2 * pi / double(n));
    return (5.0 / 8.0 - c * c) / double(n);
}

// One level over the welded ("class") topology: classes[v] is v's surface vertex, rep[c] the
// smallest vertex of class c.
struct Level {
    std::vector<uint32_t> indices;
    std::vector<uint32_t> classes;
    std::vector<uint32_t> rep;
    size_t vertex_count = 0;
};

// Rows of one level (new vertices × old vertices, columns are old representatives) and the next
// level's mesh and welding.
std::vector<Row> subdivide_level(const Level& in, Level& out) {
    const std::vector<uint32_t>& ib = in.indices;
    const std::vector<uint32_t>& cls = in.classes;
    const size_t class_count = in.rep.size();
    const size_t triangles = ib.size() / 3;

    // Class edges of the non-degenerate class triangles, with their opposite class vertices.
    struct Incidence {
        uint64_t key;
        uint32_t opposite;
    };
    std::vector<Incidence> incidences;
    incidences.reserve(ib.size());
    for (size_t t = 0; t < triangles; ++t) {
        const uint32_t c[3] = {cls[ib[3 * t]], cls[ib[3 * t + 1]], cls[ib[3 * t + 2]]};
        if (c[0] == c[1] || c[1] == c[2] || c[2] == c[0]) continue;
        for (int i = 0; i < 3; ++i) incidences.push_back({pair_key(c[i], c[(i + 1) % 3]), c[(i + 2) % 3]});
    }
    std::sort(incidences.begin(), incidences.end(), [](const Incidence& x, const Incidence& y) {
        return x.key != y.key ? x.key < y.key : x.opposite < y.opposite;
    });

    // Per class edge: its odd row (over classes); per class: neighbours and crease neighbours.
    std::unordered_map<uint64_t, Row> edge_rows;
    edge_rows.reserve(incidences.size());
    std::vector<std::vector<uint32_t>> neighbours(class_count), creases(class_count);
    for (size_t i = 0; i < incidences.size();) {
        size_t j = i;
        while (j < incidences.size() && incidences[j].key == incidences[i].key) ++j;
        const uint32_t a = uint32_t(incidences[i].key >> 32), b = uint32_t(incidences[i].key & 0xffffffffu);
        neighbours[a].push_back(b);
        neighbours[b].push_back(a);
        Row row;
        if (j - i == 2) {
            row = {
                {a, 3.0 / 8}, {b, 3.0 / 8}, {incidences[i].opposite, 1.0 / 8}, {incidences[i + 1].opposite, 1.0 / 8}};
        } else {  // boundary (one face) or non-manifold (more than two): a crease
            row = {{a, 0.5}, {b, 0.5}};
            creases[a].push_back(b);
            creases[b].push_back(a);
        }
        edge_rows.emplace(incidences[i].key, std::move(row));
        i = j;
    }
    auto even_row = [&](uint32_t v) -> Row {
        const size_t n = neighbours[v].size();
        if (n == 0) return {{v, 1.0}};
        if (creases[v].empty()) {
            const double beta = loop_beta(n);
            Row row{{v, 1.0 - double(n) * beta}};
            for (uint32_t u : neighbours[v]) row.push_back({u, beta});
            return row;
        }
        if (creases[v].size() == 2) return {{v, 0.75}, {creases[v][0], 0.125}, {creases[v][1], 0.125}};
        return {{v, 1.0}};  // a corner: one crease edge, or where more than two meet
    };

    // New vertices: even ones keep their numbers, then one per distinct unwelded edge.
    const size_t old_count = in.vertex_count;
    std::vector<Row> rows;
    rows.reserve(old_count + ib.size());
    out.classes.assign(cls.begin(), cls.end());
    for (uint32_t v = 0; v < old_count; ++v) rows.push_back(even_row(cls[v]));
    std::unordered_map<uint64_t, uint32_t> edge_vertex, class_edge_class;
    edge_vertex.reserve(ib.size());
    class_edge_class.reserve(ib.size());
    auto edge_vertex_of = [&](uint32_t a, uint32_t b) -> uint32_t {
        if (a == b) return a;  // a zero-length edge of a degenerate triangle: its midpoint is a
        const auto [it, added] = edge_vertex.emplace(pair_key(a, b), uint32_t(rows.size()));
        if (!added) return it->second;
        const uint32_t ca = cls[a], cb = cls[b];
        if (ca == cb) {
            rows.push_back(even_row(ca));
            out.classes.push_back(ca);
        } else {
            const auto found = edge_rows.find(pair_key(ca, cb));
            rows.push_back(found != edge_rows.end() ? found->second : Row{{ca, 0.5}, {cb, 0.5}});
            const auto [c, fresh] =
                class_edge_class.emplace(pair_key(ca, cb), uint32_t(class_count + class_edge_class.size()));
            (void)fresh;
            out.classes.push_back(c->second);
        }
        return it->second;
    };
    out.indices.resize(ib.size() * 4);
    for (size_t t = 0; t < triangles; ++t) {
        const uint32_t a = ib[3 * t], b = ib[3 * t + 1], c = ib[3 * t + 2];
        const uint32_t ab = edge_vertex_of(a, b), bc = edge_vertex_of(b, c), ca = edge_vertex_of(c, a);
        const uint32_t children[12] = {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca};
        std::memcpy(out.indices.data() + 12 * t, children, sizeof children);
    }
    out.vertex_count = rows.size();
    out.rep.assign(class_count + class_edge_class.size(), UINT32_MAX);
    for (uint32_t v = 0; v < out.vertex_count; ++v) out.rep[out.classes[v]] = std::min(out.rep[out.classes[v]], v);

    // Rows over classes → rows over old vertices (each class's representative).
    for (Row& row : rows)
        for (auto& [column, weight] : row) column = in.rep[column];
    return rows;
}

}  // namespace

SubdivisionOperator build_loop_subdivision(const uint32_t* indices, size_t index_count, const float* weld_positions,
                                           size_t vertex_count, size_t position_stride, unsigned levels) {
    if (levels > kMaxSubdivisionLevels)
        throw InvalidInput("subdivision levels is " + std::to_string(levels) + "; at most " +
                           std::to_string(kMaxSubdivisionLevels) + " (each level multiplies the triangles by 4)");
    validate_indices(indices, index_count, vertex_count);
    if (vertex_count > UINT32_MAX) throw InvalidInput("vertex count does not fit 32-bit indices");
    const double growth = std::pow(4.0, double(levels));
    if (double(index_count) * growth > 2147483648.0)
        throw InvalidInput(std::to_string(levels) + " levels of subdivision of " + std::to_string(index_count / 3) +
                           " triangles give more than 2^31 indices");
    if (weld_positions && position_stride < 3 * sizeof(float))
        throw InvalidInput("position stride must be at least 12 bytes");

    // Level 0 welding: vertices at identical positions form a class, numbered by smallest member.
    Level level;
    level.indices.assign(indices, indices + index_count);
    level.vertex_count = vertex_count;
    level.classes.resize(vertex_count);
    std::vector<uint32_t> rep_of(vertex_count);
    for (uint32_t v = 0; v < vertex_count; ++v) rep_of[v] = v;
    if (weld_positions) {
        auto at = [&](uint32_t v) {
            return reinterpret_cast<const float*>(reinterpret_cast<const unsigned char*>(weld_positions) +
                                                  size_t(v) * position_stride);
        };
        for (uint32_t v = 0; v < vertex_count; ++v)
            for (int i = 0; i < 3; ++i)
                if (!std::isfinite(at(v)[i]))
                    throw InvalidInput("weld position of vertex " + std::to_string(v) + " is not finite");
        std::vector<uint32_t> sorted(rep_of);
        auto less = [&](uint32_t a, uint32_t b) {
            const float *p = at(a), *q = at(b);
            for (int i = 0; i < 3; ++i)
                if (p[i] != q[i]) return p[i] < q[i];
            return a < b;
        };
        std::sort(sorted.begin(), sorted.end(), less);
        for (size_t i = 1; i < sorted.size(); ++i) {
            const float *p = at(sorted[i - 1]), *q = at(sorted[i]);
            if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) rep_of[sorted[i]] = rep_of[sorted[i - 1]];
        }
    }
    std::vector<uint32_t> class_of_rep(vertex_count, UINT32_MAX);
    for (uint32_t v = 0; v < vertex_count; ++v) {
        if (class_of_rep[rep_of[v]] == UINT32_MAX) {
            class_of_rep[rep_of[v]] = uint32_t(level.rep.size());
            level.rep.push_back(rep_of[v]);
        }
        level.classes[v] = class_of_rep[rep_of[v]];
    }

    // S starts as the identity and is composed with each level's rows.
    SubdivisionOperator op;
    op.levels = levels;
    op.input_vertex_count = vertex_count;
    std::vector<Row> current(vertex_count);
    for (uint32_t v = 0; v < vertex_count; ++v) current[v] = {{v, 1.0}};
    std::vector<double> accumulator(vertex_count, 0.0);
    std::vector<uint32_t> touched;
    for (unsigned l = 0; l < levels; ++l) {
        Level next;
        const std::vector<Row> rows = subdivide_level(level, next);
        if (next.vertex_count > UINT32_MAX)
            throw InvalidInput("the subdivided vertex count does not fit 32-bit indices");
        std::vector<Row> composed(rows.size());
        for (size_t r = 0; r < rows.size(); ++r) {
            touched.clear();
            for (const auto& [column, weight] : rows[r])
                for (const auto& [input, w] : current[column]) {
                    if (accumulator[input] == 0.0) touched.push_back(input);
                    accumulator[input] += weight * w;
                }
            std::sort(touched.begin(), touched.end());
            touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
            for (uint32_t input : touched) {
                if (accumulator[input] != 0.0) composed[r].push_back({input, accumulator[input]});
                accumulator[input] = 0.0;
            }
        }
        current = std::move(composed);
        level = std::move(next);
    }

    op.output_vertex_count = current.size();
    op.indices = std::move(level.indices);
    op.row_starts.reserve(current.size() + 1);
    op.row_starts.push_back(0);
    for (const Row& row : current) {
        for (const auto& [column, weight] : row) {
            op.columns.push_back(column);
            op.weights.push_back(weight);
        }
        op.row_starts.push_back(op.columns.size());
    }
    return op;
}

void apply_subdivision(float* destination, const SubdivisionOperator& op, const float* positions,
                       size_t position_stride) {
    if (position_stride < 3 * sizeof(float)) throw InvalidInput("position stride must be at least 12 bytes");
    if (op.row_starts.size() != op.output_vertex_count + 1)
        throw InvalidInput("subdivision operator has " + std::to_string(op.row_starts.size()) + " row starts for " +
                           std::to_string(op.output_vertex_count) + " output vertices");
    const unsigned char* base = reinterpret_cast<const unsigned char*>(positions);
    for (size_t r = 0; r < op.output_vertex_count; ++r) {
        double sum[3] = {0, 0, 0};
        for (size_t k = op.row_starts[r]; k < op.row_starts[r + 1]; ++k) {
            const float* p = reinterpret_cast<const float*>(base + size_t(op.columns[k]) * position_stride);
            for (int i = 0; i < 3; ++i) sum[i] += op.weights[k] * double(p[i]);
        }
        for (int i = 0; i < 3; ++i) destination[3 * r + size_t(i)] = float(sum[i]);
    }
}

}  // namespace animorder
