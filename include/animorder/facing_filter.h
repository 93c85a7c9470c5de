// animorder — back faces left out before rasterising, from a keyframe's geometry (facing_filter.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace animorder {

// The triangles of one keyframe that NodeRasterizer may draw from a node's viewpoint, found with
// one dot product per triangle instead of projecting and snapping its corners: a single-sided
// triangle that faces away from the eye by more than snapping and float rounding can turn over is
// left out, since the rasteriser would cull it. Exact: NodeRasterizer::rasterize_validated draws
// the same fragments from the candidates as from every triangle (test_facing_filter).
class FacingFilter {
public:
    // positions: the keyframe's (3 floats per vertex), indices already validated against
    // vertex_count; centre and radius: the framing the node cameras use (node_view_projection,
    // transform_to_clip); resolution: the viewport's; modes: as NodeRasterizer::rasterize (a
    // double-sided triangle is always a candidate). The filter keeps what it needs (no pointers).
    void build(const float* positions, size_t vertex_count, const uint32_t* indices, size_t index_count,
               const float centre[3], float radius, unsigned resolution, const uint8_t* modes);

    // build, unless the last build was build_for's with the same arguments: `key` names what the
    // addresses cannot (a keyframe's number, for a worker that draws the nodes of one keyframe
    // after another); the other arguments are compared too, positions by address.
    void build_for(uint64_t key, const float* positions, size_t vertex_count, const uint32_t* indices,
                   size_t index_count, const float centre[3], float radius, unsigned resolution, const uint8_t* modes) {
        const Arguments arguments{key,       positions, vertex_count, indices,    index_count, centre[0],
                                  centre[1], centre[2], radius,       resolution, modes};
        if (built_ && arguments == built_for_) return;
        build(positions, vertex_count, indices, index_count, centre, radius, resolution, modes);
        built_ = true;
        built_for_ = arguments;
    }

    // False when the keyframe gives no guarantee (a corner outside the framing sphere, a value
    // that is not finite, a radius beyond 2^±100, nothing built) or no triangle could be left out
    // (all double-sided).
    bool usable() const { return usable_; }

    // The candidates, ascending, for the camera node_view_projection(view_direction, radius):
    // `count` triangle indices at `ids`, valid until the next call; ids is null when the filter
    // is not usable (every triangle, as NodeRasterizer reads a null list).
    struct Candidates {
        const uint32_t* ids;
        size_t count;
    };
    Candidates candidates(const float view_direction[3]);

    // The portable copy only (tests compare it with the AVX2 copy, which gives the same list).
    void set_portable(bool portable) { portable_ = portable; }

private:
    struct Arguments {
        uint64_t key;
        const float* positions;
        size_t vertex_count;
        const uint32_t* indices;
        size_t index_count;
        float x, y, z, radius;
        unsigned resolution;
        const uint8_t* modes;
        bool operator==(const Arguments& o) const {
            return key == o.key && positions == o.positions && vertex_count == o.vertex_count && indices == o.indices &&
                   index_count == o.index_count && x == o.x && y == o.y && z == o.z && radius == o.radius &&
                   resolution == o.resolution && modes == o.modes;
        }
    };
    bool usable_ = false, portable_ = false;
    bool built_ = false;  // by build_for, with built_for_ (build alone clears it)
    Arguments built_for_{};
    // Per triangle, in float: the normal n = (b − a) × (c − a) in the framed space in units of R,
    // and the limit: the triangle is left out at eye e when n · e < limit (n · a less the threshold).
    std::vector<float> nx_, ny_, nz_, limit_;
    std::vector<float> corners_;  // build's scratch: the framed corners,
    std::vector<double> radii_;   // and their distances from the centre
    std::vector<uint32_t> out_;
};

}  // namespace animorder
