// Scoring triangle orders over many nodes: the measurement behind Han & Sander 2017 §3 (node
// assignment by measured overdraw) and every OVR in the reports.
//
// Nodes are independent, so they run in parallel (oneTBB). Each worker keeps one rasteriser and
// one clip-space buffer and writes each node's counts into that node's own slot: the numbers do
// not depend on the thread count or on scheduling, and memory grows with the workers, not with
// the nodes.
#include "animorder/overdraw.h"
#include "animorder/facing_filter.h"

#include "animorder/animated_mesh.h"
#include "animorder/camera.h"
#include "animorder/invalid_input.h"
#include "animorder/rasterizer.h"
#include "animorder/triangle_order.h"
#include "animorder/viewpoints.h"
#include "../support/worker_threads.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <string>

namespace animorder {

namespace {

// Calls settings.progress now and then (about every 1% of the nodes, and at the end), from any
// worker, never two at once.
class ProgressCounter {
public:
    ProgressCounter(const std::function<void(size_t, size_t)>& report, size_t total)
        : report_(report), total_(total), every_(std::max<size_t>(1, total / 100)) {}
    void node_done() {
        const size_t finished = ++done_;
        if (report_ && (finished % every_ == 0 || finished == total_)) {
            std::lock_guard<std::mutex> lock(mutex_);
            report_(finished, total_);
        }
    }

private:
    const std::function<void(size_t, size_t)>& report_;
    size_t total_, every_;
    std::atomic<size_t> done_{0};
    std::mutex mutex_;
};

// One worker's rasteriser: a node rasterised from its keyframe's positions moved to the frame's
// centre (done once for the keyframe's views; the rasteriser transforms them to clip space in its
// vertex pass, as transform_to_clip would) and from the facing filter's candidates (built again
// when the keyframe changes; the same fragments as from every triangle).
struct NodeWorker {
    NodeRasterizer rasterizer;
    CentredKeyframe centred;
    FacingFilter facing;

    void rasterize(const float* keyframe_positions, size_t vertex_count, const Framing& framing,
                   const uint32_t* indices, size_t index_count, const OverdrawNode& node,
                   const ScoreSettings& settings) {
        const float* keyframe = keyframe_positions + size_t(node.keyframe) * vertex_count * 3;
        const float* centre = framing.centres.data() + 3 * size_t(node.keyframe);
        centred.centre(keyframe, vertex_count, centre);
        facing.build_for(node.keyframe, keyframe, vertex_count, indices, index_count, centre, framing.radius,
                         settings.resolution, settings.triangle_modes);
        const FacingFilter::Candidates candidates = facing.candidates(node.direction);
        rasterizer.rasterize_validated(centred.vertices(node_view_projection(node.direction, framing.radius)),
                                       vertex_count, indices, index_count, settings.resolution, settings.triangle_modes,
                                       candidates.ids, candidates.count);
    }
};

}  // namespace

std::vector<uint8_t> opaque_pass_modes(const AnimatedMesh& mesh) {
    std::vector<uint8_t> modes(mesh.triangle_count(), 0);
    bool any = false;
    for (const Primitive& p : mesh.primitives) {
        const uint8_t mode =
            uint8_t((p.double_sided ? kDrawBothFaces : 0) | (p.alpha_mode == AlphaMode::Blend ? kSkipTriangle : 0));
        any = any || mode;
        for (size_t t = p.first_index / 3; t < (p.first_index + p.index_count) / 3 && t < modes.size(); ++t)
            modes[t] = mode;
    }
    if (!any) modes.clear();
    return modes;
}

std::vector<uint8_t> full_pass_modes(const AnimatedMesh& mesh) { return double_sided_triangles(mesh); }

std::vector<uint8_t> blended_triangles(const AnimatedMesh& mesh) {
    std::vector<uint8_t> blended(mesh.triangle_count(), 0);
    for (const Primitive& p : mesh.primitives)
        if (p.alpha_mode == AlphaMode::Blend)
            std::fill(blended.begin() + ptrdiff_t(p.first_index / 3),
                      blended.begin() + ptrdiff_t((p.first_index + p.index_count) / 3), 1);
    return blended;
}

std::vector<uint32_t> make_rank_table(const std::vector<const uint32_t*>& orders, size_t triangle_count) {
    const size_t k = orders.size();
    std::vector<uint32_t> ranks(triangle_count * k);
    for (size_t o = 0; o < k; ++o) {
        validate_triangle_order(orders[o], triangle_count);
        for (size_t i = 0; i < triangle_count; ++i) ranks[size_t(orders[o][i]) * k + o] = uint32_t(i);
    }
    return ranks;
}

void score_nodes(uint64_t* visible, uint64_t* passed, const float* keyframe_positions, size_t vertex_count,
                 const Framing& framing, const uint32_t* indices, size_t index_count, const OverdrawNode* nodes,
                 size_t node_count, const uint32_t* ranks, size_t order_count, const ScoreSettings& settings) {
    validate_indices(indices, index_count, vertex_count);
    const size_t keyframes = framing.centres.size() / 3;
    for (size_t n = 0; n < node_count; ++n)
        if (nodes[n].keyframe >= keyframes)
            throw InvalidInput("node " + std::to_string(n) + " names keyframe " + std::to_string(nodes[n].keyframe) +
                               ", but there are " + std::to_string(keyframes));

    tbb::enumerable_thread_specific<NodeWorker> workers;
    ProgressCounter progress(settings.progress, node_count);

    auto body = [&](const tbb::blocked_range<size_t>& range) {
        NodeWorker& w = workers.local();
        for (size_t n = range.begin(); n != range.end(); ++n) {
            w.rasterize(keyframe_positions, vertex_count, framing, indices, index_count, nodes[n], settings);
            visible[n] = w.rasterizer.visible_pixels();
            w.rasterizer.score(passed + n * order_count, ranks, order_count);
            progress.node_done();
        }
    };
    const int threads = worker_threads(settings.threads);
    tbb::task_arena arena(threads);
    arena.execute([&] { tbb::parallel_for(tbb::blocked_range<size_t>(0, node_count, 1), body); });
}

std::vector<NodeFragments> rasterize_nodes(const float* keyframe_positions, size_t vertex_count, const Framing& framing,
                                           const uint32_t* indices, size_t index_count, const OverdrawNode* nodes,
                                           size_t node_count, const ScoreSettings& settings, size_t max_bytes) {
    validate_indices(indices, index_count, vertex_count);
    const size_t keyframes = framing.centres.size() / 3;
    for (size_t n = 0; n < node_count; ++n)
        if (nodes[n].keyframe >= keyframes)
            throw InvalidInput("node " + std::to_string(n) + " names a missing keyframe");

    std::vector<NodeFragments> kept(node_count);
    // The total is the same whatever the schedule, so whether it fits is decided deterministically.
    std::atomic<size_t> total{0};
    std::atomic<bool> too_big{false};
    ProgressCounter progress(settings.progress, node_count);
    tbb::enumerable_thread_specific<NodeWorker> workers;
    auto body = [&](const tbb::blocked_range<size_t>& range) {
        NodeWorker& w = workers.local();
        for (size_t n = range.begin(); n != range.end() && !too_big; ++n) {
            w.rasterize(keyframe_positions, vertex_count, framing, indices, index_count, nodes[n], settings);
            kept[n] = w.rasterizer.export_fragments();
            if ((total += kept[n].bytes()) > max_bytes) too_big = true;
            progress.node_done();
        }
    };
    const int threads = worker_threads(settings.threads);
    tbb::task_arena arena(threads);
    arena.execute([&] { tbb::parallel_for(tbb::blocked_range<size_t>(0, node_count, 1), body); });
    if (too_big) return {};
    return kept;
}

void score_kept_nodes(uint64_t* visible, uint64_t* passed, const std::vector<NodeFragments>& nodes,
                      const uint32_t* ranks, size_t order_count, const ScoreSettings& settings) {
    const int threads = worker_threads(settings.threads);
    tbb::task_arena arena(threads);
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, nodes.size(), 64),
                          [&](const tbb::blocked_range<size_t>& range) {
                              for (size_t n = range.begin(); n != range.end(); ++n) {
                                  visible[n] = nodes[n].visible;
                                  score_fragments(passed + n * order_count, nodes[n], ranks, order_count);
                              }
                          });
    });
    if (settings.progress) settings.progress(nodes.size(), nodes.size());
}

struct NodeCache::Worker {
    NodeWorker node;
    KeepScratch scratch;
};

template <typename Body>
void NodeCache::for_nodes(size_t count, size_t grain, Body&& body) const {
    tbb::enumerable_thread_specific<Worker> workers;
    const int threads = worker_threads(settings_.threads);
    tbb::task_arena arena(threads);
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, count, grain), [&](const tbb::blocked_range<size_t>& range) {
            Worker& w = workers.local();
            for (size_t i = range.begin(); i != range.end(); ++i) body(w, i);
        });
    });
}

void NodeCache::rasterize_node(Worker& w, size_t n) const {
    w.node.rasterize(positions_, vertex_count_, framing_, indices_, index_count_, nodes_[n], settings_);
}

NodeCache::NodeCache(const float* keyframe_positions, size_t vertex_count, const Framing& framing,
                     const uint32_t* indices, size_t index_count, const OverdrawNode* nodes, size_t node_count,
                     UnitPartition partition, const ScoreSettings& settings, size_t max_bytes)
    : positions_(keyframe_positions),
      vertex_count_(vertex_count),
      framing_(framing),
      indices_(indices),
      index_count_(index_count),
      nodes_(nodes),
      node_count_(node_count),
      partition_(std::move(partition)),
      settings_(settings) {
    validate_indices(indices, index_count, vertex_count);
    if (partition_.unit_of_triangle.size() != index_count / 3)
        throw InvalidInput("node cache: the unit partition covers " +
                           std::to_string(partition_.unit_of_triangle.size()) + " triangles, the mesh has " +
                           std::to_string(index_count / 3));
    const size_t keyframes = framing.centres.size() / 3;
    for (size_t n = 0; n < node_count; ++n)
        if (nodes[n].keyframe >= keyframes)
            throw InvalidInput("node " + std::to_string(n) + " names a missing keyframe");
    // In chunks sized by the budget left, at the mean size of the nodes rasterised so far, so that
    // memory holds about the budget (and never rasterises a node only to drop it once the budget
    // is spent). Which nodes are kept, the longest run in node order whose total fits, depends on
    // their sizes only, never on the chunks or the schedule.
    const size_t least = size_t(worker_threads(settings.threads));
    std::vector<KeptNode> batch;
    bool full = false;
    size_t begin = 0;
    while (begin < node_count && !full && kept_bytes_ < max_bytes) {
        const size_t count = std::min(
            node_count - begin, nodes_within(max_bytes - kept_bytes_, sampled_bytes_, sampled_nodes_, least, 2048));
        batch.assign(count, KeptNode{});
        for_nodes(count, 1, [&](Worker& w, size_t i) {
            rasterize_node(w, begin + i);
            const NodeRasterizer::FragmentLists l = w.node.rasterizer.fragment_lists();
            batch[i] = keep_fragments(l.visible, l.single, l.starts, l.pixels, l.fragments, partition_, w.scratch);
        });
        for (KeptNode& node : batch) {
            sampled_bytes_ += node.bytes();
            ++sampled_nodes_;
            if (full || kept_bytes_ + node.bytes() > max_bytes) {
                full = true;
                continue;
            }
            kept_bytes_ += node.bytes();
            kept_.push_back(std::move(node));
        }
        begin += count;
        if (settings.progress) settings.progress(full ? node_count : begin, node_count);
    }
}

size_t nodes_within(uint64_t bytes, uint64_t sampled_bytes, uint64_t sampled_nodes, size_t least, size_t most) {
    least = std::max<size_t>(1, std::min(least, most));
    if (sampled_nodes == 0) return least;
    const uint64_t mean = std::max<uint64_t>(1, sampled_bytes / sampled_nodes);
    return size_t(std::clamp<uint64_t>(bytes / mean + 1, least, most));
}

NodeCache::~NodeCache() = default;

void NodeCache::score(uint64_t* visible, uint64_t* passed, const uint32_t* ranks, size_t order_count) const {
    const std::vector<uint16_t> unit_ranks = make_unit_rank_table(ranks, order_count, partition_);
    ProgressCounter progress(settings_.progress, node_count_);
    for_nodes(node_count_, 64, [&](Worker& w, size_t n) {
        if (const KeptNode* k = kept(n)) {
            visible[n] = k->visible;
            score_kept(passed + n * order_count, *k, unit_ranks.data(), ranks, order_count);
        } else {
            rasterize_node(w, n);
            visible[n] = w.node.rasterizer.visible_pixels();
            w.node.rasterizer.score(passed + n * order_count, ranks, order_count);
        }
        progress.node_done();
    });
}

std::vector<KeptNode> NodeCache::rasterize_again(const uint32_t* which, size_t count) const {
    std::vector<KeptNode> out(count);
    for_nodes(count, 1, [&](Worker& w, size_t i) {
        if (which[i] >= node_count_) throw InvalidInput("node cache: no node " + std::to_string(which[i]));
        rasterize_node(w, which[i]);
        const NodeRasterizer::FragmentLists l = w.node.rasterizer.fragment_lists();
        out[i] = keep_fragments(l.visible, l.single, l.starts, l.pixels, l.fragments, partition_, w.scratch);
    });
    return out;
}

}  // namespace animorder
