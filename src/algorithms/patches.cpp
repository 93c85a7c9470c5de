// Patches: fast linear clustering of a vertex-cache-optimised triangle sequence.
//
// This follows: Sander, Nehab & Barczak, "Fast Triangle Reordering for Vertex Locality and
// Reduced Overdraw", SIGGRAPH 2007, §4 (equation 1), as reused by Han & Sander, "Triangle
// Reordering for Efficient Rendering in Complex Scenes", JCGT 2017, §3.1.
//
// Tipsify's output follows wide paths along the mesh, so contiguous runs of it are spatially
// compact: clustering becomes a 1-D problem of where to cut. The sequence is cut at every hard
// boundary (a dead-end jump, where the cache is flushed anyway, so the cut costs nothing) and at
// soft boundaries, where the current patch's own ACMR M_i has fallen below λ: a patch that has
// amortised its cold-cache start is cut off before it grows long enough to leave no freedom for
// sorting. λ is therefore a close lower bound on the clustered model's ACMR.
//
// M_i is measured in a FIFO cache that starts empty at each patch start (a patch may be drawn
// after any other), counting the candidate triangle i itself: the cut goes before i when the
// patch *with* i would have M_i < λ. This reading makes the paper's two limits exact: M_i >= 0.5
// on a manifold so λ < 0.5 never cuts, and any triangle sharing a vertex with the patch gives
// M_i <= 2.5 < 3 so λ >= 3 cuts everywhere. Both limits are also enforced explicitly
// (DESIGN.md), so degenerate or disconnected input cannot blur them.
#include "animorder/patches.h"

#include "animorder/invalid_input.h"
#include "animorder/triangle_order.h"

#include <cmath>
#include <string>
#include <vector>

namespace animorder {
namespace {

void validate_hard_boundaries(const uint32_t* hard_boundaries, size_t count, size_t triangle_count) {
    if (count > 0 && hard_boundaries == nullptr) throw InvalidInput("hard boundary list is null");
    for (size_t i = 0; i < count; ++i) {
        if (hard_boundaries[i] >= triangle_count)
            throw InvalidInput("hard boundary " + std::to_string(hard_boundaries[i]) + " is past the last triangle (" +
                               std::to_string(triangle_count) + ")");
        if (i > 0 && hard_boundaries[i] <= hard_boundaries[i - 1])
            throw InvalidInput("hard boundaries must be strictly ascending");
    }
}

// A FIFO vertex cache with O(1) flush: entries are insertion stamps, and a flush advances the
// clock by more than the cache size, which evicts everything at once.
class PatchCache {
public:
    PatchCache(size_t vertex_count, unsigned cache_size)
        : stamp_(vertex_count, 0), size_(cache_size), now_(uint64_t(cache_size) + 1) {}

    void flush() { now_ += size_ + 1; }

    // Misses triangle (a, b, c) would cause now, looked up corner by corner as hardware does.
    int misses_if_drawn(const uint32_t* corners) const {
        uint64_t now = now_;
        uint32_t inserted[3];
        int misses = 0;
        for (int c = 0; c < 3; ++c) {
            const uint32_t v = corners[c];
            bool just_inserted = false;
            for (int j = 0; j < misses; ++j) just_inserted |= inserted[j] == v;
            if (!just_inserted && now - stamp_[v] > size_) {
                inserted[misses++] = v;
                ++now;
            }
        }
        return misses;
    }

    // Draws the triangle and returns its misses (the same count misses_if_drawn gave).
    int draw(const uint32_t* corners) {
        int misses = 0;
        for (int c = 0; c < 3; ++c) {
            const uint32_t v = corners[c];
            if (now_ - stamp_[v] > size_) {
                stamp_[v] = now_++;
                ++misses;
            }
        }
        return misses;
    }

private:
    std::vector<uint64_t> stamp_;
    uint64_t size_;
    uint64_t now_;
};

}  // namespace

std::vector<uint32_t> build_patches(const uint32_t* indices, size_t index_count, size_t vertex_count,
                                    const uint32_t* hard_boundaries, size_t hard_boundary_count, double lambda,
                                    unsigned cache_size) {
    validate_indices(indices, index_count, vertex_count);
    if (std::isnan(lambda)) throw InvalidInput("lambda is NaN");
    if (cache_size == 0) throw InvalidInput("cache size must be at least 1");
    const size_t triangle_count = index_count / 3;
    validate_hard_boundaries(hard_boundaries, hard_boundary_count, triangle_count);

    std::vector<uint32_t> starts{0};
    if (triangle_count == 0) return starts;

    if (lambda >= 3.0) {  // single triangles
        starts.resize(triangle_count + 1);
        for (size_t t = 0; t <= triangle_count; ++t) starts[t] = uint32_t(t);
        return starts;
    }

    const bool soft_boundaries = lambda >= 0.5;
    PatchCache cache(vertex_count, cache_size);
    size_t next_hard = 0;
    size_t patch_misses = 0, patch_triangles = 0;
    for (size_t t = 0; t < triangle_count; ++t) {
        const uint32_t* corners = indices + 3 * t;
        bool cut = false;
        if (next_hard < hard_boundary_count && hard_boundaries[next_hard] == t) {
            cut = t > 0;
            ++next_hard;
        } else if (soft_boundaries && patch_triangles > 0) {
            const double local_acmr =
                double(patch_misses + cache.misses_if_drawn(corners)) / double(patch_triangles + 1);
            cut = local_acmr < lambda;
        }
        if (cut) {
            starts.push_back(uint32_t(t));
            cache.flush();
            patch_misses = patch_triangles = 0;
        }
        patch_misses += cache.draw(corners);
        ++patch_triangles;
    }
    starts.push_back(uint32_t(triangle_count));
    return starts;
}

void expand_patch_order(uint32_t* order, const uint32_t* patch_order, const uint32_t* patch_starts,
                        size_t patch_count) {
    validate_triangle_order(patch_order, patch_count);
    size_t out = 0;
    for (size_t i = 0; i < patch_count; ++i) {
        const uint32_t p = patch_order[i];
        for (uint32_t t = patch_starts[p]; t < patch_starts[p + 1]; ++t) order[out++] = t;
    }
}

}  // namespace animorder
