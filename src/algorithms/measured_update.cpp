// The update step of `measured` k-means (beyond Han & Sander 2017, whose update sorts a cluster's
// patches by integrated distance): each cluster's patches ordered by the overdraw graph measured
// over its own nodes (measured_order.cpp: the greedy feedback-arc-set order of Eades, Lin &
// Smyth 1993 as Nehab, Barczak & Sander 2006 §5 use it, then sifting). Each cluster's pair
// counts are kept between iterations and updated with the nodes that changed cluster only; the
// clusters' searches run side by side, each the same whatever the thread.
#include "measured_update.h"

#include "../support/stopwatch.h"
#include "../support/worker_threads.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <string>
#include <vector>

namespace animorder {
namespace {

// Nodes into (sign +1) or out of (−1) a cluster's graph: the kept ones as kept, the others
// rasterised again, a chunk of about kTransientFragmentBytes at a time (a few hundred nodes at
// 256², a few dozen at 4096²: nodes beyond the budget never all come back at once). The counts
// are sums, the same however the nodes are chunked.

bool all_kept(const NodeCache& cache, const std::vector<uint32_t>& which) {
    for (const uint32_t n : which)
        if (!cache.kept(n)) return false;
    return true;
}

void add_to_graph(const NodeCache& cache, const std::vector<uint32_t>& which, int sign, unsigned threads,
                  MeasuredPairCounts& graph) {
    std::vector<const KeptNode*> kept;
    std::vector<uint32_t> again;
    for (const uint32_t n : which) {
        if (const KeptNode* node = cache.kept(n))
            kept.push_back(node);
        else
            again.push_back(n);
    }
    graph.add(kept.data(), kept.size(), sign, threads);
    uint64_t sampled_bytes = cache.sampled_bytes(), sampled_nodes = cache.sampled_nodes();
    const size_t least = size_t(worker_threads(threads));
    for (size_t begin = 0, count = 0; begin < again.size(); begin += count) {
        count = std::min(again.size() - begin,
                         nodes_within(kTransientFragmentBytes, sampled_bytes, sampled_nodes, least, 1024));
        const std::vector<KeptNode> nodes = cache.rasterize_again(again.data() + begin, count);
        std::vector<const KeptNode*> pointers;
        for (const KeptNode& node : nodes) {
            pointers.push_back(&node);
            sampled_bytes += node.bytes();
            ++sampled_nodes;
        }
        graph.add(pointers.data(), pointers.size(), sign, threads);
    }
}

}  // namespace

std::vector<size_t> measured_update_orders(const MeasuredNodes& nodes, const ClusteringSettings& settings,
                                           const std::vector<uint32_t>& assignment, MeasuredGraphs& state,
                                           std::vector<std::vector<uint32_t>>& patch_orders) {
    const MeshPatches& patches = nodes.patches;
    const uint32_t* group = patches.patch_primitive.data();
    if (state.graphs.empty()) {
        state.unit_of_triangle.assign(nodes.triangle_count, 0);
        for (size_t p = 0; p < patches.patch_count(); ++p)
            for (uint32_t j = patches.patch_starts[p]; j < patches.patch_starts[p + 1]; ++j)
                state.unit_of_triangle[patches.cache_order[j]] = uint32_t(p);
        for (size_t c = 0; c < nodes.k; ++c)
            state.graphs.emplace_back(patches.patch_count(), state.unit_of_triangle.data(),
                                      state.unit_of_triangle.size(), group, settings.front_levels);
        state.counted.assign(nodes.count, UINT32_MAX);
        state.last.assign(nodes.k, {});
        state.start.assign(nodes.k, {});
    }
    // Only the nodes that changed cluster since the last update are counted again.
    const Clock::time_point graph_start = Clock::now();
    std::vector<std::vector<uint32_t>> leaving(nodes.k), arriving(nodes.k);
    std::vector<size_t> sizes(nodes.k, 0);
    for (size_t n = 0; n < nodes.count; ++n) {
        ++sizes[assignment[n]];
        if (state.counted[n] == assignment[n]) continue;
        if (state.counted[n] != UINT32_MAX) leaving[state.counted[n]].push_back(uint32_t(n));
        arriving[assignment[n]].push_back(uint32_t(n));
        state.counted[n] = assignment[n];
    }
    size_t moved = 0;
    std::vector<uint8_t> changed(nodes.k, 0);
    bool kept = true;
    for (size_t c = 0; c < nodes.k; ++c) {
        moved += arriving[c].size();
        changed[c] = !leaving[c].empty() || !arriving[c].empty();
        kept = kept && all_kept(nodes.cache, leaving[c]) && all_kept(nodes.cache, arriving[c]);
    }
    // With at least as many clusters as workers, and every node kept (nothing to rasterise
    // again), each cluster's graph is counted by one worker straight into its table: no table per
    // worker, no merge (the peak memory of the counts is the clusters' tables alone). Integer
    // sums: the same counts either way.
    tbb::task_arena arena(worker_threads(settings.threads));
    const bool by_cluster = kept && nodes.k >= size_t(arena.max_concurrency());
    const auto count = [&](size_t c, unsigned threads) {
        add_to_graph(nodes.cache, leaving[c], -1, threads, state.graphs[c]);
        add_to_graph(nodes.cache, arriving[c], +1, threads, state.graphs[c]);
        state.graphs[c].settle();  // the counting table's memory given back before the next cluster's
    };
    if (by_cluster)
        arena.execute([&] {
            tbb::parallel_for(size_t(0), nodes.k, [&](size_t c) { count(c, 1); }, tbb::simple_partitioner());
        });
    else
        for (size_t c = 0; c < nodes.k; ++c) count(c, settings.threads);
    const double graph_seconds = seconds_since(graph_start);
    const Clock::time_point order_start = Clock::now();
    // The clusters' searches are independent: run side by side, each the same whatever the thread.
    std::vector<std::string> lines(nodes.k);
    arena.execute([&] {
        tbb::parallel_for(size_t(0), nodes.k, [&](size_t c) {
            if (sizes[c] == 0) return;
            // The buffer is already the local optimum of this very graph: nothing to do. A buffer
            // that is a measured order needs no greedy start (on real characters the greedy
            // order's backward weight is many times a sifted order's).
            const bool measured_before = patch_orders[c] == state.last[c];
            if (measured_before && !changed[c]) return;
            if (!changed[c] && patch_orders[c] == state.start[c]) {  // the same search again (its order was not kept)
                patch_orders[c] = state.last[c];
                return;
            }
            state.start[c] = patch_orders[c];
            MeasuredOrderStats stats;
            patch_orders[c] = measured_unit_order(state.graphs[c], patch_orders[c].data(), &stats, !measured_before);
            state.last[c] = patch_orders[c];
            lines[c] = " " + std::to_string(c) + ": " + std::to_string(stats.arc_count) + " arcs, greedy " +
                       std::to_string(stats.greedy_weight) + (stats.from_previous ? ", current " : ", start ") +
                       std::to_string(stats.start_weight) + ", sifted " + std::to_string(stats.final_weight) + ";";
        });
    });
    std::string line;
    for (const std::string& l : lines) line += l;
    if (settings.log)
        settings.log("measured graphs: " + std::to_string(moved) + " nodes counted in " +
                     std::to_string(graph_seconds) + " s, orders in " + std::to_string(seconds_since(order_start)) +
                     " s; backward weights per cluster:" + line);
    return sizes;
}

}  // namespace animorder
