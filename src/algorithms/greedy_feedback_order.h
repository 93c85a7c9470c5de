// The greedy minimum feedback-arc-set heuristic over any adjacency: Eades, Lin & Smyth, "A fast
// and effective heuristic for the feedback arc set problem" (Information Processing Letters 47,
// 1993), as Skiena, The Algorithm Design Manual (1997), gives it, with the weighted rule of Nehab,
// Barczak & Sander (I3D 2006, §5). order_feedback_arc_set (feedback_arc_set.cpp) runs it over an
// array of arcs; `measured` over the signed adjacency its sifting searches (measured_order.cpp),
// so no array of arcs is kept beside it. Internal to the algorithm layer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <set>
#include <utility>
#include <vector>

namespace animorder {

// The order of nodes 0..n−1 (order_feedback_arc_set's rule and tie-breaks): for_out(v, f) calls
// f(to, weight) for each arc v→to, for_in(v, f) calls f(from, weight) for each arc from→v, each in
// a fixed order (the order sources and sinks are found in), weights > 0, no self-loops.
template <typename ForOut, typename ForIn>
std::vector<uint32_t> greedy_feedback_order(size_t n, ForOut&& for_out, ForIn&& for_in) {
    std::vector<size_t> out_degree(n, 0), in_degree(n, 0);
    std::vector<int64_t> delta(n, 0);  // Σ out-weights − Σ in-weights of remaining arcs
    for (size_t v = 0; v < n; ++v) {
        for_out(uint32_t(v), [&](uint32_t, uint64_t weight) {
            ++out_degree[v];
            delta[v] += int64_t(weight);
        });
        for_in(uint32_t(v), [&](uint32_t, uint64_t weight) {
            ++in_degree[v];
            delta[v] -= int64_t(weight);
        });
    }
    // The greedy choice: largest |δ|, then lowest id.
    auto key = [&](uint32_t v) { return std::make_pair(-(delta[v] < 0 ? -delta[v] : delta[v]), v); };
    std::set<std::pair<int64_t, uint32_t>> candidates;
    for (uint32_t v = 0; v < n; ++v) candidates.insert(key(v));

    std::vector<bool> removed(n, false);
    std::deque<uint32_t> sinks, sources;
    for (uint32_t v = 0; v < n; ++v) {
        if (out_degree[v] == 0)
            sinks.push_back(v);
        else if (in_degree[v] == 0)
            sources.push_back(v);
    }
    std::vector<uint32_t> head, tail;  // order = head, then tail reversed
    auto remove = [&](uint32_t v) {
        removed[v] = true;
        candidates.erase(key(v));
        for_out(v, [&](uint32_t to, uint64_t weight) {
            if (removed[to]) return;
            candidates.erase(key(to));
            delta[to] += int64_t(weight);
            candidates.insert(key(to));
            if (--in_degree[to] == 0 && out_degree[to] != 0) sources.push_back(to);
        });
        for_in(v, [&](uint32_t from, uint64_t weight) {
            if (removed[from]) return;
            candidates.erase(key(from));
            delta[from] -= int64_t(weight);
            candidates.insert(key(from));
            if (--out_degree[from] == 0) sinks.push_back(from);
        });
    };
    size_t left = n;
    while (left > 0) {
        bool progress = true;
        while (progress) {
            progress = false;
            while (!sinks.empty()) {
                const uint32_t v = sinks.front();
                sinks.pop_front();
                if (removed[v]) continue;
                tail.push_back(v);
                remove(v);
                --left;
                progress = true;
            }
            while (!sources.empty()) {
                const uint32_t v = sources.front();
                sources.pop_front();
                if (removed[v]) continue;
                if (out_degree[v] == 0) {  // became a sink meanwhile: the sinks' loop takes it
                    sinks.push_back(v);
                    progress = true;
                    break;
                }
                head.push_back(v);
                remove(v);
                --left;
                progress = true;
                if (!sinks.empty()) break;  // sinks first, as the heuristic says
            }
        }
        if (left == 0) break;
        // Only cycles remain: the node with the largest |δ| goes to its winning side.
        const uint32_t v = candidates.begin()->second;
        if (delta[v] >= 0)
            head.push_back(v);
        else
            tail.push_back(v);
        remove(v);
        --left;
    }
    head.insert(head.end(), tail.rbegin(), tail.rend());
    return head;
}

}  // namespace animorder
