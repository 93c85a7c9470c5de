// animorder — the named methods of DESIGN.md applied to a whole AnimatedMesh.
//
// Each primitive is reordered on its own (primitives are separate draws with their own
// materials, so triangles never move between them); the result keeps every primitive's index
// range. This layer composes the algorithms of animorder.h; it does no file I/O either.
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/animorder.h"
#include "animorder/clustering.h"
#include "animorder/evaluation.h"

#include <string>
#include <vector>

namespace animorder {

// Single-buffer methods (DESIGN.md names): "original" (Tipsify only), "static-sander07",
// "meshopt" (meshoptimizer's optimizeVertexCache + optimizeOverdraw(1.05), the users' baseline)
// and "static-nehab06" (planar clusters ordered by a measured overdraw graph, nehab06.h).
enum class StaticMethod { Original, StaticSander07, Meshopt, StaticNehab06 };

// Parses a DESIGN.md method name; throws InvalidInput listing the known names otherwise.
StaticMethod parse_static_method(const std::string& name);
const char* method_name(StaticMethod method);

struct StaticMethodSettings {
    double lambda = kDefaultLambda;
    unsigned cache_size = kDefaultCacheSize;
    size_t keyframe = 0;  // the keyframe whose positions static-sander07 sorts with
    // static-nehab06: clusters (0: automatic, powers of two), icosphere views, resolution of the
    // graph's rasterisation, and whether its graph sums over the whole animation: `keyframe`
    // and every ceil(F / 8)-th keyframe from 0, so that at most 9 keyframes are rasterised (else
    // only `keyframe`). Clusters always come from the normals of `keyframe`.
    size_t nehab_clusters = 0;
    size_t nehab_views = 162;
    unsigned nehab_resolution = 256;
    bool nehab_all_keyframes = false;
    unsigned threads = 0;  // static-nehab06's rasterisation; 0: all hardware threads
};

struct StaticMethodResult {
    std::vector<uint32_t> indices;  // same layout as mesh.indices: primitive ranges kept
    // The same as a face permutation of the whole mesh (primitives drawn in file order), which
    // is what the overdraw engine's rank tables take.
    std::vector<uint32_t> order;
    size_t patch_count = 0;         // summed over primitives (static-sander07; static-nehab06: clusters)
    size_t hard_boundary_count = 0;
};

// meshoptimizer's vertex cache + overdraw optimisation of one index buffer as a face permutation.
std::vector<uint32_t> meshopt_order(const uint32_t* indices, size_t index_count, const float* positions,
                                    size_t vertex_count, unsigned cache_size);

// Runs the method on every primitive. Throws InvalidInput for an invalid mesh or settings.
StaticMethodResult run_static_method(const AnimatedMesh& mesh, StaticMethod method,
                                     const StaticMethodSettings& settings);

// Han & Sander 2017 over a whole character: "single" (one set of k buffers per clip) or "joint"
// (one set for all clips). Buffers are face permutations of the whole mesh; tables pick them.
struct AnimatedMethodResult {
    MeshPatches patches;
    MethodBuffers buffers;                  // single: k per clip, clip after clip; joint: k
    std::vector<ClusteringResult> runs;     // one per clip (single) or one (joint)
    Framing framing;                        // all keyframes (centres); R per run inside runs
    std::vector<float> run_radius;          // R used by each run
    double seconds_patches = 0;
};

AnimatedMethodResult run_han_sander(const AnimatedMesh& mesh, bool joint, double lambda, unsigned cache_size,
                                    const ClusteringSettings& settings);

// ACMR/ATVR of a whole index buffer drawn primitive by primitive, each draw starting with an
// empty cache (a draw call does not inherit the previous draw's post-transform cache).
VertexCacheStats analyze_mesh_vertex_cache(const AnimatedMesh& mesh, const std::vector<uint32_t>& indices,
                                           unsigned cache_size = kDefaultCacheSize);

}  // namespace animorder
