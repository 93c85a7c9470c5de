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
#include "animorder/kept_fragments.h"
#include "animorder/rasterizer.h"
#include "animorder/viewpoints.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace animorder {

// ranks[t·order_count + o] = the position at which order o draws triangle t. Each orders[o] is a
// face permutation of triangle_count triangles (validated). Interleaved so that scoring reads one
// cache line per fragment for all orders.
std::vector<uint32_t> make_rank_table(const std::vector<const uint32_t*>& orders, size_t triangle_count);

// The opaque pass of a mesh (DESIGN.md "Materials"): double-sided primitives drawn without
// culling, blended ones skipped (they are drawn after, without depth writes, and ordered for
// blending). Empty when every triangle is single-sided and opaque (then pass nullptr).
std::vector<uint8_t> opaque_pass_modes(const AnimatedMesh& mesh);
// The transparent pass: every triangle drawn (the opaque ones for their depth), double-sided
// ones without culling. Empty when none is double-sided.
std::vector<uint8_t> full_pass_modes(const AnimatedMesh& mesh);
// 1 for every triangle of a blended primitive (AlphaMode::Blend), else 0: one entry per triangle.
std::vector<uint8_t> blended_triangles(const AnimatedMesh& mesh);

// One (keyframe, viewpoint): keyframe indexes the keyframe arrays, direction is a unit vector
// from the frame's centre towards the camera.
struct OverdrawNode {
    uint32_t keyframe = 0;
    float direction[3] = {0, 0, 1};
};

struct ScoreSettings {
    unsigned resolution = 256;
    unsigned threads = 0;  // 0: all hardware threads
    // Null, or one mode per triangle of the index list scored (kDrawBothFaces, kSkipTriangle:
    // NodeRasterizer::rasterize). Not owned: it must outlive the call.
    const uint8_t* triangle_modes = nullptr;
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
void score_kept_nodes(uint64_t* visible, uint64_t* passed, const std::vector<NodeFragments>& nodes,
                      const uint32_t* ranks, size_t order_count, const ScoreSettings& settings);

// The nodes of a k-means run, rasterised once and kept compactly (KeptNode) for any number of
// unit orders. Nodes are kept in node order while their total stays within max_bytes; the rest
// are rasterised again whenever they are scored. Either way a node's counts are the same, so the
// budget trades time for memory and never changes a result. The arrays must outlive the cache.
class NodeCache {
public:
    NodeCache(const float* keyframe_positions, size_t vertex_count, const Framing& framing, const uint32_t* indices,
              size_t index_count, const OverdrawNode* nodes, size_t node_count, UnitPartition partition,
              const ScoreSettings& settings, size_t max_bytes);
    ~NodeCache();
    NodeCache(const NodeCache&) = delete;
    NodeCache& operator=(const NodeCache&) = delete;

    size_t node_count() const { return node_count_; }
    size_t kept_count() const { return kept_.size(); }  // nodes [0, kept_count()) are kept
    size_t kept_bytes() const { return kept_bytes_; }
    // The nodes rasterised to fill the cache (kept, and the first that did not fit) and their
    // total KeptNode bytes: the sample nodes_within sizes later chunks by.
    uint64_t sampled_nodes() const { return sampled_nodes_; }
    uint64_t sampled_bytes() const { return sampled_bytes_; }
    const UnitPartition& partition() const { return partition_; }

    // visible[n] and passed[n · order_count + o] for every node and every order of the rank table
    // (make_rank_table over unit orders; InvalidInput for an order that splits a unit).
    void score(uint64_t* visible, uint64_t* passed, const uint32_t* ranks, size_t order_count) const;
    // Node n's KeptNode, or nullptr when it is not kept (n >= kept_count()).
    const KeptNode* kept(size_t n) const { return n < kept_.size() ? &kept_[n] : nullptr; }
    // KeptNodes of the nodes which[0..count), rasterised again (in parallel).
    std::vector<KeptNode> rasterize_again(const uint32_t* which, size_t count) const;

private:
    struct Worker;
    template <typename Body>
    void for_nodes(size_t count, size_t grain, Body&& body) const;
    void rasterize_node(Worker& w, size_t n) const;

    const float* positions_;
    size_t vertex_count_;
    const Framing& framing_;
    const uint32_t* indices_;
    size_t index_count_;
    const OverdrawNode* nodes_;
    size_t node_count_;
    UnitPartition partition_;
    ScoreSettings settings_;
    std::vector<KeptNode> kept_;
    size_t kept_bytes_ = 0;
    uint64_t sampled_nodes_ = 0, sampled_bytes_ = 0;
};

// How many nodes to rasterise together so that their KeptNodes take about `bytes`, at the mean
// size of the sampled nodes (one more, to find where a budget ends), between `least` (one per
// thread, say) and `most`; `least` when nothing is sampled yet.
size_t nodes_within(uint64_t bytes, uint64_t sampled_bytes, uint64_t sampled_nodes, size_t least, size_t most);

}  // namespace animorder
