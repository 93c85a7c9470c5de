// animorder — scoring orders over the evaluation nodes of DESIGN.md (the paper's protocol:
// 300 random viewpoints from a fixed seed, at 3R, every keyframe of every clip, 512×512).
// No file I/O here.
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/methods.h"
#include "animorder/viewpoints.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace animorder {

// The fixed seed of DESIGN.md's evaluation viewpoints; never the clustering viewpoints.
constexpr uint64_t kEvaluationSeed = 20170501;

struct EvaluationSettings {
    size_t views = 300;
    uint64_t seed = kEvaluationSeed;
    unsigned resolution = 512;
    unsigned threads = 0;
    std::function<void(size_t, size_t)> progress;
};

struct OverdrawSummary {
    double ovr_mean = 0;    // mean over nodes of passed/visible
    double ovr_pooled = 0;  // Σ passed / Σ visible
    size_t nodes = 0;
};

struct OrderEvaluation {
    OverdrawSummary overall;
    std::vector<OverdrawSummary> per_clip;  // mesh.clips order
};

// The oracle's order (MethodBuffers::front_to_back) at one node: patches by ascending distance from the eye (eye: a point, in
// the same framed space as centroids, which holds 3 floats per patch), ties by patch id.
std::vector<uint32_t> front_to_back_patch_order(const float* centroids, size_t patch_count, const float eye[3]);

// Scores every method at every evaluation node (clip keyframes × random views, R per clip): one
// rasterisation per node, then each method's buffer for that node scored from its fragments.
// Deterministic whatever the thread count. Returns one entry per method.
std::vector<OrderEvaluation> evaluate_methods(const AnimatedMesh& mesh, const std::vector<MethodBuffers>& methods,
                                              const EvaluationSettings& settings);

// Blend error (DESIGN.md "Blend error") of orders on the blended primitives, pooled over nodes:
// at each pixel, the fragments of blended primitives nearer than the opaque scene's depth (the
// usual transparent pass: depth test on, writes off); a pair of them at different depths is
// mis-sorted when the nearer is drawn first.
struct BlendSummary {
    double missorted_pair_fraction = 0;   // Σ mis-sorted pairs / Σ pairs
    double missorted_pixel_fraction = 0;  // Σ pixels with a mis-sorted pair / Σ covered pixels
    uint64_t pairs = 0, missorted_pairs = 0, covered = 0, missorted_pixels = 0;
    size_t nodes = 0;
};

struct BlendEvaluation {
    BlendSummary overall;
    std::vector<BlendSummary> per_clip;  // mesh.clips order
};

// The blend error of every method's buffers (picked per node as evaluate_methods does; the
// oracle, which has no buffers, gets an empty summary), then one more entry: the bound, the
// blended triangles sorted back to front at every node by the eye distance of their centroids.
// Same nodes as evaluate_methods (settings); deterministic whatever the thread count. Throws
// InvalidInput when the mesh has no blended primitive.
std::vector<BlendEvaluation> evaluate_blend(const AnimatedMesh& mesh, const std::vector<MethodBuffers>& methods,
                                            const EvaluationSettings& settings);

// The bound's order at one node: the triangles of blended primitives farthest first by the
// squared distance from eye to their centroid (positions: one keyframe, minus centre), ties by
// index, in place of the blended triangles of identity; other triangles keep their place.
std::vector<uint32_t> back_to_front_blended_order(const AnimatedMesh& mesh, const float* positions,
                                                  const float centre[3], const float eye[3]);

}  // namespace animorder
