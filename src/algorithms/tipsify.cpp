// Tipsify: linear-time vertex cache optimisation.
//
// This follows: Pedro V. Sander, Diego Nehab, Joshua Barczak. "Fast Triangle Reordering for
// Vertex Locality and Reduced Overdraw". ACM Transactions on Graphics (SIGGRAPH) 26(3), 2007, §3,
// pseudo-code Tipsify / Get-Next-Vertex / Skip-Dead-End.
//
// Triangles are emitted as fans around a sequence of fanning vertices. The next fanning vertex
// is picked among the 1-ring candidates of the current fan: the one that entered the cache
// earliest among those that would still be cached after being fanned themselves (conservatively,
// position + 2·live triangles <= k), else the first candidate with live triangles. When no
// candidate has live triangles the algorithm is at a dead-end and jumps: first to the most
// recently referenced vertex with live triangles (the dead-end stack), last to the next vertex
// with live triangles in input order. Each such jump is a *hard boundary*: fast linear
// clustering (§4, patches.cpp) cuts there, because the cache has usually been flushed.
//
// Cache positions come from insertion time stamps (s − C[v]), so k only appears in constant-time
// tests and the run time is O(triangles), independent of k. One deviation from the pseudo-code,
// for speed and not for results: the candidate set N of a fan is the stretch of the dead-end
// stack that the fan pushed (the same vertices, possibly repeated), so no set is built.
#include "animorder/tipsify.h"

#include "animorder/invalid_input.h"
#include "animorder/triangle_order.h"

#include <memory>
#include <vector>

namespace animorder {
namespace {

// Vertex-triangle adjacency as an offset map into one array (counting sort over the index
// buffer, "Build-Adjacency" in the paper).
struct Adjacency {
    std::vector<uint32_t> offsets;          // vertex_count + 1
    std::unique_ptr<uint32_t[]> triangles;  // index_count, every slot written before use
};

Adjacency build_adjacency(const uint32_t* indices, size_t index_count, size_t vertex_count) {
    Adjacency adjacency;
    adjacency.offsets.assign(vertex_count + 1, 0);
    adjacency.triangles.reset(new uint32_t[index_count]);  // not zeroed: filled right below
    uint32_t* offsets = adjacency.offsets.data();
    for (size_t i = 0; i < index_count; ++i) ++offsets[indices[i] + 1];
    for (size_t v = 0; v < vertex_count; ++v) offsets[v + 1] += offsets[v];
    // Fill using offsets[v] as a moving cursor, then shift back by one slot.
    for (size_t t = 0; t < index_count / 3; ++t)
        for (int c = 0; c < 3; ++c) adjacency.triangles[offsets[indices[3 * t + c]]++] = uint32_t(t);
    for (size_t v = vertex_count; v > 0; --v) offsets[v] = offsets[v - 1];
    offsets[0] = 0;
    return adjacency;
}

// Writes the face permutation to order and/or the index buffer to destination (either may be
// null), in the same pass, so producing an index buffer costs no second walk over the triangles.
TipsifyResult run_tipsify(uint32_t* order, uint32_t* destination, const uint32_t* indices, size_t index_count,
                          size_t vertex_count, unsigned cache_size) {
    validate_indices(indices, index_count, vertex_count);
    if (cache_size < 3) throw InvalidInput("Tipsify needs a cache of at least 3 entries");
    if (destination != nullptr && destination == indices && index_count > 0)
        throw InvalidInput("Tipsify: destination must not alias indices");
    TipsifyResult result;
    const size_t triangle_count = index_count / 3;
    if (triangle_count == 0) return result;

    const Adjacency adjacency = build_adjacency(indices, index_count, vertex_count);
    const uint32_t* offsets = adjacency.offsets.data();
    const uint32_t* vertex_triangles = adjacency.triangles.get();

    // L: live (not yet emitted) triangles per vertex and C: cache time stamps, side by side
    // because every visit reads both; E: emitted flags.
    struct VertexState {
        uint32_t live;
        uint32_t stamp;
    };
    std::vector<VertexState> state(vertex_count);
    for (size_t v = 0; v < vertex_count; ++v) state[v] = {offsets[v + 1] - offsets[v], 0};
    std::vector<uint8_t> emitted(triangle_count, 0);
    // Receives each corner once (3t pushes at most); read only below its top, so never zeroed.
    std::unique_ptr<uint32_t[]> dead_end(new uint32_t[index_count]);
    size_t dead_end_top = 0;

    const uint32_t k = cache_size;
    uint32_t s = k + 1;  // time stamp; s − C[v] > k means "not in cache"
    size_t cursor = 0;   // input-order sweep for Skip-Dead-End, never moves back
    size_t emitted_count = 0;

    // The arbitrary starting vertex: the first with triangles (vertex 0 may be unreferenced).
    while (cursor < vertex_count && state[cursor].live == 0) ++cursor;
    uint32_t fan = uint32_t(cursor);

    for (;;) {
        const size_t candidates_begin = dead_end_top;
        for (uint32_t a = offsets[fan], end = offsets[fan + 1]; a < end; ++a) {
            const uint32_t t = vertex_triangles[a];
            if (emitted[t]) continue;
            const uint32_t* corners = indices + 3 * size_t(t);
            for (int c = 0; c < 3; ++c) {
                const uint32_t v = corners[c];
                dead_end[dead_end_top++] = v;
                VertexState& vs = state[v];
                --vs.live;
                if (s - vs.stamp > k) vs.stamp = s++;
            }
            emitted[t] = 1;
            if (order) order[emitted_count] = t;
            if (destination) {
                destination[3 * emitted_count + 0] = corners[0];
                destination[3 * emitted_count + 1] = corners[1];
                destination[3 * emitted_count + 2] = corners[2];
            }
            ++emitted_count;
        }
        if (emitted_count == triangle_count) break;

        // Get-Next-Vertex: the candidate entering the cache earliest that stays cached.
        int64_t best = -1;
        int64_t best_priority = -1;
        for (size_t i = candidates_begin; i < dead_end_top; ++i) {
            const uint32_t v = dead_end[i];
            const VertexState vs = state[v];
            if (vs.live == 0) continue;
            int64_t priority = 0;
            const uint32_t position = s - vs.stamp;
            if (position + 2 * vs.live <= k) priority = position;
            if (priority > best_priority) {
                best_priority = priority;
                best = int64_t(v);
            }
        }
        if (best >= 0) {
            fan = uint32_t(best);
            continue;
        }

        // Skip-Dead-End: most recently referenced vertex with live triangles, else input order.
        result.hard_boundaries.push_back(uint32_t(emitted_count));
        while (dead_end_top > 0 && best < 0) {
            const uint32_t v = dead_end[--dead_end_top];
            if (state[v].live > 0) best = int64_t(v);
        }
        while (best < 0) {  // terminates: some triangle is still live
            if (state[cursor].live > 0)
                best = int64_t(cursor);
            else
                ++cursor;
        }
        fan = uint32_t(best);
    }
    return result;
}

}  // namespace

TipsifyResult tipsify(uint32_t* order, const uint32_t* indices, size_t index_count, size_t vertex_count,
                      unsigned cache_size) {
    return run_tipsify(order, nullptr, indices, index_count, vertex_count, cache_size);
}

TipsifyResult tipsify_index_buffer(uint32_t* destination, const uint32_t* indices, size_t index_count,
                                   size_t vertex_count, unsigned cache_size) {
    return run_tipsify(nullptr, destination, indices, index_count, vertex_count, cache_size);
}

}  // namespace animorder
