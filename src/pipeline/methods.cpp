// The named methods of DESIGN.md over a whole character, and the one place their names are spelled.
//
// original:          Tipsify (Sander, Nehab & Barczak 2007, §3) — the vertex cache order alone.
// static-sander07:   Tipsify + fast linear clustering (§4) + sort by occlusion potential (§5).
// static-nehab06:    Nehab, Barczak & Sander 2006 (nehab06.cpp): normal clusters, measured overdraw
//                    graph, feedback-arc-set order; each primitive framed and measured on its own.
// meshopt:           meshoptimizer's vertex cache + overdraw optimisers (meshopt_order.cpp).
// tipsify-per-frame: static-sander07 at every keyframe, one buffer each (the paper's "Tipsify").
// single, joint:     Han & Sander 2017 (clustering.cpp): k-means over (keyframe, view) nodes.
// measured, measured-joint: single / joint with measured cluster orders (measured_order.cpp).
// oracle:            per evaluation node, the patches front-to-back (evaluation.cpp): a bound.
// All run per primitive: a character's primitives are separate draws.
#include "animorder/methods.h"

#include "animorder/animated_mesh.h"
#include "animorder/blend_orders.h"
#include "animorder/clustering.h"
#include "animorder/evaluation.h"
#include "animorder/held_out_choice.h"
#include "animorder/invalid_input.h"
#include "animorder/kept_fragments.h"
#include "animorder/mesh_patches.h"
#include "animorder/measured_order.h"
#include "animorder/meshopt_order.h"
#include "animorder/nehab06.h"
#include "animorder/selection_table.h"
#include "animorder/static_sander07.h"
#include "animorder/tipsify.h"
#include "animorder/triangle_order.h"
#include "animorder/vertex_cache.h"
#include "animorder/viewpoints.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <string>

namespace animorder {

namespace {

struct MethodInfo {
    Method method;
    const char* name;
    bool lambda;           // reads λ (the patch threshold)
    bool clusters;         // k-means: reads k, the views and the k-means settings
    bool buffers;          // has orders to ship (not the oracle)
    bool single_buffer;    // one order for the whole animation
    bool joint;            // k-means over all clips at once
    bool measured;         // k-means whose cluster orders come from measured overdraw (OrderSource)
    Method joint_variant;  // k-means: what --joint makes of it
    BlendOrder blend;
};

// A single-buffer method: one order for the whole animation.
constexpr MethodInfo one_buffer(Method method, const char* name, bool lambda, BlendOrder blend) {
    return {method, name, lambda, false, true, true, false, false, method, blend};
}
// Han & Sander's k-means and its variants: k buffers per clip, or for all clips (joint).
constexpr MethodInfo k_means(Method method, const char* name, bool joint, bool measured, Method joint_variant) {
    return {method, name, true, true, true, false, joint, measured, joint_variant, BlendOrder::PerCluster};
}

// The table every name, parse and property comes from.
constexpr MethodInfo kMethods[] = {
    one_buffer(Method::Original, "original", false, BlendOrder::AsInput),
    one_buffer(Method::StaticSander07, "static-sander07", true, BlendOrder::Reversed),
    one_buffer(Method::StaticNehab06, "static-nehab06", false, BlendOrder::Reversed),
    one_buffer(Method::Meshopt, "meshopt", false, BlendOrder::Reversed),
    // static-sander07 at every keyframe: a buffer per keyframe.
    {Method::TipsifyPerFrame, "tipsify-per-frame", true, false, true, false, false, false, Method::TipsifyPerFrame,
     BlendOrder::Reversed},
    k_means(Method::Single, "single", false, false, Method::Joint),
    k_means(Method::Joint, "joint", true, false, Method::Joint),
    // A new order at every evaluation node: a bound, no buffers.
    {Method::Oracle, "oracle", true, false, false, false, false, false, Method::Oracle, BlendOrder::PerNode},
    k_means(Method::Measured, "measured", false, true, Method::MeasuredJoint),
    k_means(Method::MeasuredJoint, "measured-joint", true, true, Method::MeasuredJoint),
};

const MethodInfo& info(Method method) {
    for (const MethodInfo& m : kMethods)
        if (m.method == method) return m;
    throw InvalidInput("unknown method value " + std::to_string(int(method)));
}

std::string known_names(bool single_buffer_only) {
    std::string names;
    for (const MethodInfo& m : kMethods)
        if (!single_buffer_only || m.single_buffer) names += std::string(names.empty() ? "" : ", ") + m.name;
    return names;
}

}  // namespace

const std::vector<Method>& all_methods() {
    static const std::vector<Method> methods = [] {
        std::vector<Method> all;
        for (const MethodInfo& m : kMethods) all.push_back(m.method);
        return all;
    }();
    return methods;
}

const char* method_name(Method method) { return info(method).name; }

Method parse_method(const std::string& name) {
    for (const MethodInfo& m : kMethods)
        if (name == m.name) return m.method;
    throw InvalidInput("unknown method '" + name + "' (known: " + known_names(false) + ")");
}

Method parse_static_method(const std::string& name) {
    for (const MethodInfo& m : kMethods)
        if (name == m.name && m.single_buffer) return m.method;
    throw InvalidInput("unknown single-buffer method '" + name + "' (known: " + known_names(true) + ")");
}

bool method_uses_lambda(Method method) { return info(method).lambda; }
bool method_uses_clusters(Method method) { return info(method).clusters; }
bool method_has_buffers(Method method) { return info(method).buffers; }
bool method_is_clustered(Method method) { return info(method).clusters; }
bool method_is_joint(Method method) { return info(method).joint; }
bool method_runs_per_clip(Method method) { return info(method).clusters && !info(method).joint; }
bool method_has_joint_variant(Method method) { return info(method).clusters; }
Method method_joint_variant(Method method) {
    if (!info(method).clusters) throw InvalidInput(std::string(method_name(method)) + " has no joint variant");
    return info(method).joint_variant;
}
BlendOrder method_blend_order(Method method) { return info(method).blend; }

const char* distance_name(DistanceVariant variant) { return variant == DistanceVariant::Jcgt ? "jcgt" : "i3d"; }
DistanceVariant parse_distance(const std::string& name) {
    if (name == "jcgt") return DistanceVariant::Jcgt;
    if (name == "i3d") return DistanceVariant::I3d;
    throw InvalidInput("the distance must be jcgt or i3d, not '" + name + "'");
}
const char* update_name(UpdateRule rule) { return rule == UpdateRule::Monotone ? "monotone" : "paper"; }
UpdateRule parse_update(const std::string& name) {
    if (name == "monotone") return UpdateRule::Monotone;
    if (name == "paper") return UpdateRule::Paper;
    throw InvalidInput("the update rule must be monotone or paper, not '" + name + "'");
}

const char* library_version() { return ANIMORDER_VERSION; }

void validate_method_settings(const MethodSettings& settings) {
    if (!std::isfinite(settings.lambda)) throw InvalidInput("lambda must be a finite number");
    // The ranges the CLI's options check (tools/animorder/main.cpp), for every other caller too.
    if (!(settings.lambda >= 0 && settings.lambda <= 1000)) throw InvalidInput("lambda must be between 0 and 1000");
    if (settings.cache_size < 3 || settings.cache_size > 1024)
        throw InvalidInput("cache_size must be between 3 and 1024");
    const ClusteringSettings& c = settings.clustering;
    if (c.resolution < 8 || c.resolution > 4096) throw InvalidInput("resolution must be between 8 and 4096");
    if (c.max_iterations < 1 || c.max_iterations > 1000)
        throw InvalidInput("max_iterations must be between 1 and 1000");
    if (c.threads > 1024) throw InvalidInput("threads must be between 0 and 1024");
    if (c.clusters == 0 || c.clusters > kMaxClusters)
        throw InvalidInput("k (clusters) must be between 1 and " + std::to_string(kMaxClusters));
    if (!(c.min_separation_deg >= 0 && c.min_separation_deg <= 180))
        throw InvalidInput("the minimum separation must be between 0 and 180 degrees");
    if (c.front_levels > kMaxFrontLevels)
        throw InvalidInput("front levels must be between 0 (every level) and " + std::to_string(kMaxFrontLevels));
    icosphere_subdivisions_for(c.views);  // throws for a count that is no icosphere
    icosphere_subdivisions_for(settings.nehab_views);
}

StaticMethodResult run_static_method(const AnimatedMesh& mesh, StaticMethod method,
                                     const StaticMethodSettings& settings) {
    validate_animated_mesh(mesh);
    if (!info(method).single_buffer)
        throw InvalidInput(std::string(method_name(method)) + " is not a single-buffer method");
    if (mesh.keyframe_count() > 0 && settings.keyframe >= mesh.keyframe_count())
        throw InvalidInput("keyframe " + std::to_string(settings.keyframe) + " does not exist (the mesh has " +
                           std::to_string(mesh.keyframe_count()) + ")");
    if (method != StaticMethod::Original && mesh.keyframe_count() == 0 && mesh.triangle_count() > 0)
        throw InvalidInput(std::string(method_name(method)) + " needs positions, and the mesh has no keyframe");

    StaticMethodResult result;
    result.indices.resize(mesh.indices.size());
    result.order.reserve(mesh.triangle_count());
    for (const Primitive& primitive : mesh.primitives) {
        const uint32_t* source = mesh.indices.data() + primitive.first_index;
        const size_t triangles = primitive.index_count / 3;
        std::vector<uint32_t> order(triangles);
        if (method == StaticMethod::Original) {
            result.hard_boundary_count +=
                tipsify(order.data(), source, primitive.index_count, mesh.vertex_count, settings.cache_size)
                    .hard_boundaries.size();
        } else if (method == StaticMethod::Meshopt) {
            order = meshopt_order(source, primitive.index_count, mesh.keyframe(settings.keyframe), mesh.vertex_count,
                                  settings.cache_size);
        } else if (method == StaticMethod::StaticNehab06) {
            Nehab06Settings nehab;
            nehab.clusters = std::min(settings.nehab_clusters, triangles);  // small primitives: fewer
            nehab.views = settings.nehab_views;
            nehab.resolution = settings.nehab_resolution;
            nehab.cache_size = settings.cache_size;
            nehab.threads = settings.threads;
            // The graph is measured with back faces culled, double-sided or not (Nehab06Settings::
            // triangle_modes can draw both faces, and evaluate counts them): measured, drawing both
            // faces in the graph gave worse orders under the true, double-sided count, on Xbot's walk
            // (OVR 1.865 → 1.955, automatic clusters; 1.848 → 1.969 at 640) and MorphStressTest's
            // TheWave (2.068 → 2.208, automatic; better only at fixed counts: 1.988 → 1.918 at 64):
            // on a closed double-sided shell every cluster hides its opposite one from one side and
            // is hidden by it from the other, near-cancelling arcs that crowd out the concavities'.
            // (`evaluate X --clip C --methods static-nehab06 [--nehab-clusters N] --eval-views 60
            // --eval-resolution 256`, TheWave with 20 views.) Blended primitives likewise: their
            // culled graph, reversed, mis-sorts fewer pixels on the bundled character's hair and
            // cape (11.5%) than without culling (14.1%) or skipped as in the opaque pass (15.9%).
            // The clustering keyframe first: clusters come from the first listed keyframe.
            std::vector<uint32_t> keyframes{uint32_t(settings.keyframe)};
            if (settings.nehab_all_keyframes) {
                const size_t count = mesh.keyframe_count(), stride = (count + 7) / 8;
                for (size_t f = 0; f < count; f += stride)
                    if (f != settings.keyframe) keyframes.push_back(uint32_t(f));
            }
            result.patch_count += order_static_nehab06(order.data(), source, primitive.index_count,
                                                       mesh.keyframe_positions.data(), mesh.keyframe_count(),
                                                       mesh.vertex_count, keyframes.data(), keyframes.size(), nehab)
                                      .cluster_count;
        } else {
            const StaticOrderResult r =
                order_static_sander07(order.data(), source, primitive.index_count, mesh.keyframe(settings.keyframe),
                                      mesh.vertex_count, 3 * sizeof(float), settings.lambda, settings.cache_size);
            result.patch_count += r.patch_count;
            result.hard_boundary_count += r.hard_boundary_count;
        }
        apply_triangle_order(result.indices.data() + primitive.first_index, source, order.data(), triangles);
        const uint32_t first_triangle = uint32_t(primitive.first_index / 3);
        for (uint32_t t : order) result.order.push_back(first_triangle + t);
    }
    return result;
}

VertexCacheStats analyze_mesh_vertex_cache(const AnimatedMesh& mesh, const std::vector<uint32_t>& indices,
                                           unsigned cache_size) {
    // The cache sees the corners in the order the file's index data lists them: a mirrored
    // primitive's as written (to_file_winding), not as flipped for the rasteriser.
    std::vector<uint32_t> as_written;
    if (has_mirrored_primitives(mesh)) {
        as_written = indices;
        to_file_winding(mesh, as_written.data());
    }
    const uint32_t* drawn = as_written.empty() ? indices.data() : as_written.data();
    VertexCacheStats total;
    size_t referenced = 0;
    for (const Primitive& primitive : mesh.primitives) {
        const VertexCacheStats s =
            analyze_vertex_cache(drawn + primitive.first_index, primitive.index_count, mesh.vertex_count, cache_size);
        total.misses += s.misses;
        total.triangles += s.triangles;
        referenced += s.referenced_vertices;
    }
    // Vertices shared by two primitives count once per primitive, as each draw transforms them.
    total.referenced_vertices = referenced;
    total.acmr = total.triangles ? double(total.misses) / double(total.triangles) : 0.0;
    total.atvr = referenced ? double(total.misses) / double(referenced) : 0.0;
    return total;
}

AnimatedMethodResult run_han_sander(const AnimatedMesh& mesh, bool joint, double lambda, unsigned cache_size,
                                    const ClusteringSettings& settings, bool blend_clusters, bool planar_units) {
    validate_animated_mesh(mesh);
    if (mesh.clips.empty()) throw InvalidInput("the mesh has no clip to cluster");
    AnimatedMethodResult result;
    const auto start = std::chrono::steady_clock::now();
    result.patches = build_mesh_patches(mesh, lambda, cache_size);
    // measured: the λ patches, whose distance order each cluster may keep (held_out_choice.h),
    // set aside where other units replace them.
    const bool measured = settings.order == OrderSource::Measured;
    MeshPatches lambda_patches, measured_pieces;
    if (planar_units) {
        lambda_patches = result.patches;
        result.patches = build_planar_units(mesh, result.patches, 0, cache_size);
    } else if (settings.order == OrderSource::Measured) {
        const std::vector<uint32_t> first = joined_vertices(mesh);
        size_t distinct = 0;
        for (size_t v = 0; v < first.size(); ++v) distinct += first[v] == v;
        // Pieces only as large as needed to bring the units near a dense graph's size: a small
        // flat-shaded mesh keeps its single triangles (they cost little there).
        const size_t most = std::min<size_t>(kMeasuredSurfaceUnitTriangles,
                                             (mesh.triangle_count() + kDenseMeasuredUnits - 1) / kDenseMeasuredUnits);
        if (2 * distinct <= mesh.vertex_count && most >= 2) {
            MeshPatches pieces = build_welded_patches(mesh, lambda, most, cache_size);
            if (settings.log)
                settings.log("units: flat-shaded (" + std::to_string(distinct) + " positions for " +
                             std::to_string(mesh.vertex_count) + " vertices): " + std::to_string(pieces.patch_count()) +
                             " pieces of at most " + std::to_string(most) +
                             " triangles of the surface's patches, not the " +
                             std::to_string(result.patches.patch_count()) + " patches of the vertex buffer");
            lambda_patches = std::move(result.patches);
            result.patches = std::move(pieces);
        } else if (result.patches.patch_count() > kMaxListedUnits) {
            // Beyond kMaxListedUnits a node's lists are kept per triangle, and the graph, the
            // counting and the search grow with the square of the units a pixel sees: k-means
            // runs as `single`'s over the patches, then each cluster's measured order of runs
            // of them (at λ = 3, single triangles) packed along the cache order, from some of
            // its nodes, replaces the distance order where the held-out views say so.
            const size_t most = (result.patches.patch_count() + kMaxListedUnits - 1) / kMaxListedUnits;
            measured_pieces = patch_pieces(result.patches, most);
            if (settings.log)
                settings.log("units: " + std::to_string(result.patches.patch_count()) + " patches, more than " +
                             std::to_string(kMaxListedUnits) + ": `single`'s k-means over them, then measured orders "
                             "of " + std::to_string(measured_pieces.patch_count()) + " pieces of at most " +
                             std::to_string(most) + " triangles checked against its orders on held-out views");
        }
    }
    const bool refine = measured && measured_pieces.patch_count() > 0;
    result.seconds_patches = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.framing = frame_animated_mesh(mesh);

    auto clip_keyframes = [&](const Clip& c) {
        std::vector<uint32_t> k;
        for (size_t f = 0; f < c.keyframe_count; ++f) k.push_back(uint32_t(c.first_keyframe + f));
        return k;
    };
    std::vector<std::vector<uint32_t>> sets;
    if (joint) {
        std::vector<uint32_t> all;
        for (const Clip& c : mesh.clips)
            for (uint32_t k : clip_keyframes(c)) all.push_back(k);
        sets.push_back(all);
    } else {
        for (const Clip& c : mesh.clips) sets.push_back(clip_keyframes(c));
    }
    for (size_t s = 0; s < sets.size(); ++s) {
        const std::vector<uint32_t>& keyframes = sets[s];
        const Framing framing = frame_subset(result.framing, keyframes);
        result.run_radius.push_back(framing.radius);
        // A run per clip names its clip in its log lines and progress.
        ClusteringSettings run_settings = settings;
        if (!joint && sets.size() > 1) {
            const std::string clip = "clip '" + mesh.clips[s].name + "' (" + std::to_string(s + 1) + "/" +
                                     std::to_string(sets.size()) + "): ";
            if (settings.log)
                run_settings.log = [&settings, clip](const std::string& line) { settings.log(clip + line); };
            if (settings.progress)
                run_settings.progress = [&settings, clip](const std::string& stage, size_t done, size_t total) {
                    settings.progress(clip + stage, done, total);
                };
        }
        if (refine) {  // `single`'s k-means exactly (its stop rule too), measured orders after
            run_settings.order = OrderSource::Distance;
            run_settings.settled_gain = 0;
        }
        result.runs.push_back(cluster_nodes(mesh, result.patches, framing, keyframes, run_settings));
        // The check offers Han & Sander's JCGT distance order (the default update); with the I3D
        // distance (`--distance i3d`) measured's orders are kept as the k-means left them.
        if (measured && !framing.shows_nothing() && (refine || settings.distance == DistanceVariant::Jcgt)) {
            ClusteringResult& run = result.runs.back();
            const auto held_start = std::chrono::steady_clock::now();
            // The alternative to each cluster's order: the distance order of the λ patches after
            // measured k-means, or the measured order of the pieces after `single`'s.
            const size_t stride = (run.assignment.size() + kMeasuredRefineNodes - 1) / kMeasuredRefineNodes;
            const HeldOutChoice choice = choose_on_held_out_views(
                mesh, framing, settings.resolution, settings.threads, run,
                refine ? measured_cluster_orders(mesh, measured_pieces, framing, run, settings.resolution,
                                                 settings.threads, std::max<size_t>(1, stride), settings.front_levels)
                       : distance_cluster_orders(mesh, lambda_patches.patch_count() ? lambda_patches : result.patches,
                                                 framing, run));
            run.held_out_nodes = choice.nodes;
            run.held_out_distance = choice.taken;
            if (refine)
                for (uint8_t& d : run.held_out_distance) d = !d;
            run.seconds_held_out =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - held_start).count();
            if (run_settings.log) {
                size_t kept = 0;
                for (const uint8_t d : run.held_out_distance) kept += d;
                const auto ovr = [&](uint64_t passed) {
                    return choice.visible ? std::to_string(double(passed) / double(choice.visible)) : std::string("-");
                };
                run_settings.log("held-out views: " + std::to_string(choice.nodes) + " nodes; the distance order kept in " +
                                 std::to_string(kept) + " of " + std::to_string(choice.taken.size()) +
                                 " clusters (OVR there " + ovr(choice.current_passed) + " before, " +
                                 ovr(choice.chosen_passed) + " after); " + std::to_string(choice.reassigned) +
                                 " clustering nodes reassigned" +
                                 (choice.dropped ? ", " + std::to_string(choice.dropped) + " buffers left unused dropped"
                                                 : std::string()));
            }
        }
        // Blended primitives: back to front for each cluster, in the measured blend order of its
        // nodes (blend_orders.h; the nodes' transparent pass rasterised once); with blend_clusters,
        // by their own k clusters of the same nodes, the buffers then being the (opaque, blend)
        // cluster pairs the nodes take. A run that draws nothing (cluster_nodes' "nothing drawn")
        // keeps its one buffer as it is.
        const bool drawn = !framing.shows_nothing();
        if (drawn && has_blended_primitives(mesh) && !blend_clusters) {
            blended_orders_from_clusters(mesh, result.framing, framing.radius, result.runs.back());
            ClusteringResult& run = result.runs.back();
            measured_blended_orders(mesh,
                                    blend_fragments_of_nodes(mesh, framing, run, settings.resolution, settings.threads),
                                    run.assignment, run.triangle_orders, settings.threads);
        } else if (drawn && has_blended_primitives(mesh)) {
            const BlendClustering blend =
                cluster_blend_nodes(mesh, framing, result.runs.back(), settings.resolution, settings.threads);
            combine_with_blend_clusters(mesh, blend, result.runs.back());
        }
    }
    for (size_t c = 0; c < mesh.clips.size(); ++c) {
        const size_t run = joint ? 0 : c;
        uint32_t base = 0;  // buffers of the runs before (k each without blended primitives)
        for (size_t r = 0; r < run; ++r) base += uint32_t(result.runs[r].triangle_orders.size());
        result.buffers.table_base.push_back(base);
        result.buffers.tables.push_back(
            build_selection_table(result.runs[run], mesh.clips[c].first_keyframe, mesh.clips[c].keyframe_count));
    }
    for (const ClusteringResult& r : result.runs)
        for (const auto& order : r.triangle_orders) result.buffers.orders.push_back(order);
    return result;
}

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// One table per clip whose every cell says `buffer of keyframe f` (a single buffer: always 0).
SelectionTable constant_table(size_t keyframes, bool one_per_keyframe) {
    SelectionTable t;
    t.keyframes = uint32_t(keyframes);
    t.theta_steps = 2;
    t.phi_steps = 1;
    for (uint32_t f = 0; f < t.keyframes; ++f) t.cells.insert(t.cells.end(), 2, uint8_t(one_per_keyframe ? f : 0));
    return t;
}

StaticMethodSettings static_settings(const MethodSettings& settings) {
    StaticMethodSettings s;
    s.lambda = settings.lambda;
    s.cache_size = settings.cache_size;
    s.keyframe = settings.keyframe;
    s.nehab_clusters = settings.nehab_clusters;
    s.nehab_views = settings.nehab_views;
    s.nehab_resolution = settings.clustering.resolution;
    s.nehab_all_keyframes = settings.nehab_all_keyframes;
    s.threads = settings.clustering.threads;
    return s;
}

// A single-buffer method: its order, and a table per clip that always names it.
void run_single_buffer(MethodResult& result, const AnimatedMesh& mesh, const MethodSettings& settings) {
    StaticMethodResult r = run_static_method(mesh, result.method, static_settings(settings));
    result.buffers.orders.push_back(std::move(r.order));
    result.framing = frame_animated_mesh(mesh);
    for (const Clip& c : mesh.clips) {
        result.buffers.tables.push_back(constant_table(c.keyframe_count, false));
        result.buffers.table_base.push_back(0);
    }
    result.patch_count = r.patch_count;
    result.hard_boundary_count = r.hard_boundary_count;
}

// Han & Sander 2017; the fallback is the buffer the most clustering nodes chose.
void run_clustered(MethodResult& result, const AnimatedMesh& mesh, const MethodSettings& settings) {
    const bool joint = method_is_joint(result.method);
    ClusteringSettings clustering = settings.clustering;
    if (info(result.method).measured) {
        clustering.order = OrderSource::Measured;
        if (clustering.settled_gain == 0) clustering.settled_gain = kMeasuredSettledGain;
    }
    AnimatedMethodResult r =
        run_han_sander(mesh, joint, settings.lambda, settings.cache_size, clustering, settings.blend_clusters,
                       clustering.order == OrderSource::Measured && settings.measured_planar_units);
    std::vector<size_t> chosen(r.buffers.orders.size(), 0);
    for (size_t i = 0; i < r.runs.size(); ++i)
        for (uint32_t c : r.runs[i].assignment) ++chosen[r.buffers.table_base[joint ? 0 : i] + c];
    result.fallback = uint32_t(std::max_element(chosen.begin(), chosen.end()) - chosen.begin());
    for (const ClusteringResult& run : r.runs) {
        double seconds = run.seconds_rasterization;
        for (const ClusteringIteration& x : run.iterations) seconds += x.seconds_assignment + x.seconds_update;
        result.run_seconds.push_back(seconds + run.seconds_held_out);
    }
    result.buffers = std::move(r.buffers);
    result.framing = std::move(r.framing);
    result.patch_count = r.patches.patch_count();
    result.runs = std::move(r.runs);
    result.run_radius = std::move(r.run_radius);
    result.seconds_patches = r.seconds_patches;
}

// static-sander07 sorted at every keyframe: the paper's "Tipsify" column. A keyframe's table cell
// names its own buffer, so the sidecar and glTF writers take it as they are (clips of up to
// kMaxPerKeyframeBuffers keyframes; the table cells are bytes).
void run_tipsify_per_frame(MethodResult& result, const AnimatedMesh& mesh, const MethodSettings& settings) {
    StaticMethodSettings s = static_settings(settings);
    for (size_t f = 0; f < mesh.keyframe_count(); ++f) {
        s.keyframe = f;
        StaticMethodResult r = run_static_method(mesh, Method::StaticSander07, s);
        result.patch_count = r.patch_count;
        result.buffers.orders.push_back(std::move(r.order));
        result.buffers.keyframe_buffer.push_back(uint32_t(f));
    }
    result.framing = frame_animated_mesh(mesh);
    bool fits = true;
    for (const Clip& c : mesh.clips) fits = fits && c.keyframe_count <= kMaxPerKeyframeBuffers;
    for (size_t c = 0; fits && c < mesh.clips.size(); ++c) {
        result.buffers.tables.push_back(constant_table(mesh.clips[c].keyframe_count, true));
        result.buffers.table_base.push_back(uint32_t(mesh.clips[c].first_keyframe));
    }
}

// A bound, not a product: every evaluation node draws the patches sorted front-to-back for itself
// (evaluation.cpp). Its ACMR is the mean over the orders of 12 icosahedron views at each clip's
// first keyframe.
void run_oracle(MethodResult& result, const AnimatedMesh& mesh, const MethodSettings& settings) {
    auto patches = std::make_shared<MeshPatches>(build_mesh_patches(mesh, settings.lambda, settings.cache_size));
    result.buffers.front_to_back = patches;
    result.framing = frame_animated_mesh(mesh);
    result.patch_count = patches->patch_count();
    const std::vector<float> views = icosphere_directions(0);
    std::vector<uint32_t> indices(mesh.indices.size());
    size_t samples = 0;
    for (const Clip& clip : mesh.clips) {
        const std::vector<uint32_t> first = {uint32_t(clip.first_keyframe)};
        const std::vector<float> centroids = patch_centroids(mesh, *patches, result.framing, first);
        for (size_t v = 0; v < views.size() / 3; ++v) {
            const float radius = 3 * result.framing.radius;
            const float eye[3] = {radius * views[3 * v], radius * views[3 * v + 1], radius * views[3 * v + 2]};
            const std::vector<uint32_t> order = patch_order_to_triangle_order(
                *patches, front_to_back_patch_order(centroids.data(), patches->patch_count(), eye));
            apply_triangle_order(indices.data(), mesh.indices.data(), order.data(), mesh.triangle_count());
            const VertexCacheStats s = analyze_mesh_vertex_cache(mesh, indices, settings.cache_size);
            result.acmr_mean += s.acmr;
            result.atvr_mean += s.atvr;
            ++samples;
        }
    }
    result.acmr_mean /= double(std::max<size_t>(1, samples));
    result.atvr_mean /= double(std::max<size_t>(1, samples));
}

}  // namespace

void reverse_blended_primitives(const AnimatedMesh& mesh, std::vector<uint32_t>& order) {
    if (order.size() != mesh.triangle_count()) throw InvalidInput("an order does not cover the mesh's triangles");
    for (const Primitive& p : mesh.primitives) {
        if (p.alpha_mode != AlphaMode::Blend) continue;
        const size_t first = p.first_index / 3, last = (p.first_index + p.index_count) / 3;
        for (size_t i = first; i < last; ++i)
            if (order[i] < first || order[i] >= last)
                throw InvalidInput("an order moves triangles between primitives ('" + p.name + "')");
        std::reverse(order.begin() + ptrdiff_t(first), order.begin() + ptrdiff_t(last));
    }
}

void tie_instances(const AnimatedMesh& mesh, std::vector<uint32_t>& order) {
    if (order.size() != mesh.triangle_count()) throw InvalidInput("an order does not cover the mesh's triangles");
    std::map<std::pair<int, int>, const Primitive*> first;
    for (const Primitive& p : mesh.primitives) {
        if (p.source_mesh < 0) continue;
        const auto [at, inserted] = first.emplace(std::make_pair(p.source_mesh, p.source_primitive), &p);
        if (inserted) continue;
        const Primitive& f = *at->second;
        if (f.index_count != p.index_count)
            throw InvalidInput("two primitives from one file primitive have different triangle counts ('" + p.name +
                               "')");
        const size_t from = f.first_index / 3, to = p.first_index / 3, n = p.index_count / 3;
        for (size_t i = 0; i < n; ++i) {
            if (order[from + i] < from || order[from + i] >= from + n)
                throw InvalidInput("an order moves triangles between primitives ('" + f.name + "')");
            order[to + i] = uint32_t(to + (order[from + i] - from));
        }
    }
}

MethodResult run_method(const AnimatedMesh& mesh, Method method, const MethodSettings& settings) {
    validate_method_settings(settings);
    return run_validated_method(mesh, method, settings);
}

MethodResult run_validated_method(const AnimatedMesh& mesh, Method method, const MethodSettings& settings) {
    validate_animated_mesh(mesh);
    if (mesh.keyframe_count() > 0 && settings.keyframe >= mesh.keyframe_count())
        throw InvalidInput("keyframe " + std::to_string(settings.keyframe) + " does not exist (the mesh has " +
                           std::to_string(mesh.keyframe_count()) + ")");
    const auto start = std::chrono::steady_clock::now();
    MethodResult result;
    result.method = method;
    switch (method) {
        case Method::Original:
        case Method::StaticSander07:
        case Method::StaticNehab06:
        case Method::Meshopt: run_single_buffer(result, mesh, settings); break;
        case Method::TipsifyPerFrame: run_tipsify_per_frame(result, mesh, settings); break;
        case Method::Single:
        case Method::Joint:
        case Method::Measured:
        case Method::MeasuredJoint: run_clustered(result, mesh, settings); break;
        case Method::Oracle:
            run_oracle(result, mesh, settings);
            result.seconds = seconds_since(start);
            return result;
    }
    // Blended primitives are drawn back to front: every buffer of a single-buffer sorting method
    // carries the reverse of its front-to-back order there (BlendOrder::Reversed); the input
    // order stays as it is for original, and k-means sorts them per cluster in run_han_sander.
    if (method_blend_order(method) == BlendOrder::Reversed)
        for (std::vector<uint32_t>& order : result.buffers.orders) reverse_blended_primitives(mesh, order);
    for (std::vector<uint32_t>& order : result.buffers.orders) tie_instances(mesh, order);
    // The time covers the method, not its ACMR (the oracle's ACMR sampling is part of its run).
    result.seconds = seconds_since(start);
    std::vector<uint32_t> indices(mesh.indices.size());
    const size_t count = result.buffers.orders.size();
    for (const std::vector<uint32_t>& order : result.buffers.orders) {
        apply_triangle_order(indices.data(), mesh.indices.data(), order.data(), mesh.triangle_count());
        const VertexCacheStats s = analyze_mesh_vertex_cache(mesh, indices, settings.cache_size);
        result.acmr_mean += s.acmr / double(count);
        result.atvr_mean += s.atvr / double(count);
    }
    return result;
}

}  // namespace animorder
