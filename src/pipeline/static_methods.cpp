// The static methods of DESIGN.md ("original", "static-sander07") over a whole character.
//
// original:        Tipsify (Sander, Nehab & Barczak 2007, §3) — the vertex cache order alone.
// static-sander07: Tipsify + fast linear clustering (§4) + sort by occlusion potential (§5).
// meshopt:         meshoptimizer's vertex cache + overdraw optimisers (meshopt_method.cpp).
// static-nehab06:  Nehab, Barczak & Sander 2006 (nehab06.cpp): normal clusters, measured overdraw
//                  graph, feedback-arc-set order; each primitive framed and measured on its own.
// All run per primitive: a character's primitives are separate draws.
#include "animorder/methods.h"
#include "animorder/nehab06.h"

#include <algorithm>
#include <chrono>
#include <string>

namespace animorder {

StaticMethod parse_static_method(const std::string& name) {
    if (name == "original") return StaticMethod::Original;
    if (name == "static-sander07") return StaticMethod::StaticSander07;
    if (name == "meshopt") return StaticMethod::Meshopt;
    if (name == "static-nehab06") return StaticMethod::StaticNehab06;
    throw InvalidInput("unknown method '" + name +
                       "' (available: original, static-sander07, static-nehab06, meshopt, single, joint)");
}

const char* method_name(StaticMethod method) {
    switch (method) {
        case StaticMethod::Original: return "original";
        case StaticMethod::StaticSander07: return "static-sander07";
        case StaticMethod::Meshopt: return "meshopt";
        case StaticMethod::StaticNehab06: return "static-nehab06";
    }
    return "?";
}

StaticMethodResult run_static_method(const AnimatedMesh& mesh, StaticMethod method,
                                     const StaticMethodSettings& settings) {
    validate_animated_mesh(mesh);
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
            const StaticOrderResult r = order_static_sander07(
                order.data(), source, primitive.index_count, mesh.keyframe(settings.keyframe), mesh.vertex_count,
                3 * sizeof(float), settings.lambda, settings.cache_size);
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
    VertexCacheStats total;
    size_t referenced = 0;
    for (const Primitive& primitive : mesh.primitives) {
        const VertexCacheStats s = analyze_vertex_cache(indices.data() + primitive.first_index,
                                                        primitive.index_count, mesh.vertex_count, cache_size);
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
                                    const ClusteringSettings& settings) {
    validate_animated_mesh(mesh);
    if (mesh.clips.empty()) throw InvalidInput("the mesh has no clip to cluster");
    AnimatedMethodResult result;
    const auto start = std::chrono::steady_clock::now();
    result.patches = build_mesh_patches(mesh, lambda, cache_size);
    result.seconds_patches = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.framing = frame_keyframes(mesh.keyframe_positions.data(), mesh.keyframe_count(), mesh.vertex_count,
                                     mesh.indices.data(), mesh.indices.size());

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
    for (const auto& keyframes : sets) {
        const Framing framing = frame_subset(result.framing, keyframes);
        result.run_radius.push_back(framing.radius);
        result.runs.push_back(cluster_nodes(mesh, result.patches, framing, keyframes, settings));
    }
    for (size_t c = 0; c < mesh.clips.size(); ++c) {
        const size_t run = joint ? 0 : c;
        result.buffers.table_base.push_back(uint32_t(joint ? 0 : c * settings.clusters));
        result.buffers.tables.push_back(
            build_selection_table(result.runs[run], mesh.clips[c].first_keyframe, mesh.clips[c].keyframe_count));
    }
    for (const ClusteringResult& r : result.runs)
        for (const auto& order : r.triangle_orders) result.buffers.orders.push_back(order);
    return result;
}

}  // namespace animorder
