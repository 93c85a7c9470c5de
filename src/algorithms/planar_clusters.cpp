// Planar clusters by normals, and Tipsify inside each cluster.
//
// This follows: Nehab, Barczak & Sander, "Triangle Order Optimization for Graphics Hardware
// Computation Culling", I3D 2006, §3, which adapts the k-means chart clustering of Sander, Wood,
// Gortler, Snyder & Hoppe, "Multi-Chart Geometry Images", SGP 2003, §3: the assignment step grows
// every cluster from its seed by a breadth-first (here best-first, Dijkstra) search over the
// triangles' edge adjacency, and the update step moves each seed to its cluster's centre, found
// by a breadth-first search from the cluster's boundary. Nehab et al. replace Sander's metric by
// one on normals alone, the edge cost between a cluster c and a candidate face f
//     cost(c, f) = 1 − n̄c · nf + ε,
// with n̄c the cluster's current average normal and ε a small constant that breaks ties towards
// the seed in flat regions; clusters need not be discs. The paper's §1 leaves the locality
// optimisation inside clusters open (it used Hoppe 1999); here it is Tipsify (tipsify.cpp).
//
// Choices where the papers leave room (documented in nehab06.h): seeds start one at a time at
// the face farthest from the seeds so far (a component no seed reaches first, the largest first,
// so each connected component gets one while seeds last; a component without a seed joins, whole,
// the cluster closest to its mean normal); triangles are adjacent across a seam (vertices split
// at one position count as one); n̄c is the area-weighted mean of unit normals, renormalised; all
// ties go to the lower cluster id, then the lower triangle id, so the result is deterministic.
#include "animorder/planar_clusters.h"

#include "joined_vertices.h"

#include "animorder/invalid_input.h"
#include "animorder/tipsify.h"
#include "animorder/triangle_order.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <queue>
#include <string>
#include <vector>

namespace animorder {
namespace {

struct Vec3 {
    double x = 0, y = 0, z = 0;
};
double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Unit face normals (zero for a degenerate triangle) and areas.
void face_normals(std::vector<Vec3>& normals, std::vector<double>& areas, const uint32_t* indices, size_t triangles,
                  const float* positions) {
    normals.resize(triangles);
    areas.resize(triangles);
    for (size_t t = 0; t < triangles; ++t) {
        const float* a = positions + 3 * size_t(indices[3 * t]);
        const float* b = positions + 3 * size_t(indices[3 * t + 1]);
        const float* c = positions + 3 * size_t(indices[3 * t + 2]);
        const Vec3 u{double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
        const Vec3 v{double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
        const Vec3 n{u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
        const double length = std::sqrt(dot(n, n));
        areas[t] = 0.5 * length;
        normals[t] = length > 0 ? Vec3{n.x / length, n.y / length, n.z / length} : Vec3{};
    }
}

// Triangles sharing an undirected edge, as sorted neighbour lists (CSR). A non-manifold edge
// links all of its triangles.
struct FaceAdjacency {
    std::vector<uint32_t> offsets;  // triangles + 1
    std::vector<uint32_t> neighbours;
};

FaceAdjacency face_adjacency(const uint32_t* indices, size_t triangles, size_t vertex_count) {
    // Vertex → triangles (counting sort), then for each corner edge (u, v) the triangles around u
    // that also use v.
    std::vector<uint32_t> start(vertex_count + 1, 0), around(3 * triangles);
    for (size_t i = 0; i < 3 * triangles; ++i) ++start[indices[i] + 1];
    for (size_t v = 0; v < vertex_count; ++v) start[v + 1] += start[v];
    {
        std::vector<uint32_t> fill(start.begin(), start.end() - 1);
        for (size_t i = 0; i < 3 * triangles; ++i) around[fill[indices[i]]++] = uint32_t(i / 3);
    }
    FaceAdjacency adjacency;
    adjacency.offsets.assign(triangles + 1, 0);
    adjacency.neighbours.reserve(3 * triangles);
    std::vector<uint32_t> list;
    for (size_t t = 0; t < triangles; ++t) {
        list.clear();
        for (int i = 0; i < 3; ++i) {
            const uint32_t u = indices[3 * t + size_t(i)], v = indices[3 * t + size_t(i + 1) % 3];
            if (u == v) continue;
            for (uint32_t j = start[u]; j < start[u + 1]; ++j) {
                const uint32_t f = around[j];
                if (f == t) continue;
                const uint32_t* g = indices + 3 * size_t(f);
                if (g[0] == v || g[1] == v || g[2] == v) list.push_back(f);
            }
        }
        std::sort(list.begin(), list.end());
        list.erase(std::unique(list.begin(), list.end()), list.end());
        adjacency.neighbours.insert(adjacency.neighbours.end(), list.begin(), list.end());
        adjacency.offsets[t + 1] = uint32_t(adjacency.neighbours.size());
    }
    return adjacency;
}

// The index buffer with every vertex replaced by the smallest vertex at a bit-identical position,
// so a UV or normal seam (split vertices at one position) does not cut the surface in two.
std::vector<uint32_t> weld_indices(const uint32_t* indices, size_t index_count, const float* positions,
                                   size_t vertex_count) {
    const std::vector<uint32_t> canonical = first_vertex_at_each_position(positions, vertex_count);
    std::vector<uint32_t> welded(indices, indices + index_count);
    for (uint32_t& i : welded) i = canonical[i];
    return welded;
}

struct Entry {
    double cost;
    uint32_t cluster;
    uint32_t triangle;
    bool operator>(const Entry& o) const {
        if (cost != o.cost) return cost > o.cost;
        if (cluster != o.cluster) return cluster > o.cluster;
        return triangle > o.triangle;
    }
};
using MinQueue = std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>>;

double step_cost(Vec3 cluster_normal, Vec3 face_normal) {
    return 1.0 - dot(cluster_normal, face_normal) + kPlanarClusterEpsilon;
}

// Best-first growth from the queue's entries: a face keeps the cheapest (cost, cluster) offer.
void grow(MinQueue& queue, std::vector<double>& distance, std::vector<uint32_t>& owner,
          const std::vector<Vec3>& cluster_normals, const std::vector<Vec3>& normals, const FaceAdjacency& adjacency) {
    while (!queue.empty()) {
        const Entry e = queue.top();
        queue.pop();
        if (e.cost > distance[e.triangle] || (e.cost == distance[e.triangle] && owner[e.triangle] != e.cluster))
            continue;  // stale
        for (uint32_t i = adjacency.offsets[e.triangle]; i < adjacency.offsets[e.triangle + 1]; ++i) {
            const uint32_t f = adjacency.neighbours[i];
            const double cost = e.cost + step_cost(cluster_normals[e.cluster], normals[f]);
            if (cost < distance[f] || (cost == distance[f] && e.cluster < owner[f])) {
                distance[f] = cost;
                owner[f] = e.cluster;
                queue.push({cost, e.cluster, f});
            }
        }
    }
}

std::vector<Vec3> mean_normals(const std::vector<uint32_t>& owner, size_t clusters, const std::vector<Vec3>& normals,
                               const std::vector<double>& areas, const std::vector<uint32_t>& seeds) {
    std::vector<Vec3> sums(clusters);
    for (size_t t = 0; t < owner.size(); ++t) {
        if (owner[t] == kNone) continue;  // after seeding: a component no seed reached
        Vec3& s = sums[owner[t]];
        s.x += areas[t] * normals[t].x;
        s.y += areas[t] * normals[t].y;
        s.z += areas[t] * normals[t].z;
    }
    for (size_t c = 0; c < clusters; ++c) {
        const double length = std::sqrt(dot(sums[c], sums[c]));
        sums[c] = length > 0 ? Vec3{sums[c].x / length, sums[c].y / length, sums[c].z / length} : normals[seeds[c]];
    }
    return sums;
}

}  // namespace

struct PlanarClusterer::State {
    size_t triangles = 0;
    std::vector<Vec3> normals;
    std::vector<double> areas;
    FaceAdjacency adjacency;
    std::vector<uint32_t> component;        // per triangle: its connected component
    std::vector<uint32_t> component_faces;  // per component: its triangle count
    // Farthest-point seeding so far: seeds for k clusters extend those for fewer, so a larger
    // count resumes where the last one stopped.
    std::vector<uint32_t> seeds;
    std::vector<Vec3> seed_normals;
    std::vector<double> distance;
    std::vector<uint32_t> owner;
};

PlanarClusterer::PlanarClusterer(const uint32_t* indices, size_t index_count, const float* positions,
                                 size_t vertex_count)
    : state_(std::make_unique<State>()) {
    validate_indices(indices, index_count, vertex_count);
    const size_t triangles = index_count / 3;
    if (triangles == 0) return;
    if (!positions) throw InvalidInput("cluster_by_normals: positions are missing");
    if (triangles >= kNone) throw InvalidInput("cluster_by_normals: too many triangles");
    for (size_t i = 0; i < index_count; ++i)
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(positions[3 * size_t(indices[i]) + size_t(k)]))
                throw InvalidInput("cluster_by_normals: vertex " + std::to_string(indices[i]) +
                                   " has a non-finite position");
    State& s = *state_;
    s.triangles = triangles;
    face_normals(s.normals, s.areas, indices, triangles, positions);
    const std::vector<uint32_t> welded = weld_indices(indices, index_count, positions, vertex_count);
    s.adjacency = face_adjacency(welded.data(), triangles, vertex_count);
    // Connected components over the adjacency, numbered in order of their lowest triangle.
    s.component.assign(triangles, kNone);
    std::vector<uint32_t> stack;
    for (uint32_t t = 0; t < triangles; ++t) {
        if (s.component[t] != kNone) continue;
        const uint32_t c = uint32_t(s.component_faces.size());
        s.component_faces.push_back(0);
        s.component[t] = c;
        stack.push_back(t);
        while (!stack.empty()) {
            const uint32_t f = stack.back();
            stack.pop_back();
            ++s.component_faces[c];
            for (uint32_t i = s.adjacency.offsets[f]; i < s.adjacency.offsets[f + 1]; ++i) {
                const uint32_t g = s.adjacency.neighbours[i];
                if (s.component[g] == kNone) {
                    s.component[g] = c;
                    stack.push_back(g);
                }
            }
        }
    }
    s.distance.assign(triangles, kInfinity);
    s.owner.assign(triangles, kNone);
}

PlanarClusterer::~PlanarClusterer() = default;

size_t PlanarClusterer::component_count() const { return state_->component_faces.size(); }

std::vector<uint32_t> PlanarClusterer::cluster(size_t cluster_count, unsigned max_iterations) {
    State& st = *state_;
    const size_t triangles = st.triangles;
    if (triangles == 0) return {};
    if (cluster_count == 0) throw InvalidInput("cluster_by_normals: the cluster count must be at least 1");
    const size_t k = std::min(cluster_count, triangles);
    const std::vector<Vec3>& normals = st.normals;
    const std::vector<double>& areas = st.areas;
    const FaceAdjacency& adjacency = st.adjacency;

    // Seeding: one at a time at the farthest face, each seed's region grown incrementally (a new
    // seed only takes faces it reaches more cheaply), with the seed's own normal as n̄c.
    if (st.seeds.size() > k) {
        st.seeds.clear();
        st.seed_normals.clear();
        std::fill(st.distance.begin(), st.distance.end(), kInfinity);
        std::fill(st.owner.begin(), st.owner.end(), kNone);
    }
    while (st.seeds.size() < k) {
        // A component no seed reached yet, the one with most triangles first (its lowest
        // triangle); once every component has a seed, the farthest face.
        uint32_t farthest = 0;
        for (uint32_t t = 1; t < triangles; ++t) {
            const bool unreached = st.distance[t] == kInfinity, best_unreached = st.distance[farthest] == kInfinity;
            if (unreached && best_unreached) {
                if (st.component_faces[st.component[t]] > st.component_faces[st.component[farthest]]) farthest = t;
            } else if (st.distance[t] > st.distance[farthest]) {
                farthest = t;
            }
        }
        const uint32_t c = uint32_t(st.seeds.size());
        st.seeds.push_back(farthest);
        st.seed_normals.push_back(normals[farthest]);
        st.distance[farthest] = 0;
        st.owner[farthest] = c;
        MinQueue queue;
        queue.push({0.0, c, farthest});
        grow(queue, st.distance, st.owner, st.seed_normals, normals, adjacency);
    }
    std::vector<uint32_t> seeds = st.seeds;
    std::vector<uint32_t> owner = st.owner;
    std::vector<double> distance(triangles);
    std::vector<Vec3> cluster_normals;

    for (unsigned iteration = 0;; ++iteration) {
        // Assignment: grow every cluster from its seed with its current average normal.
        cluster_normals = mean_normals(owner, k, normals, areas, seeds);
        std::fill(distance.begin(), distance.end(), kInfinity);
        std::fill(owner.begin(), owner.end(), kNone);
        MinQueue queue;
        for (uint32_t c = 0; c < k; ++c) {
            distance[seeds[c]] = 0;
            owner[seeds[c]] = c;
            queue.push({0.0, c, seeds[c]});
        }
        grow(queue, distance, owner, cluster_normals, normals, adjacency);
        // A component without a seed joins, whole, the cluster closest to its area-weighted
        // mean normal (splitting it would cost vertex-cache misses along the cut).
        std::vector<Vec3> unseeded(st.component_faces.size());
        bool any_unseeded = false;
        for (size_t t = 0; t < triangles; ++t)
            if (owner[t] == kNone) {
                Vec3& n = unseeded[st.component[t]];
                n.x += areas[t] * normals[t].x;
                n.y += areas[t] * normals[t].y;
                n.z += areas[t] * normals[t].z;
                any_unseeded = true;
            }
        if (any_unseeded) {
            std::vector<uint32_t> joins(st.component_faces.size(), kNone);
            for (size_t t = 0; t < triangles; ++t) {
                if (owner[t] != kNone) continue;
                uint32_t& best = joins[st.component[t]];
                if (best == kNone) {
                    const Vec3 n = unseeded[st.component[t]];
                    best = 0;
                    for (uint32_t c = 1; c < k; ++c)
                        if (dot(cluster_normals[c], n) > dot(cluster_normals[best], n)) best = c;
                }
                owner[t] = best;
            }
        }
        if (iteration >= max_iterations) break;

        // Update: each seed moves to the face of its cluster farthest (in steps) from the cluster's
        // boundary; ties by closeness to the cluster's normal, then lower triangle id.
        cluster_normals = mean_normals(owner, k, normals, areas, seeds);
        std::vector<uint32_t> depth(triangles, kNone);
        std::vector<uint32_t> frontier;
        for (uint32_t t = 0; t < triangles; ++t)
            for (uint32_t i = adjacency.offsets[t]; i < adjacency.offsets[t + 1]; ++i)
                if (owner[adjacency.neighbours[i]] != owner[t]) {
                    depth[t] = 0;
                    frontier.push_back(t);
                    break;
                }
        for (size_t head = 0; head < frontier.size(); ++head) {
            const uint32_t t = frontier[head];
            for (uint32_t i = adjacency.offsets[t]; i < adjacency.offsets[t + 1]; ++i) {
                const uint32_t f = adjacency.neighbours[i];
                if (owner[f] == owner[t] && depth[f] == kNone) {
                    depth[f] = depth[t] + 1;
                    frontier.push_back(f);
                }
            }
        }
        std::vector<uint32_t> next(k, kNone);
        for (uint32_t t = 0; t < triangles; ++t) {
            const uint32_t c = owner[t];
            const uint32_t s = next[c];
            // A cluster without a boundary (a whole component) has kNone everywhere: all tie.
            if (s == kNone || depth[t] > depth[s] ||
                (depth[t] == depth[s] && dot(normals[t], cluster_normals[c]) > dot(normals[s], cluster_normals[c])))
                next[c] = t;
        }
        if (next == seeds) break;
        seeds = next;
    }
    return owner;
}

std::vector<uint32_t> cluster_by_normals(const uint32_t* indices, size_t index_count, const float* positions,
                                         size_t vertex_count, size_t cluster_count, unsigned max_iterations) {
    PlanarClusterer clusterer(indices, index_count, positions, vertex_count);
    if (index_count >= 3 && cluster_count == 0)
        throw InvalidInput("cluster_by_normals: the cluster count must be at least 1");
    return clusterer.cluster(cluster_count, max_iterations);
}

std::vector<uint32_t> tipsify_clusters(uint32_t* order, const uint32_t* indices, size_t index_count,
                                       size_t vertex_count, const uint32_t* cluster_of, size_t cluster_count,
                                       unsigned cache_size) {
    validate_indices(indices, index_count, vertex_count);
    const size_t triangles = index_count / 3;
    std::vector<uint32_t> starts(cluster_count + 1, 0);
    for (size_t t = 0; t < triangles; ++t) {
        if (cluster_of[t] >= cluster_count)
            throw InvalidInput("tipsify_clusters: triangle " + std::to_string(t) + " is in cluster " +
                               std::to_string(cluster_of[t]) + ", but there are " + std::to_string(cluster_count));
        ++starts[cluster_of[t] + 1];
    }
    for (size_t c = 0; c < cluster_count; ++c) starts[c + 1] += starts[c];
    std::vector<uint32_t> members(triangles);
    {
        std::vector<uint32_t> fill(starts.begin(), starts.end() - 1);
        for (size_t t = 0; t < triangles; ++t) members[fill[cluster_of[t]]++] = uint32_t(t);
    }
    std::vector<uint32_t> local_of(vertex_count, kNone);
    std::vector<uint32_t> local_indices, local_order;
    std::vector<uint32_t> used;
    for (size_t c = 0; c < cluster_count; ++c) {
        const uint32_t begin = starts[c], end = starts[c + 1];
        local_indices.clear();
        used.clear();
        for (uint32_t i = begin; i < end; ++i)
            for (int corner = 0; corner < 3; ++corner) {
                const uint32_t v = indices[3 * size_t(members[i]) + size_t(corner)];
                if (local_of[v] == kNone) {
                    local_of[v] = uint32_t(used.size());
                    used.push_back(v);
                }
                local_indices.push_back(local_of[v]);
            }
        local_order.resize(end - begin);
        tipsify(local_order.data(), local_indices.data(), local_indices.size(), used.size(), cache_size);
        for (uint32_t i = begin; i < end; ++i) order[i] = members[begin + local_order[i - begin]];
        for (uint32_t v : used) local_of[v] = kNone;
    }
    if (triangles == 0 && cache_size < 3) throw InvalidInput("Tipsify needs a cache of at least 3 entries");
    return starts;
}

}  // namespace animorder
