// animorder — scoring orders over the evaluation nodes of DESIGN.md (the paper's protocol:
// 300 random viewpoints from a fixed seed, at 3R, every keyframe of every clip, 512×512).
// No file I/O here.
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/clustering.h"
#include "animorder/overdraw.h"

#include <cstdint>
#include <functional>
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

// A method under evaluation: its buffers (face permutations of the whole mesh, primitives drawn
// in file order) and how it picks one at a node. Without tables it has one buffer for every node;
// with tables (one per clip, mesh.clips order) a node draws buffer table_base[clip] + the table's
// cell for (keyframe in the clip, view direction): exactly what an application does at run time.
struct MethodBuffers {
    std::vector<std::vector<uint32_t>> orders;
    std::vector<SelectionTable> tables;
    std::vector<uint32_t> table_base;
};

// Scores every method at every evaluation node (clip keyframes × random views, R per clip), all
// buffers of all methods from one rasterisation per node. Returns one entry per method.
std::vector<OrderEvaluation> evaluate_methods(const AnimatedMesh& mesh, const std::vector<MethodBuffers>& methods,
                                              const EvaluationSettings& settings);

}  // namespace animorder
