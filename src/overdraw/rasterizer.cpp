// The overdraw engine's rasteriser: exact coverage and depth per DESIGN.md, fragments kept per
// pixel so that any number of triangle orders are scored from one rasterisation.
//
// It measures what Han & Sander, "Triangle Reordering for Efficient Rendering in Complex Scenes"
// (JCGT 2017, §3) measure with GPU occlusion queries, under the rules of OpenGL as Mesa's
// llvmpipe implements them (the reference it is checked against):
// - clip space in, clipped against the near and far planes (and a guard band, which changes no
//   covered pixel), divided by w as x·(1/w), mapped to the viewport in float;
// - vertices snapped to 1/256 pixel after moving pixel centres to integer coordinates, rounding
//   half away from zero (llvmpipe's subpixel_snap);
// - orientation from the snapped coordinates: counter-clockwise in OpenGL window space is front,
//   clockwise and zero-area triangles are culled, except that a double-sided triangle's clockwise
//   side is drawn as a front face (its corners swapped, as llvmpipe does);
// - y flipped to point down, then Direct3D's top-left rule (a pixel centre on an edge is covered
//   only by a top or a left edge), with exact integer edge functions;
// - depth linear in screen space (the plane through the three window-space vertices), a float
//   depth buffer cleared to 1 and a LESS test.
//
// Overdraw depends only on, per pixel, the set of fragments and the order they arrive in. So a
// node is rasterised once, in any order, keeping every fragment (pixel, triangle, depth); the
// fragments are then grouped by pixel and sorted by depth. Drawn in an order with ranks r, a
// fragment passes LESS iff its rank is lower than the ranks of all fragments of that pixel at
// smaller or equal depth: one walk from the nearest fragment with a running minimum rank gives
// the count for every order at once. Exact ties in depth form a group of which only the fragment
// drawn first can pass.
//
// This file: the NodeRasterizer API and the choice of compiled copy. The per-node code is
// rasterize_node.h (compiled by rasterize_node_{portable,avx2,avx512}.cpp), the replay of the
// kept fragments under many orders fragment_scoring.cpp, blended primitives blend_fragments.cpp.
#include "animorder/rasterizer.h"

#include "animorder/invalid_input.h"
#include "animorder/triangle_order.h"

#include "raster_state.h"

#include <algorithm>
#include <string>

namespace animorder {

using namespace raster;

NodeRasterizer::NodeRasterizer() : state_(std::make_unique<State>()) {}
NodeRasterizer::~NodeRasterizer() = default;
NodeRasterizer::NodeRasterizer(NodeRasterizer&&) noexcept = default;
NodeRasterizer& NodeRasterizer::operator=(NodeRasterizer&&) noexcept = default;

unsigned NodeRasterizer::resolution() const { return state_->resolution; }
uint64_t NodeRasterizer::visible_pixels() const { return state_->visible; }
uint64_t NodeRasterizer::fragments() const { return state_->raw_count; }

void NodeRasterizer::visit_fragments(const std::function<void(uint32_t, uint32_t, float)>& visit) const {
    const State& s = *state_;
    for (size_t f = 0; f < s.raw_count; ++f) visit(s.raw_pixel[f], s.raw_triangle[f], s.raw_depth[f]);
}

namespace {

// The checks, then the widest copy set_copy allows.
void rasterize_source(NodeRasterizer::State& s, const VertexSource& source, size_t vertex_count,
                      const uint32_t* indices, size_t index_count, unsigned resolution, const uint8_t* modes,
                      const uint32_t* candidates, size_t candidate_count) {
    if (resolution == 0 || resolution > 16384)
        throw InvalidInput("resolution " + std::to_string(resolution) + " is outside 1..16384");
    s.resolution = resolution;
#ifdef ANIMORDER_RASTER_AVX2
    if (s.copy == NodeRasterizer::Copy::Avx512)
        return rasterize_node_avx512(s, source, vertex_count, indices, index_count, resolution, modes, candidates,
                                     candidate_count);
    if (s.copy == NodeRasterizer::Copy::Avx2)
        return rasterize_node_avx2(s, source, vertex_count, indices, index_count, resolution, modes, candidates,
                                   candidate_count);
#endif
    rasterize_node_portable(s, source, vertex_count, indices, index_count, resolution, modes, candidates,
                            candidate_count);
}
}  // namespace

void NodeRasterizer::rasterize(const float* clip_xyzw, size_t vertex_count, const uint32_t* indices, size_t index_count,
                               unsigned resolution, const uint8_t* modes) {
    validate_indices(indices, index_count, vertex_count);
    rasterize_validated(clip_xyzw, vertex_count, indices, index_count, resolution, modes, nullptr, 0);
}

void NodeRasterizer::rasterize_validated(const float* clip_xyzw, size_t vertex_count, const uint32_t* indices,
                                         size_t index_count, unsigned resolution, const uint8_t* modes,
                                         const uint32_t* candidates, size_t candidate_count) {
    VertexSource source;
    source.clip = reinterpret_cast<const ClipVertex*>(clip_xyzw);
    rasterize_source(*state_, source, vertex_count, indices, index_count, resolution, modes, candidates,
                     candidate_count);
}

void NodeRasterizer::rasterize_validated(const CentredVertices& vertices, size_t vertex_count, const uint32_t* indices,
                                         size_t index_count, unsigned resolution, const uint8_t* modes,
                                         const uint32_t* candidates, size_t candidate_count) {
    VertexSource source;
    source.x = vertices.x;
    source.y = vertices.y;
    source.z = vertices.z;
    source.m = vertices.view_projection;
    rasterize_source(*state_, source, vertex_count, indices, index_count, resolution, modes, candidates,
                     candidate_count);
}

NodeRasterizer::Copy NodeRasterizer::widest_copy() {
#ifdef ANIMORDER_RASTER_AVX2
    static const Copy widest = [] {
        if (!__builtin_cpu_supports("avx2")) return Copy::Portable;
        const bool avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                            __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
        return avx512 ? Copy::Avx512 : Copy::Avx2;
    }();
    return widest;
#else
    return Copy::Portable;
#endif
}

const char* NodeRasterizer::copy_name(Copy copy) {
    switch (copy) {
        case Copy::Avx2: return "AVX2";
        case Copy::Avx512: return "AVX-512";
        default: return "portable";
    }
}

void NodeRasterizer::set_copy(Copy widest) { state_->copy = std::min(widest, widest_copy()); }
NodeRasterizer::Copy NodeRasterizer::copy() const { return state_->copy; }

}  // namespace animorder
