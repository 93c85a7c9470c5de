// animorder — the named methods of DESIGN.md applied to a whole AnimatedMesh (methods.cpp).
//
// A method turns a character into the buffers an application ships (face permutations of the
// whole mesh), how it picks one at run time (lookup tables per clip), the fallback buffer a
// viewer without the table draws, and their vertex-cache cost. `run_method` is what the tool,
// the benchmarks and the tests call; the names below are spelled here and nowhere else.
//
// Each primitive is reordered on its own (primitives are separate draws with their own
// materials, so triangles never move between them). This layer composes the algorithms of
// animorder.h; it does no file I/O either.
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/clustering.h"
#include "animorder/mesh_patches.h"
#include "animorder/patches.h"
#include "animorder/selection_table.h"
#include "animorder/vertex_cache.h"
#include "animorder/viewpoints.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace animorder {

// ---------------------------------------------------------------------------------------------
// Names

// Every method of DESIGN.md. Original: Tipsify only. StaticSander07: Sander et al. 2007.
// StaticNehab06: Nehab et al. 2006. Meshopt: meshoptimizer's optimisers (the users' baseline).
// TipsifyPerFrame: static-sander07 sorted at every keyframe (one buffer each, the paper's
// "Tipsify" column). Single / Joint: Han & Sander 2017 (k buffers per clip / for all clips).
// Oracle: the patches sorted front-to-back at every evaluation node — a bound, not an order to
// ship (it has no buffers).
// Measured / MeasuredJoint: single / joint with each cluster's patches ordered by the overdraw
// graph measured over its own nodes (measured_order.h), not by distance — beyond the paper.
enum class Method {
    Original,
    StaticSander07,
    StaticNehab06,
    Meshopt,
    TipsifyPerFrame,
    Single,
    Joint,
    Oracle,
    Measured,
    MeasuredJoint
};

// The method a user gets without asking: `measured`, the paper's k-means with each cluster's
// order from its measured overdraw (issue 46: docs/RESULTS.md, "Measured cluster orders", has its
// OVR, time and memory against `single` on every character); `--joint` gives `measured-joint`.
constexpr Method kDefaultMethod = Method::Measured;

// The most keyframes a clip may have for tipsify-per-frame's buffers to be written: each keyframe
// has its own buffer, and a lookup table's cells are bytes naming them.
constexpr size_t kMaxPerKeyframeBuffers = 256;

// All methods in DESIGN.md's order.
const std::vector<Method>& all_methods();

// The DESIGN.md name ("static-sander07", ...) and back. parse_method throws InvalidInput naming
// the unknown name and listing the known ones.
const char* method_name(Method method);
Method parse_method(const std::string& name);

// What a method is: every property below is a column of the one method table (methods.cpp), so
// a caller asks the method, never compares it with a list of names.
//
// Single, Joint, Measured, MeasuredJoint: k-means buffers; the joint ones span all clips, the
// others run once per clip (method_runs_per_clip: their reports time each clip's run).
bool method_is_clustered(Method method);
bool method_is_joint(Method method);
bool method_runs_per_clip(Method method);
// What `optimize --joint` makes of a method: single and joint give joint, measured and
// measured-joint give measured-joint. Throws InvalidInput for a method without a joint variant.
bool method_has_joint_variant(Method method);
Method method_joint_variant(Method method);

// How a method's buffers order the triangles of blended (alphaMode BLEND) primitives, which are
// drawn back to front (DESIGN.md "Blend error"):
enum class BlendOrder {
    AsInput,     // original: the file's order, as it is
    Reversed,    // a single-buffer sort (and tipsify-per-frame): the reverse of its front-to-back order
    PerCluster,  // k-means: each cluster's blended patches sorted back to front (run_han_sander)
    PerNode,     // the oracle: sorted at every node
};
BlendOrder method_blend_order(Method method);

// Which settings a method reads (reports print the others as null): λ (the patch threshold), and
// k / views / the k-means settings.
bool method_uses_lambda(Method method);
bool method_uses_clusters(Method method);
// False for the oracle: a new order at every node, nothing an application can draw.
bool method_has_buffers(Method method);

// The names of the k-means variants ("jcgt", "i3d"; "monotone", "paper") and back; parse_*
// throw InvalidInput for an unknown name.
const char* distance_name(DistanceVariant variant);
DistanceVariant parse_distance(const std::string& name);
const char* update_name(UpdateRule rule);
UpdateRule parse_update(const std::string& name);

// ---------------------------------------------------------------------------------------------
// Buffers and how a method picks one

// A method's buffers (face permutations of the whole mesh, primitives drawn in file order) and
// how it picks one at a node, in this order of precedence:
// - front_to_back (the "oracle" bound): no stored buffer; at every node the patches are sorted by
//   the distance from that node's eye to their centroid at that node's keyframe, nearest first;
// - keyframe_buffer (tipsify-per-frame): a node draws keyframe_buffer[its keyframe];
// - tables (one per clip, mesh.clips order): a node draws buffer table_base[clip] + the table's
//   cell for (keyframe in the clip, view direction): exactly what an application does at run time;
// - otherwise orders[0] at every node.
struct MethodBuffers {
    std::vector<std::vector<uint32_t>> orders;
    std::vector<SelectionTable> tables;
    std::vector<uint32_t> table_base;
    std::vector<uint32_t> keyframe_buffer;             // one entry per keyframe of the mesh
    std::shared_ptr<const MeshPatches> front_to_back;  // the oracle's patches
};

// ---------------------------------------------------------------------------------------------
// Running a method on a whole character

// Every setting of every method; each method reads those it uses. Defaults are the library's.
struct MethodSettings {
    double lambda = kDefaultLambda;  // patch threshold (static-sander07, tipsify-per-frame, single, joint, oracle)
    unsigned cache_size = kDefaultCacheSize;
    size_t keyframe = 0;  // static methods: the keyframe whose positions they sort with
    // single / joint: k-means (clusters is k; views, resolution, seed, ... as ClusteringSettings;
    // its log and progress callbacks are passed on). The resolution is also static-nehab06's.
    ClusteringSettings clustering;
    // static-nehab06: planar clusters (0: automatic, powers of two), measuring views, and whether
    // its graph also sums 8 keyframes spread over the animation (else `keyframe` only).
    size_t nehab_clusters = 0;
    size_t nehab_views = 162;
    bool nehab_all_keyframes = false;
    // single / joint on a mesh with blended primitives (blend_orders.h): false — their back-to-
    // front orders follow the opaque k-means clusters (k buffers per clip); true — they get their
    // own k clusters by measured blend error, and the buffers are the (opaque, blend) cluster
    // pairs the nodes take (up to k² per clip).
    bool blend_clusters = false;
    // measured / measured-joint: Nehab 2006's planar clusters (as many as λ gives patches) as the
    // units instead of the λ patches (build_planar_units).
    bool measured_planar_units = false;
};

// Throws InvalidInput for settings no method can run with (λ outside 0..1000 or not finite, k
// outside 1..kMaxClusters, a view count that is no icosphere, a separation outside 0..180°, the
// resolution, cache size, iteration cap or threads outside the CLI's ranges, ...).
void validate_method_settings(const MethodSettings& settings);

struct MethodResult {
    Method method = Method::Original;
    MethodBuffers buffers;
    Framing framing;        // every keyframe: the sidecar's and glTF's frame centres
    uint32_t fallback = 0;  // the buffer most clustering nodes chose: what viewers without the table draw
    double acmr_mean = 0;   // mean over buffers (oracle: over 12 views at each clip's first keyframe)
    double atvr_mean = 0;
    double seconds = 0;              // the whole run_method
    size_t patch_count = 0;          // patches (static-nehab06: planar clusters), summed over primitives
    size_t hard_boundary_count = 0;  // original, static-sander07
    // single / joint: the k-means runs (one per clip, or one for joint), each run's view radius,
    // the seconds spent building patches, and each run's seconds.
    std::vector<ClusteringResult> runs;
    std::vector<float> run_radius;
    double seconds_patches = 0;
    std::vector<double> run_seconds;
};

// The library's version, "MAJOR.MINOR.PATCH": the package's (`animorder --version`, the CMake
// package's and pkg-config's).
const char* library_version();

// Runs the method on the whole mesh. Throws InvalidInput for an invalid mesh or settings.
// Primitives loaded from one file primitive (a glTF mesh several nodes draw) share its one index
// buffer, so every buffer gives them the first one's order (tie_instances; the k-means runs'
// statistics are of the orders before that step, ACMR after).
MethodResult run_method(const AnimatedMesh& mesh, Method method, const MethodSettings& settings = {});

// run_method for settings validate_method_settings has accepted already (the tool checks them
// before it loads the input, so that a bad option is named first): the same run, without checking
// them a second time.
MethodResult run_validated_method(const AnimatedMesh& mesh, Method method, const MethodSettings& settings);

// In `order` (a permutation of the mesh's triangles that keeps each primitive's in its range), each
// later primitive of a file primitive (same source_mesh and source_primitive, source_mesh ≥ 0)
// takes the first one's order, triangle for triangle. Throws InvalidInput when they differ in size
// or the order moves triangles between primitives.
void tie_instances(const AnimatedMesh& mesh, std::vector<uint32_t>& order);

// ---------------------------------------------------------------------------------------------
// The building blocks run_method composes (tests and benchmarks call them alone)

// The single-buffer methods: Original, StaticSander07, Meshopt, StaticNehab06.
using StaticMethod = Method;
// parse_method restricted to the single-buffer methods (InvalidInput for the others).
Method parse_static_method(const std::string& name);

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
    unsigned nehab_resolution = ClusteringSettings{}.resolution;
    bool nehab_all_keyframes = false;
    unsigned threads = 0;  // static-nehab06's rasterisation; 0: all hardware threads
};

struct StaticMethodResult {
    std::vector<uint32_t> indices;  // same layout as mesh.indices: primitive ranges kept
    // The same as a face permutation of the whole mesh (primitives drawn in file order), which
    // is what the overdraw engine's rank tables take.
    std::vector<uint32_t> order;
    size_t patch_count = 0;  // summed over primitives (static-sander07; static-nehab06: clusters)
    size_t hard_boundary_count = 0;
};

// One single-buffer method on every primitive. Throws InvalidInput for an invalid mesh or
// settings, or a method that is not single-buffer.
StaticMethodResult run_static_method(const AnimatedMesh& mesh, Method method, const StaticMethodSettings& settings);

// Han & Sander 2017 over a whole character: "single" (one set of k buffers per clip) or "joint"
// (one set for all clips). Buffers are face permutations of the whole mesh; tables pick them.
struct AnimatedMethodResult {
    MeshPatches patches;
    MethodBuffers buffers;               // single: k per clip, clip after clip; joint: k
    std::vector<ClusteringResult> runs;  // one per clip (single) or one (joint)
    Framing framing;                     // all keyframes (centres); R per run inside runs
    std::vector<float> run_radius;       // R used by each run
    double seconds_patches = 0;
};

// planar_units: the units are build_planar_units' (of keyframe 0), not the λ patches. The
// measured order (settings.order Measured) on a flat-shaded mesh — at most half as many distinct
// positions as vertices (joined_vertices): faces share no vertex, so every λ patch is one
// triangle, and its graph and sifting grow with the square of the units a pixel sees — takes as
// its units build_welded_patches' pieces of at most min(kMeasuredSurfaceUnitTriangles,
// ceil(triangles / kDenseMeasuredUnits)) triangles, when that is 2 or more (a flat-shaded mesh of
// up to 1024 triangles keeps its single triangles: they cost little there): its time and memory
// stay near single's, its OVR below (docs/RESULTS.md, issue 46's note). The vertex cache gains
// nothing from λ there (no vertex is shared: ACMR 3 whatever the order).
constexpr size_t kMeasuredSurfaceUnitTriangles = 8;
// `measured` on a mesh with more λ patches than kMaxListedUnits (kept_fragments.h; Xbot at λ = 3):
// `single`'s k-means over the patches, then each cluster's measured order of runs of them
// (patch_pieces, as few patches a run as bring the units within kMaxListedUnits), from about this
// many of the run's nodes (every stride-th of each cluster's), taken where it passes fewer
// fragments on held-out views (held_out_choice.h). Elsewhere, measured k-means, then each
// cluster's distance order taken where it passes fewer there.
constexpr size_t kMeasuredRefineNodes = 2048;
// `measured`'s ClusteringSettings::settled_gain (unless set): k-means stops once an iteration
// lowers the mean node OVR by less than this fraction.
constexpr double kMeasuredSettledGain = 1e-4;
AnimatedMethodResult run_han_sander(const AnimatedMesh& mesh, bool joint, double lambda, unsigned cache_size,
                                    const ClusteringSettings& settings, bool blend_clusters = false,
                                    bool planar_units = false);

// Reverses, in a face permutation of the whole mesh, the draw order of every blended primitive
// (AlphaMode::Blend) in place: a front-to-back order becomes back to front. run_method applies it
// to the buffers of every method but original. Throws InvalidInput when the order moves
// triangles between primitives.
void reverse_blended_primitives(const AnimatedMesh& mesh, std::vector<uint32_t>& order);

// ACMR/ATVR of a whole index buffer drawn primitive by primitive, each draw starting with an
// empty cache (a draw call does not inherit the previous draw's post-transform cache).
VertexCacheStats analyze_mesh_vertex_cache(const AnimatedMesh& mesh, const std::vector<uint32_t>& indices,
                                           unsigned cache_size = kDefaultCacheSize);

}  // namespace animorder
