// animorder — viewpoints, cameras and the overdraw engine (DESIGN.md: framing, camera,
// viewpoints, rasterisation rules, overdraw of an order at a node).
//
// The engine measures what Han & Sander 2017 measured with GPU occlusion queries: how many
// fragments pass a LESS depth test when a mesh is drawn in a given triangle order at a node
// (keyframe, viewpoint). One rasterisation of a node keeps every pixel's fragments; any number
// of orders are then scored by replaying those fragments in each order's sequence, which gives
// exactly what drawing each order separately would. No file I/O here.
#pragma once

#include "animorder/animated_mesh.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace animorder {

// ---------------------------------------------------------------------------------------------
// Viewpoints and framing (viewpoints.cpp)

// Unit directions at the vertices of an icosahedron subdivided `subdivisions` times
// (0 → 12, 1 → 42, 2 → 162, 3 → 642, ...): 10·4^s + 2 directions, xyz each. Deterministic.
std::vector<float> icosphere_directions(unsigned subdivisions);

// The subdivision level that gives `count` directions; throws InvalidInput if count is not
// 10·4^s + 2 (12, 42, 162, 642, 2562).
unsigned icosphere_subdivisions_for(size_t count);

// `count` directions uniform on the unit sphere from a seeded generator (DESIGN.md's evaluation
// viewpoints use 300 with a fixed seed). Same seed, same directions, on every platform.
std::vector<float> random_sphere_directions(size_t count, uint64_t seed);

// Framing (DESIGN.md): each keyframe's bounding box centre (of the vertices the index buffer
// references) moves to the origin; the view radius R is the largest distance from a keyframe's
// centre to one of its vertices, over all keyframes. Framing never rotates.
struct Framing {
    std::vector<float> centres;  // 3 per keyframe
    std::vector<float> radii;    // per keyframe: farthest vertex from its centre
    float radius = 0;            // the view radius R: the largest of radii
};
Framing frame_keyframes(const float* keyframe_positions, size_t keyframe_count, size_t vertex_count,
                        const uint32_t* indices, size_t index_count);

// The same framing with R taken over a subset of keyframes (one clip is one animation).
Framing frame_subset(const Framing& framing, const std::vector<uint32_t>& keyframes);

// ---------------------------------------------------------------------------------------------
// The camera (camera.cpp)

using Mat4d = std::array<double, 16>;  // column-major, as OpenGL

// Camera at distance 3R along the unit direction `view_direction` (from the origin towards the
// eye), looking at the origin, square viewport, vertical field of view 2·asin(1/3) so the sphere
// of radius R exactly fits, near plane at distance R, far at 5R. Up is +Y, or +Z when the view
// direction is within ~2.6° of ±Y. Returns projection · view (OpenGL clip space, z in [−w, w]).
Mat4d node_view_projection(const float view_direction[3], float radius);

// clip[4v..4v+3] = view_projection · (positions[v] − centre, 1), in float as a vertex shader would.
void transform_to_clip(float* clip_xyzw, const float* positions, size_t vertex_count, const float centre[3],
                       const Mat4d& view_projection);

// ---------------------------------------------------------------------------------------------
// Orders as rank tables (overdraw.cpp)

// ranks[t·order_count + o] = the position at which order o draws triangle t. Each orders[o] is a
// face permutation of triangle_count triangles (validated). Interleaved so that scoring reads one
// cache line per fragment for all orders.
std::vector<uint32_t> make_rank_table(const std::vector<const uint32_t*>& orders, size_t triangle_count);

// ---------------------------------------------------------------------------------------------
// The rasteriser (rasterizer.cpp)

// One node's rasterisation under DESIGN.md's rules: pixel centres at +0.5, top-left fill rule
// (after flipping OpenGL's window y to point down), vertices snapped to 1/256 pixel, depth
// linear in screen space, LESS against a buffer cleared to 1, back faces (clockwise in OpenGL
// window space) culled, triangles clipped against the near and far planes. It keeps, for every
// pixel, the fragments of all front-facing triangles sorted by depth, so scoring an order never
// needs another rasterisation. Reuse one instance across nodes: its buffers are kept.
class NodeRasterizer {
public:
    NodeRasterizer();
    ~NodeRasterizer();
    NodeRasterizer(NodeRasterizer&&) noexcept;
    NodeRasterizer& operator=(NodeRasterizer&&) noexcept;

    // Rasterises the triangle list (clip-space positions, 4 floats per vertex) into a square
    // viewport of resolution × resolution pixels. Replaces the previous node.
    void rasterize(const float* clip_xyzw, size_t vertex_count, const uint32_t* indices, size_t index_count,
                   unsigned resolution);

    // Pixels covered by at least one fragment (what the depth buffer shows after any order).
    uint64_t visible_pixels() const;
    // Fragments generated (what a draw with the depth test off would shade).
    uint64_t fragments() const;

    // For each of order_count orders (rank table from make_rank_table), the fragments that pass
    // the depth test when the triangles are drawn in that order.
    void score(uint64_t* passed, const uint32_t* ranks, size_t order_count) const;

    // Per pixel (row 0 at the top), fragments passing the depth test under one order
    // (order_index of the rank table): the heatmap behind the paper's Figure 1.
    std::vector<uint32_t> passed_per_pixel(const uint32_t* ranks, size_t order_count, size_t order_index) const;

    unsigned resolution() const;

    // Calls visit(pixel, triangle, depth) for every fragment of the node (pixel = row · resolution
    // + column, row 0 at the top; triangle = index in the rasterised triangle list).
    void visit_fragments(const std::function<void(uint32_t, uint32_t, float)>& visit) const;

    // The node's fragments in the compact form scoring needs (see NodeFragments).
    struct NodeFragments export_fragments() const;

    struct State;  // defined in rasterizer.cpp only

private:
    std::unique_ptr<State> state_;
};

// What scoring needs of a rasterised node, and nothing more: the visible and single-fragment pixel
// counts, and for each pixel with several fragments its triangles nearest first (the top bit marks
// a depth equal to the previous fragment's). Orders never change it, so k-means keeps it between
// iterations instead of rasterising the node again.
struct NodeFragments {
    uint64_t visible = 0;
    uint64_t single = 0;
    std::vector<uint32_t> starts;     // multi-fragment pixels + 1
    std::vector<uint32_t> fragments;  // triangle | tie bit
    size_t bytes() const { return (starts.size() + fragments.size()) * 4 + sizeof(*this); }
};

// passed[o] for each order of the rank table, from a node's fragments (NodeRasterizer::score
// gives the same numbers).
void score_fragments(uint64_t* passed, const NodeFragments& node, const uint32_t* ranks, size_t order_count);

// ---------------------------------------------------------------------------------------------
// Many nodes at once (overdraw.cpp)

// One (keyframe, viewpoint): keyframe indexes the keyframe arrays, direction is a unit vector
// from the frame's centre towards the camera.
struct OverdrawNode {
    uint32_t keyframe = 0;
    float direction[3] = {0, 0, 1};
};

struct ScoreSettings {
    unsigned resolution = 256;
    unsigned threads = 0;  // 0: all hardware threads
    // Called now and then with (nodes done, total), from any worker thread, never concurrently.
    std::function<void(size_t, size_t)> progress;
};

// For every node: transforms the keyframe (framed, camera per DESIGN.md), rasterises once, and
// scores each order of the rank table. visible[n] and passed[n·order_count + o] are written per
// node, so results are identical whatever the thread count; memory holds one node per thread.
void score_nodes(uint64_t* visible, uint64_t* passed, const float* keyframe_positions, size_t vertex_count,
                 const Framing& framing, const uint32_t* indices, size_t index_count, const OverdrawNode* nodes,
                 size_t node_count, const uint32_t* ranks, size_t order_count, const ScoreSettings& settings);

// Rasterises every node once and keeps its NodeFragments (in parallel, deterministic), or
// returns an empty vector when the fragments would take more than max_bytes (the caller then
// scores with score_nodes, rasterising again each time).
std::vector<NodeFragments> rasterize_nodes(const float* keyframe_positions, size_t vertex_count, const Framing& framing,
                                           const uint32_t* indices, size_t index_count, const OverdrawNode* nodes,
                                           size_t node_count, const ScoreSettings& settings, size_t max_bytes);

// score_nodes' results from kept fragments: no rasterisation at all.
void score_kept_nodes(uint64_t* visible, uint64_t* passed, const std::vector<NodeFragments>& nodes, const uint32_t* ranks,
                      size_t order_count, const ScoreSettings& settings);

}  // namespace animorder
