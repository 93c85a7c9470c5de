// static-nehab06: view-independent cluster order from a partial-order graph of measured overdraw.
//
// This follows: Nehab, Barczak & Sander, "Triangle Order Optimization for Graphics Hardware
// Computation Culling", I3D 2006:
//   §3  planar clusters (planar_clusters.cpp), each optimised for vertex locality (Tipsify here);
//   §4  the partial-order graph: for clusters a and b, an arc a→b when drawing a before b
//       generates fewer pixels than b before a over a set of viewpoints (the icosphere's), weighted
//       by the net difference; no arc when both orders generate the same number;
//   §5  the cluster order: a topological sort when the graph is acyclic, otherwise the greedy
//       minimum feedback-arc-set heuristic (Skiena 1997, after Eades, Lin & Smyth 1993) removing
//       sources and sinks, and when only cycles remain the node with the greatest absolute
//       difference between its outgoing and incoming weights, placed on the winning side;
//   §6  the number of clusters: successive powers of two until the overdraw stops improving.
//
// Where this differs from the paper, and why:
// - The paper renders each pair of clusters with occlusion queries (O(n²) draws per view, pairs
//   with disjoint screen boxes skipped). Here each view is rasterised once, keeping every pixel's
//   fragments sorted by depth (overdraw.h); a pair's two draws are then replayed exactly from the
//   fragments of the pixels where both clusters appear, so the cost follows the fragments, not n².
//   A pixel's contribution for a before b, with P_c the fragments of c that pass when c is drawn
//   alone (in its own Tipsify order), m_c its nearest depth and Q_c(d) those of c's passing
//   fragments nearer than d, is passed(a, b) = P_a + Q_b(m_a): the saving of a before b is
//   P_b + Q_a(m_b) − P_a − Q_b(m_a). Equal depths never pass (LESS), as in the engine.
// - The camera is DESIGN.md's perspective camera at 3R (the paper used an orthographic one, and
//   notes the target application's camera is the better choice), at 256² instead of 512².
// - For an animated mesh the graph sums over the listed keyframes (each framed on its own centre,
//   R the largest radius over them), so one buffer serves the whole animation.
// Views run in parallel (oneTBB); each worker sums into its own integer matrix and the matrices
// are added at the end, so the graph is identical for any thread count.
#include "animorder/nehab06.h"

#include "animorder/camera.h"
#include "animorder/invalid_input.h"
#include "animorder/overdraw.h"
#include "animorder/planar_clusters.h"
#include "animorder/rasterizer.h"
#include "animorder/tipsify.h"
#include "animorder/triangle_order.h"
#include "animorder/vertex_cache.h"
#include "animorder/viewpoints.h"

#include "../overdraw/fragment_encoding.h"
#include "../support/stopwatch.h"
#include "../support/worker_threads.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

namespace animorder {
namespace {

constexpr size_t kMaxKeptBytes = size_t(1) << 30;  // keep node fragments across candidates below 1 GiB

size_t pair_index(size_t a, size_t b, size_t n) {  // a < b < n, row-major upper triangle
    return a * (2 * n - a - 1) / 2 + (b - a - 1);
}

// Per-worker scratch and sums for the graph.
struct GraphWorker {
    std::vector<int64_t> sums;  // pair_index(a, b): fragments saved by drawing a before b
    struct Fragment {
        uint32_t cluster, rank, group;
    };
    std::vector<Fragment> pixel;
    std::vector<uint32_t> passes;  // depth groups of passing fragments, per cluster run
    struct Run {
        uint32_t cluster, begin, end;  // passes[begin, end): decreasing groups; last is the nearest
    };
    std::vector<Run> runs;
};

// Adds one node's pair savings to w.sums. cluster_of and rank are per triangle; rank orders the
// triangles inside each cluster.
void accumulate_node(GraphWorker& w, const NodeFragments& node, const uint32_t* cluster_of, const uint32_t* rank,
                     size_t cluster_count) {
    if (node.starts.size() < 2) return;
    const size_t pixels = node.starts.size() - 1;
    for (size_t p = 0; p < pixels; ++p) {
        const uint32_t* f = node.fragments.data() + node.starts[p];
        const uint32_t n = node.starts[p + 1] - node.starts[p];
        const uint32_t first_cluster = cluster_of[f[0] & kTriangleMask];
        bool mixed = false;
        for (uint32_t j = 1; j < n && !mixed; ++j) mixed = cluster_of[f[j] & kTriangleMask] != first_cluster;
        if (!mixed) continue;
        w.pixel.clear();
        uint32_t group = 0;
        for (uint32_t j = 0; j < n; ++j) {
            if (j > 0 && !(f[j] & kTieBit)) ++group;
            const uint32_t t = f[j] & kTriangleMask;
            w.pixel.push_back({cluster_of[t], rank[t], group});
        }
        // Few fragments per pixel: insertion sort by (cluster, rank).
        for (size_t i = 1; i < w.pixel.size(); ++i) {
            const GraphWorker::Fragment x = w.pixel[i];
            size_t j = i;
            for (; j > 0 && (w.pixel[j - 1].cluster > x.cluster ||
                             (w.pixel[j - 1].cluster == x.cluster && w.pixel[j - 1].rank > x.rank));
                 --j)
                w.pixel[j] = w.pixel[j - 1];
            w.pixel[j] = x;
        }
        // Each cluster drawn alone: a fragment passes when it is nearer than all drawn before it.
        w.passes.clear();
        w.runs.clear();
        for (size_t i = 0; i < w.pixel.size();) {
            const uint32_t c = w.pixel[i].cluster;
            GraphWorker::Run run{c, uint32_t(w.passes.size()), 0};
            uint32_t nearest = std::numeric_limits<uint32_t>::max();
            for (; i < w.pixel.size() && w.pixel[i].cluster == c; ++i)
                if (w.pixel[i].group < nearest) {
                    nearest = w.pixel[i].group;
                    w.passes.push_back(nearest);
                }
            run.end = uint32_t(w.passes.size());
            w.runs.push_back(run);
        }
        auto nearer_passes = [&](const GraphWorker::Run& r, uint32_t depth) {  // Q_r(depth)
            int64_t q = 0;
            for (uint32_t i = r.end; i > r.begin && w.passes[i - 1] < depth; --i) ++q;
            return q;
        };
        for (size_t x = 0; x < w.runs.size(); ++x)
            for (size_t y = x + 1; y < w.runs.size(); ++y) {
                const GraphWorker::Run &a = w.runs[x], &b = w.runs[y];
                const int64_t pa = a.end - a.begin, pb = b.end - b.begin;
                const uint32_t ma = w.passes[a.end - 1], mb = w.passes[b.end - 1];
                const int64_t saving = (pb + nearer_passes(a, mb)) - (pa + nearer_passes(b, ma));
                if (saving) w.sums[pair_index(a.cluster, b.cluster, cluster_count)] += saving;
            }
    }
}

struct Nodes {
    Framing framing;
    std::vector<OverdrawNode> list;
};

Nodes make_nodes(const uint32_t* indices, size_t index_count, const float* keyframe_positions, size_t keyframe_count,
                 size_t vertex_count, const std::vector<uint32_t>& keyframes, size_t views) {
    Nodes nodes;
    const std::vector<float> directions = icosphere_directions(icosphere_subdivisions_for(views));
    nodes.framing = frame_subset(
        frame_keyframes(keyframe_positions, keyframe_count, vertex_count, indices, index_count), keyframes);
    // Keyframes that shrink the mesh (or a primitive framed on its own) to a point draw nothing from
    // any view: no node, no arc (and no camera at 3R = 0).
    if (nodes.framing.shows_nothing()) return nodes;
    for (uint32_t k : keyframes)
        for (size_t v = 0; v < directions.size() / 3; ++v) {
            OverdrawNode node;
            node.keyframe = k;
            for (int i = 0; i < 3; ++i) node.direction[i] = directions[3 * v + size_t(i)];
            nodes.list.push_back(node);
        }
    return nodes;
}

std::vector<uint32_t> checked_keyframes(const uint32_t* keyframes, size_t keyframe_list_count, size_t keyframe_count,
                                        const float* keyframe_positions, size_t vertex_count, const uint32_t* indices,
                                        size_t index_count) {
    if (!keyframe_positions || keyframe_count == 0) throw InvalidInput("static-nehab06 needs keyframe positions");
    if (keyframe_list_count && !keyframes) throw InvalidInput("static-nehab06: the keyframe list is missing");
    std::vector<uint32_t> list(keyframes, keyframes + keyframe_list_count);
    if (list.empty()) list.push_back(0);
    for (uint32_t k : list) {
        if (k >= keyframe_count)
            throw InvalidInput("static-nehab06: keyframe " + std::to_string(k) + " does not exist (there are " +
                               std::to_string(keyframe_count) + ")");
        const float* p = keyframe_positions + size_t(k) * vertex_count * 3;
        for (size_t i = 0; i < index_count; ++i)
            for (int c = 0; c < 3; ++c)
                if (!std::isfinite(p[3 * size_t(indices[i]) + size_t(c)]))
                    throw InvalidInput("static-nehab06: vertex " + std::to_string(indices[i]) + " of keyframe " +
                                       std::to_string(k) + " has a non-finite position");
    }
    return list;
}

void check_graph_settings(size_t views, unsigned resolution, size_t cluster_count) {
    icosphere_subdivisions_for(views);  // throws for a count that is no icosphere
    if (resolution == 0 || resolution > 8192)
        throw InvalidInput("static-nehab06: resolution " + std::to_string(resolution) + " is outside 1..8192");
    if (cluster_count > kMaxNehabClusters)
        throw InvalidInput("static-nehab06: " + std::to_string(cluster_count) + " clusters is more than the " +
                           std::to_string(kMaxNehabClusters) + " the graph allows");
}

// The fragments of every node: kept (when they fit) or rasterised again on each pass.
class NodeSource {
public:
    NodeSource(const uint32_t* indices, size_t index_count, const float* keyframe_positions, size_t vertex_count,
               Nodes nodes, unsigned resolution, unsigned threads, bool keep, const uint8_t* triangle_modes = nullptr)
        : indices_(indices),
          index_count_(index_count),
          positions_(keyframe_positions),
          vertex_count_(vertex_count),
          nodes_(std::move(nodes)) {
        settings_.resolution = resolution;
        settings_.threads = threads;
        settings_.triangle_modes = triangle_modes;
        if (keep)
            kept_ = rasterize_nodes(positions_, vertex_count_, nodes_.framing, indices_, index_count_,
                                    nodes_.list.data(), nodes_.list.size(), settings_, kMaxKeptBytes);
    }
    int threads() const { return worker_threads(settings_.threads); }
    size_t size() const { return nodes_.list.size(); }

    // The graph's pair sums over every node.
    std::vector<int64_t> pair_sums(const uint32_t* cluster_of, const uint32_t* rank, size_t cluster_count,
                                   double& seconds_rasterization) const {
        const size_t pairs = cluster_count * (cluster_count - 1) / 2;
        struct Worker {
            GraphWorker graph;
            NodeRasterizer rasterizer;
            CentredKeyframe centred;  // the keyframe last drawn's
            double seconds_raster = 0;
        };
        tbb::enumerable_thread_specific<Worker> workers;
        auto body = [&](const tbb::blocked_range<size_t>& range) {
            Worker& w = workers.local();
            w.graph.sums.resize(pairs, 0);
            for (size_t n = range.begin(); n != range.end(); ++n) {
                if (!kept_.empty()) {
                    accumulate_node(w.graph, kept_[n], cluster_of, rank, cluster_count);
                    continue;
                }
                const Clock::time_point start = Clock::now();
                const OverdrawNode& node = nodes_.list[n];
                w.centred.centre(positions_ + size_t(node.keyframe) * vertex_count_ * 3, vertex_count_,
                                 nodes_.framing.centres.data() + 3 * size_t(node.keyframe));
                // The indices were checked once (order_static_nehab06).
                w.rasterizer.rasterize_validated(
                    w.centred.vertices(node_view_projection(node.direction, nodes_.framing.radius)), vertex_count_,
                    indices_, index_count_, settings_.resolution, settings_.triangle_modes);
                const NodeFragments fragments = w.rasterizer.export_fragments();
                w.seconds_raster += seconds_since(start);
                accumulate_node(w.graph, fragments, cluster_of, rank, cluster_count);
            }
        };
        tbb::task_arena arena(threads());
        arena.execute([&] { tbb::parallel_for(tbb::blocked_range<size_t>(0, nodes_.list.size(), 1), body); });
        std::vector<int64_t> sums(pairs, 0);
        double raster = 0;
        for (const Worker& w : workers) {  // integer sums: the worker order does not matter
            for (size_t i = 0; i < w.graph.sums.size(); ++i) sums[i] += w.graph.sums[i];
            raster = std::max(raster, w.seconds_raster);  // wall time, workers run side by side
        }
        seconds_rasterization += raster;
        return sums;
    }

    // Mean OVR of one order over every node.
    double mean_ovr(const uint32_t* order, size_t triangle_count) const {
        const std::vector<uint32_t> ranks = make_rank_table({order}, triangle_count);
        std::vector<uint64_t> visible(size()), passed(size());
        if (!kept_.empty())
            score_kept_nodes(visible.data(), passed.data(), kept_, ranks.data(), 1, settings_);
        else
            score_nodes(visible.data(), passed.data(), positions_, vertex_count_, nodes_.framing, indices_,
                        index_count_, nodes_.list.data(), nodes_.list.size(), ranks.data(), 1, settings_);
        double sum = 0;
        size_t counted = 0;
        for (size_t n = 0; n < size(); ++n)
            if (visible[n]) {
                sum += double(passed[n]) / double(visible[n]);
                ++counted;
            }
        return counted ? sum / double(counted) : 1.0;
    }
    bool kept() const { return !kept_.empty(); }

private:
    const uint32_t* indices_;
    size_t index_count_;
    const float* positions_;
    size_t vertex_count_;
    Nodes nodes_;
    ScoreSettings settings_;
    std::vector<NodeFragments> kept_;
};

std::vector<Arc> arcs_from_sums(const std::vector<int64_t>& sums, size_t cluster_count) {
    std::vector<Arc> arcs;
    for (size_t a = 0; a < cluster_count; ++a)
        for (size_t b = a + 1; b < cluster_count; ++b) {
            const int64_t s = sums[pair_index(a, b, cluster_count)];
            if (s > 0) arcs.push_back({uint32_t(a), uint32_t(b), uint64_t(s)});
            if (s < 0) arcs.push_back({uint32_t(b), uint32_t(a), uint64_t(-s)});
        }
    return arcs;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

std::vector<Arc> build_overdraw_graph(const uint32_t* indices, size_t index_count, const float* keyframe_positions,
                                      size_t keyframe_count, size_t vertex_count, const uint32_t* keyframes,
                                      size_t keyframe_list_count, const uint32_t* cluster_of, size_t cluster_count,
                                      const uint32_t* draw_order, const OverdrawGraphSettings& settings) {
    validate_indices(indices, index_count, vertex_count);
    check_graph_settings(settings.views, settings.resolution, cluster_count);
    const size_t triangles = index_count / 3;
    if (triangles == 0 || cluster_count < 2) return {};
    validate_triangle_order(draw_order, triangles);
    for (size_t t = 0; t < triangles; ++t)
        if (cluster_of[t] >= cluster_count)
            throw InvalidInput("overdraw graph: triangle " + std::to_string(t) + " is in cluster " +
                               std::to_string(cluster_of[t]) + ", but there are " + std::to_string(cluster_count));
    const std::vector<uint32_t> list = checked_keyframes(keyframes, keyframe_list_count, keyframe_count,
                                                         keyframe_positions, vertex_count, indices, index_count);
    std::vector<uint32_t> rank(triangles);
    for (size_t i = 0; i < triangles; ++i) rank[draw_order[i]] = uint32_t(i);
    const NodeSource source(
        indices, index_count, keyframe_positions, vertex_count,
        make_nodes(indices, index_count, keyframe_positions, keyframe_count, vertex_count, list, settings.views),
        settings.resolution, settings.threads, false);
    double raster = 0;
    return arcs_from_sums(source.pair_sums(cluster_of, rank.data(), cluster_count, raster), cluster_count);
}

namespace {

// One candidate order for a given number of clusters (§3–§5), and what the search compares.
struct Candidate {
    std::vector<uint32_t> order;  // face permutation
    double acmr = 0;              // of its clusters Tipsified
    size_t clusters = 0, arcs = 0;
    FeedbackArcs feedback;
};

// Builds candidates for any cluster count from the same mesh, nodes and clusterer; the time of
// each stage adds to the result's timings.
struct CandidateBuilder {
    const uint32_t* indices;
    size_t index_count;
    size_t vertex_count;
    unsigned cache_size;
    const NodeSource& source;
    PlanarClusterer& clusterer;
    Nehab06Result& result;

    Candidate build(size_t wanted) const {
        const size_t triangles = index_count / 3;
        Candidate c;
        c.clusters = std::min(wanted, triangles);

        // §3: planar clusters, each Tipsified on its own; the ACMR of the clusters in id order
        // (the cluster order changes it little).
        Clock::time_point t0 = Clock::now();
        const std::vector<uint32_t> cluster_of = clusterer.cluster(c.clusters);
        std::vector<uint32_t> grouped(triangles);
        const std::vector<uint32_t> starts = tipsify_clusters(grouped.data(), indices, index_count, vertex_count,
                                                              cluster_of.data(), c.clusters, cache_size);
        {
            std::vector<uint32_t> buffer(index_count);
            apply_triangle_order(buffer.data(), indices, grouped.data(), triangles);
            c.acmr = analyze_vertex_cache(buffer.data(), index_count, vertex_count, cache_size).acmr;
        }
        result.seconds_clustering += seconds_since(t0);

        // §4: the partial-order graph from the pair sums over every node.
        t0 = Clock::now();
        std::vector<uint32_t> rank(triangles);
        for (size_t i = 0; i < triangles; ++i) rank[grouped[i]] = uint32_t(i);
        std::vector<Arc> arcs;
        if (c.clusters > 1)
            arcs = arcs_from_sums(
                source.pair_sums(cluster_of.data(), rank.data(), c.clusters, result.seconds_rasterization), c.clusters);
        result.seconds_graph += seconds_since(t0);

        // §5: the cluster order (feedback arc set), then each cluster's triangles in Tipsify order.
        t0 = Clock::now();
        const std::vector<uint32_t> cluster_order = order_feedback_arc_set(c.clusters, arcs.data(), arcs.size());
        c.arcs = arcs.size();
        c.feedback = count_feedback_arcs(cluster_order.data(), c.clusters, arcs.data(), arcs.size());
        c.order.reserve(triangles);
        for (uint32_t cluster : cluster_order)
            c.order.insert(c.order.end(), grouped.begin() + starts[cluster], grouped.begin() + starts[cluster + 1]);
        result.seconds_ordering += seconds_since(t0);
        return c;
    }
};

double tipsify_acmr(const uint32_t* indices, size_t index_count, size_t vertex_count, unsigned cache_size) {
    std::vector<uint32_t> buffer(index_count);
    tipsify_index_buffer(buffer.data(), indices, index_count, vertex_count, cache_size);
    return analyze_vertex_cache(buffer.data(), index_count, vertex_count, cache_size).acmr;
}

// The automatic cluster count, §6 ("an appropriate number of clusters can be found by trying the
// method on successive powers of two, until the average overdraw stops improving consistently";
// the rules are Nehab06Settings::clusters'): 2, 4, 8, ... clusters, each scored by its mean OVR
// over the nodes. Every eligible count goes into result.candidates; returns the chosen one.
Candidate search_cluster_count(const CandidateBuilder& builder, const PlanarClusterer& clusterer,
                               const NodeSource& source, Nehab06Result& result) {
    constexpr double kGain = 0.005;       // a doubling "improves" when it lowers the best by 0.5%
    constexpr double kAcmrBudget = 1.25;  // a count costing more than 1.25 × Tipsify's ACMR is out
    constexpr size_t kLargest = 1024;
    const size_t triangles = builder.index_count / 3;
    const size_t components = clusterer.component_count();
    Clock::time_point t0 = Clock::now();
    const double budget =
        kAcmrBudget * tipsify_acmr(builder.indices, builder.index_count, builder.vertex_count, builder.cache_size);
    result.seconds_selection += seconds_since(t0);

    std::vector<Candidate> tried;
    double best = std::numeric_limits<double>::infinity();
    int stalled = 0;
    for (size_t k = 2;; k *= 2) {
        Candidate c = builder.build(k);
        if (c.acmr > budget && !tried.empty()) break;  // over the ACMR budget: not eligible, stop
        t0 = Clock::now();
        const double ovr = source.mean_ovr(c.order.data(), triangles);
        result.seconds_selection += seconds_since(t0);
        result.candidates.push_back({c.clusters, ovr, c.acmr});
        tried.push_back(std::move(c));
        // The stopping rule: two doublings in a row without a gain of kGain on the best. Below the
        // component count clusters are unions of whole components: the mean OVR can sit on a
        // plateau there and fall once components split, so no stall counts.
        if (ovr < best * (1 - kGain) || k < components)
            stalled = 0;
        else
            ++stalled;
        best = std::min(best, ovr);
        if (stalled >= 2 || k >= kLargest || k >= triangles) break;
    }
    // The smallest count within kGain of the best mean OVR.
    size_t pick = 0;
    while (result.candidates[pick].mean_ovr > best * (1 + kGain)) ++pick;
    return std::move(tried[pick]);
}

}  // namespace

Nehab06Result order_static_nehab06(uint32_t* order, const uint32_t* indices, size_t index_count,
                                   const float* keyframe_positions, size_t keyframe_count, size_t vertex_count,
                                   const uint32_t* keyframes, size_t keyframe_list_count,
                                   const Nehab06Settings& settings) {
    validate_indices(indices, index_count, vertex_count);
    check_graph_settings(settings.views, settings.resolution, settings.clusters);
    if (settings.cache_size < 3) throw InvalidInput("static-nehab06: the cache needs at least 3 entries");
    Nehab06Result result;
    const size_t triangles = index_count / 3;
    if (triangles == 0) return result;
    const std::vector<uint32_t> list = checked_keyframes(keyframes, keyframe_list_count, keyframe_count,
                                                         keyframe_positions, vertex_count, indices, index_count);
    const float* cluster_positions = keyframe_positions + size_t(list[0]) * vertex_count * 3;
    const bool automatic = settings.clusters == 0;

    // The measuring nodes (§4's viewpoints, at every listed keyframe); their fragments are kept
    // when several candidates will replay them.
    Clock::time_point start = Clock::now();
    const NodeSource source(
        indices, index_count, keyframe_positions, vertex_count,
        make_nodes(indices, index_count, keyframe_positions, keyframe_count, vertex_count, list, settings.views),
        settings.resolution, settings.threads, automatic, settings.triangle_modes);
    if (source.kept()) result.seconds_rasterization = seconds_since(start);
    result.seconds_graph = result.seconds_rasterization;

    start = Clock::now();
    PlanarClusterer clusterer(indices, index_count, cluster_positions, vertex_count);
    result.seconds_clustering += seconds_since(start);

    const CandidateBuilder builder{indices, index_count, vertex_count, settings.cache_size, source, clusterer, result};
    const Candidate chosen =
        automatic ? search_cluster_count(builder, clusterer, source, result) : builder.build(settings.clusters);

    // The final order: the chosen candidate's faces.
    std::copy(chosen.order.begin(), chosen.order.end(), order);
    result.cluster_count = chosen.clusters;
    result.arc_count = chosen.arcs;
    result.feedback_arc_count = chosen.feedback.count;
    result.feedback_weight = double(chosen.feedback.weight);
    return result;
}

}  // namespace animorder
