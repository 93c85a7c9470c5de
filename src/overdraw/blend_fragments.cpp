// Blended (BLEND) primitives in the overdraw engine (issue 18): a node's fragments of blended
// triangles exported per pixel, nearest first, and scored under many orders as mis-sorted pairs
// (two fragments of a pixel at different depths drawn farther-before-nearer).
#include "animorder/rasterizer.h"

#include "animorder/invalid_input.h"

#include "fragment_encoding.h"
#include "raster_state.h"

#include <algorithm>
#include <vector>

namespace animorder {

BlendFragments NodeRasterizer::export_blend_fragments(const uint8_t* blended) const {
    const State& s = *state_;
    BlendFragments out;
    // A pixel's lone fragment is counted when blended (no opaque fragment hides it); the grouped
    // lists keep only its pixel, so its triangle comes from the raw fragments.
    if (s.single > 0) {
        std::vector<uint8_t> single(size_t(s.resolution) * s.resolution, 0);
        for (size_t i = 0; i < s.single; ++i) single[s.single_pixels[i]] = 1;
        for (size_t f = 0; f < s.raw_count; ++f)
            if (single[s.raw_pixel[f]] && blended[s.raw_triangle[f]]) ++out.covered;
    }
    out.starts.push_back(0);
    for (size_t m = 0; m < s.multi_count; ++m) {
        const uint32_t* f = s.multi_fragment.data() + s.multi_start[m];
        const uint32_t n = s.multi_start[m + 1] - s.multi_start[m];
        const size_t begin = out.fragments.size();
        for (uint32_t j = 0; j < n;) {
            uint32_t end = j + 1;  // the group of equal depths j .. end − 1
            while (end < n && (f[end] & kTieBit)) ++end;
            bool opaque = false;
            for (uint32_t i = j; i < end; ++i) opaque = opaque || !blended[f[i] & kTriangleMask];
            if (opaque) break;  // the opaque depth: this group fails LESS, and so does all behind it
            for (uint32_t i = j; i < end; ++i) out.fragments.push_back((f[i] & kTriangleMask) | (i > j ? kTieBit : 0));
            j = end;
        }
        const size_t count = out.fragments.size() - begin;
        if (count >= 1) ++out.covered;
        if (count >= 2) {
            out.pixels.push_back(s.multi_pixel[m]);
            out.starts.push_back(uint32_t(out.fragments.size()));
        } else {
            out.fragments.resize(begin);
        }
    }
    return out;
}

namespace {

// One pixel's counted fragments (nearest first) under one order: pairs at different depths, and
// those drawn nearer-before-farther.
void blend_pixel(const uint32_t* f, uint32_t n, const uint32_t* ranks, size_t order_count, size_t o, uint64_t& pairs,
                 uint64_t& missorted) {
    uint32_t group_start = 0;
    for (uint32_t j = 0; j < n; ++j) {
        if (!(f[j] & kTieBit)) group_start = j;
        const uint32_t rank_far = ranks[size_t(f[j] & kTriangleMask) * order_count + o];
        for (uint32_t i = 0; i < group_start; ++i) {  // every strictly nearer fragment
            ++pairs;
            missorted += ranks[size_t(f[i] & kTriangleMask) * order_count + o] < rank_far;
        }
    }
}

}  // namespace

void score_blend(BlendCounts* counts, const BlendFragments& node, const uint32_t* ranks, size_t order_count) {
    for (size_t o = 0; o < order_count; ++o) {
        BlendCounts c;
        c.covered = node.covered;
        for (size_t m = 0; m < node.pixels.size(); ++m) {
            uint64_t pairs = 0, missorted = 0;
            blend_pixel(node.fragments.data() + node.starts[m], node.starts[m + 1] - node.starts[m], ranks, order_count,
                        o, pairs, missorted);
            c.pairs += pairs;
            c.missorted_pairs += missorted;
            c.missorted_pixels += missorted > 0;
        }
        counts[o] = c;
    }
}

std::vector<uint32_t> missorted_per_pixel(const BlendFragments& node, unsigned resolution, const uint32_t* ranks,
                                          size_t order_count, size_t order_index) {
    if (order_index >= order_count) throw InvalidInput("order index out of range");
    std::vector<uint32_t> image(size_t(resolution) * resolution, 0);
    for (size_t m = 0; m < node.pixels.size(); ++m) {
        uint64_t pairs = 0, missorted = 0;
        blend_pixel(node.fragments.data() + node.starts[m], node.starts[m + 1] - node.starts[m], ranks, order_count,
                    order_index, pairs, missorted);
        if (node.pixels[m] < image.size()) image[node.pixels[m]] = uint32_t(missorted);
    }
    return image;
}

}  // namespace animorder
