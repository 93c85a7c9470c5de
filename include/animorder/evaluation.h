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

}  // namespace animorder
