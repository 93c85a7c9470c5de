// `animorder reapply OPTIMIZED PROCESSED -o OUT`: after a tool rewrote an optimised glTF file
// (gltfpack, gltf-pipeline, `gltf-transform reorder`…), the k orders of OPTIMIZED mapped onto
// PROCESSED's triangles and written into a copy of PROCESSED. Triangles are matched by their
// corners (match_triangles): the posed positions of each corner at the first keyframe of every
// clip both files share (positions as the loader computes them: node transforms, skins, morph
// targets and KHR_mesh_quantization dequantisation applied, so indices and vertex layouts may
// differ). Refused, with nothing written, unless every triangle of every optimised primitive
// matches one triangle of PROCESSED and every processed primitive is wholly matched or untouched.
// With --nearest D (a simplified PROCESSED), a processed triangle found nowhere takes the place
// of the optimised triangle whose posed centroid is nearest (within D of the diagonal): each
// order then draws the processed triangles in the order of the optimised triangles they stand
// for, ties in PROCESSED's own sequence, and the tables' centres become the processed mesh's.
#include "commands.h"
#include "input.h"

#include "animorder/animated_mesh.h"
#include "animorder/atomic_write.h"
#include "animorder/gltf_extension.h"
#include "animorder/gltf_loader.h"
#include "animorder/load.h"
#include "animorder/triangle_matching.h"
#include "animorder/viewpoints.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <numeric>
#include <stdexcept>

namespace animorder::tool {
namespace {

// A tolerance as the option takes it (%g: 0.001, 0.01).
std::string shown(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", value);
    return text;
}

// Per triangle of the listed primitives of `mesh` (or all when `only` is empty), its three
// corners, each with xyz at every keyframe in `keyframes`.
std::vector<float> corners(const AnimatedMesh& mesh, const std::vector<size_t>& triangles,
                           const std::vector<size_t>& keyframes) {
    const size_t dims = 3 * keyframes.size();
    std::vector<float> out(triangles.size() * 3 * dims);
    for (size_t i = 0; i < triangles.size(); ++i)
        for (size_t c = 0; c < 3; ++c) {
            const uint32_t v = mesh.indices[3 * triangles[i] + c];
            for (size_t k = 0; k < keyframes.size(); ++k)
                for (size_t a = 0; a < 3; ++a)
                    out[(i * 3 + c) * dims + 3 * k + a] = mesh.keyframe(keyframes[k])[3 * v + a];
        }
    return out;
}

}  // namespace

int run_reapply(const ReapplyOptions& options) {
    const std::string extension = file_extension(options.output);
    if (extension != ".glb" && extension != ".gltf")
        throw std::runtime_error(options.output + ": the output must be a .glb or .gltf file");
    // Every file the two loads read (a .gltf's buffers and images too) is an input.
    std::vector<std::string> inputs;
    for (const std::string* file : {&options.optimized, &options.processed}) {
        try {
            const std::vector<std::string> reads = files_load_reads(*file, {});
            inputs.insert(inputs.end(), reads.begin(), reads.end());
        } catch (const LoadError&) {  // loading says what is wrong
            inputs.push_back(*file);
        }
    }
    check_outputs({options.output}, inputs);
    OrdersExtensionCheck orders = read_orders_extension(options.optimized);
    LoadOptions load;
    load.max_keyframe_bytes = options.max_memory;
    const AnimatedMesh a = load_gltf(options.optimized, load);
    const AnimatedMesh b = load_gltf(options.processed, load);
    // The triangles as the files have them (a mirrored primitive's are flipped on loading).
    std::vector<uint32_t> a_file = a.indices, b_file = b.indices;
    to_file_winding(a, a_file.data());
    to_file_winding(b, b_file.data());

    // The keyframes compared: the first of up to four clips both files have, else keyframe 0. A clip
    // pairs with the clip of its name in the other file; where several share a name (Mixamo's
    // "mixamo.com", "Take 001"), the n-th of that name in one with the n-th in the other, when both
    // files have as many of it (else, one of them dropped, none of that name is compared).
    std::vector<size_t> ka, kb;
    const auto named = [](const AnimatedMesh& m, const std::string& name) {
        std::vector<const Clip*> out;
        for (const Clip& c : m.clips)
            if (c.name == name) out.push_back(&c);
        return out;
    };
    for (const Clip& ca : a.clips) {
        const std::vector<const Clip*> in_a = named(a, ca.name), in_b = named(b, ca.name);
        if (in_a.size() != in_b.size()) continue;
        const size_t rank = size_t(std::find(in_a.begin(), in_a.end(), &ca) - in_a.begin());
        if (ka.size() < 4) ka.push_back(ca.first_keyframe), kb.push_back(in_b[rank]->first_keyframe);
    }
    const bool unpaired = ka.empty();
    if (unpaired) ka = {0}, kb = {0};

    // OPTIMIZED's primitives with orders, and each order as a permutation of its drawn triangles.
    struct Source {
        const ExtensionPrimitive* ext;
        size_t first_triangle, triangles;
        std::vector<std::vector<uint32_t>> order_triangles;  // per order: triangle positions in `indices`
    };
    std::vector<Source> sources;
    std::vector<size_t> a_triangles;
    for (const Primitive& p : a.primitives)
        for (const ExtensionPrimitive& e : orders.primitives)
            if (e.mesh == p.source_mesh && e.primitive == p.source_primitive) {
                if (e.indices.size() != p.index_count)
                    throw std::runtime_error(options.optimized + ": primitive " + std::to_string(e.mesh) + "/" +
                                             std::to_string(e.primitive) + " reads back with another index count");
                for (size_t i = 0; i < p.index_count; ++i)
                    if (a_file[p.first_index + i] != e.indices[i] + p.vertex_base)
                        throw std::runtime_error(options.optimized + ": primitive " + std::to_string(e.mesh) + "/" +
                                                 std::to_string(e.primitive) + " reads back with other indices");
                Source s{&e, p.first_index / 3, p.index_count / 3, {}};
                const size_t n = e.indices.size();
                for (uint32_t o = 0; o < e.order_count; ++o)
                    s.order_triangles.push_back(triangle_permutation(e.indices.data(), e.orders.data() + o * n, n / 3));
                for (size_t t = 0; t < s.triangles; ++t) a_triangles.push_back(s.first_triangle + t);
                sources.push_back(std::move(s));
            }
    if (sources.empty()) throw std::runtime_error(options.optimized + ": no primitive with orders reads back");
    std::vector<size_t> b_triangles(b.triangle_count());
    for (size_t t = 0; t < b_triangles.size(); ++t) b_triangles[t] = t;

    // Tolerance: relative to the diagonal of OPTIMIZED's first compared keyframe.
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t v = 0; v < a.vertex_count; ++v)
        for (int c = 0; c < 3; ++c)
            lo[c] = std::min(lo[c], a.keyframe(ka[0])[3 * v + size_t(c)]),
            hi[c] = std::max(hi[c], a.keyframe(ka[0])[3 * v + size_t(c)]);
    const float diagonal = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                     (hi[2] - lo[2]) * (hi[2] - lo[2]));
    if (unpaired) {
        // No clip pairs by name (a pipeline dropped some animations, or all of them): the first
        // keyframes of the pair of clips, one of each file, that matches most triangles (a still
        // copy's one keyframe included), among the first 8 clips of each.
        size_t best = 0;
        for (size_t i = 0; i < a.clips.size() && i < 8; ++i)
            for (size_t j = 0; j < b.clips.size() && j < 8; ++j) {
                const TriangleMatch trial = match_triangles(corners(a, a_triangles, {a.clips[i].first_keyframe}),
                                                            corners(b, b_triangles, {b.clips[j].first_keyframe}), 3,
                                                            float(options.tolerance) * diagonal);
                if (trial.matched > best)
                    best = trial.matched, ka = {a.clips[i].first_keyframe}, kb = {b.clips[j].first_keyframe};
            }
    }
    // Both files' corners at the compared keyframes, made once for every search below.
    const std::vector<float> a_corners = corners(a, a_triangles, ka), b_corners = corners(b, b_triangles, kb);
    const TriangleMatch m = match_triangles(a_corners, b_corners, 3 * ka.size(), float(options.tolerance) * diagonal);
    // Per triangle of OPTIMIZED (global index): its triangle of PROCESSED.
    std::vector<int64_t> b_of_a(a.triangle_count(), -1);
    for (size_t t = 0; t < m.from_of_to.size(); ++t)
        if (m.from_of_to[t] >= 0) b_of_a[a_triangles[size_t(m.from_of_to[t])]] = int64_t(t);
    if (!options.quiet)
        std::fprintf(stderr, "animorder: matched %zu of %zu optimised triangles to %zu processed triangles\n",
                     m.matched, a_triangles.size(), b.triangle_count());
    // A triangle with a repeated vertex draws nothing, and pipelines drop it (gltfpack does): its
    // absence is no change of the mesh, and the orders skip it. Any other one must be found.
    size_t dropped = 0;
    for (const size_t t : a_triangles) {
        const uint32_t* corner = &a.indices[3 * t];
        dropped += b_of_a[t] < 0 && (corner[0] == corner[1] || corner[1] == corner[2] || corner[0] == corner[2]);
    }
    // Per triangle of PROCESSED: the optimised triangle (global index) it is, or stands for.
    std::vector<int64_t> source(b.triangle_count(), -1);
    for (size_t t = 0; t < m.from_of_to.size(); ++t)
        if (m.from_of_to[t] >= 0) source[t] = int64_t(a_triangles[size_t(m.from_of_to[t])]);
    size_t near = 0;
    // Per processed triangle beyond --nearest: how far the nearest optimised one lies, as a fraction
    // of the diagonal (0 for the others).
    std::vector<double> beyond(b.triangle_count(), 0);
    if (options.nearest > 0) {
        std::vector<size_t> missing;
        for (size_t t = 0; t < source.size(); ++t)
            if (source[t] < 0) missing.push_back(t);
        // Centroid distances over the compared keyframes, as one keyframe's: divided by √keyframes.
        const NearestTriangles n = nearest_triangles(a_corners, corners(b, missing, kb), 3 * ka.size());
        const double limit = options.nearest * diagonal * std::sqrt(double(ka.size()));
        for (size_t i = 0; i < missing.size() && !n.from_of_to.empty(); ++i) {
            if (n.distance[i] > limit) {
                beyond[missing[i]] = n.distance[i] / (diagonal * std::sqrt(double(ka.size())));
                continue;
            }
            source[missing[i]] = int64_t(a_triangles[n.from_of_to[i]]);
            ++near;
        }
        if (!options.quiet)
            std::fprintf(stderr, "animorder: %zu of %zu other processed triangles lie within --nearest %s of an optimised one\n",
                         near, missing.size(), shown(options.nearest).c_str());
    } else if (m.matched + dropped != a_triangles.size()) {
        // A mesh left as it was whose animation a pipeline resampled or quantised (gltfpack's
        // defaults) poses its corners a little apart: say which tolerance would match them all.
        std::string wider;
        for (const double factor : {10.0, 100.0}) {
            const TriangleMatch trial =
                match_triangles(a_corners, b_corners, 3 * ka.size(), float(options.tolerance * factor) * diagonal);
            if (trial.matched + dropped != a_triangles.size()) continue;
            wider = "; all are found at --tolerance " + shown(options.tolerance * factor) +
                    " (the posed corners moved: was the animation resampled or quantised?)";
            break;
        }
        throw std::runtime_error(options.processed + ": only " + std::to_string(m.matched) + " of " +
                                 std::to_string(a_triangles.size() - dropped) + " optimised triangles found within " +
                                 "--tolerance " + shown(options.tolerance) +
                                 " (changed mesh? a simplified one takes --nearest 0.1)" + wider + "; nothing written");
    }

    // Per order, each optimised triangle's place: its source's rank among the sources, then its
    // position in that source's order (the sequence the orders draw OPTIMIZED's triangles in).
    std::vector<std::vector<uint32_t>> rank(orders.buffer_count, std::vector<uint32_t>(a.triangle_count(), 0));
    for (uint32_t o = 0; o < orders.buffer_count; ++o) {
        uint32_t at = 0;
        for (const Source& src : sources)
            for (const uint32_t q : src.order_triangles[o]) rank[o][src.first_triangle + q] = at++;
    }
    std::vector<PrimitiveOrders> out;
    std::map<std::pair<int, int>, size_t> seen;
    // Processed primitives none of whose triangles is OPTIMIZED's (new geometry, or a copy of a
    // primitive whose triangles the first copy matched): kept in their own order, and said so.
    std::string unordered;
    size_t unordered_primitives = 0, unordered_triangles = 0;
    for (const Primitive& p : b.primitives) {
        const size_t first = p.first_index / 3, last = first + p.index_count / 3;
        size_t hits = 0;
        for (size_t t = first; t < last; ++t) hits += source[t] >= 0;
        if (hits == 0) {
            unordered += (unordered.empty() ? "" : ", ") + p.name;
            ++unordered_primitives;
            unordered_triangles += p.index_count / 3;
            continue;
        }
        double farthest = 0;
        for (size_t t = first; t < last; ++t) farthest = std::max(farthest, beyond[t]);
        if (hits != p.index_count / 3)
            throw std::runtime_error(
                options.processed + ": primitive " + p.name + " holds " + std::to_string(p.index_count / 3 - hits) +
                " triangles that are not OPTIMIZED's" +
                (options.nearest > 0 ? " nor within --nearest " + shown(options.nearest) +
                                           " of one (the farthest lies " + shown(farthest) + " away)"
                                     : std::string()) +
                " (changed mesh?); nothing written");
        PrimitiveOrders po;
        po.mesh = p.source_mesh, po.primitive = p.source_primitive;
        std::vector<uint32_t> drawn(p.index_count / 3);
        for (uint32_t o = 0; o < orders.buffer_count; ++o) {
            // The processed triangles in the order of the optimised ones they are or stand for.
            std::iota(drawn.begin(), drawn.end(), uint32_t(first));
            std::stable_sort(drawn.begin(), drawn.end(), [&](uint32_t x, uint32_t y) {
                return rank[o][size_t(source[x])] < rank[o][size_t(source[y])];
            });
            for (const uint32_t t : drawn)
                for (size_t c = 0; c < 3; ++c) po.orders.push_back(uint32_t(b_file[3 * size_t(t) + c] - p.vertex_base));
        }
        // A mesh several nodes draw (instances) has one index buffer: written once, when every
        // instance's orders agree (OPTIMIZED's instances share theirs, so they do unless the
        // pipeline changed one of them).
        const auto [at, first_instance] = seen.emplace(std::make_pair(p.source_mesh, p.source_primitive), out.size());
        if (first_instance)
            out.push_back(std::move(po));
        else if (out[at->second].orders != po.orders)
            throw std::runtime_error(options.processed + ": mesh " + std::to_string(p.source_mesh) +
                                     " is drawn by several nodes whose optimised triangles come in different orders; "
                                     "nothing written");
    }
    if (near > 0) {
        // A simplified mesh frames a little apart from the optimised one (its extremities cut
        // short): each clip's centres become the processed mesh's frame centres, where an
        // engine's lookup (and `check`) takes them from. The n-th clip of a name takes the n-th
        // of PROCESSED's clips of that name.
        const Framing framing = frame_animated_mesh(b);
        std::map<std::string, size_t> seen_of_name;
        for (ExtensionClip& c : orders.clips) {
            size_t nth = seen_of_name[c.name]++;
            for (const Clip& clip : b.clips) {
                if (clip.name != c.name || nth-- != 0) continue;
                if (clip.keyframe_count != c.keyframes) {
                    if (!options.quiet)
                        std::fprintf(stderr,
                                     "animorder: note: clip '%s' has %zu keyframes in %s, %u in the orders: its "
                                     "centres stay OPTIMIZED's\n",
                                     printable(c.name).c_str(), size_t(clip.keyframe_count), options.processed.c_str(),
                                     c.keyframes);
                    break;
                }
                c.centers = std::vector<float>(framing.centres.begin() + long(3 * clip.first_keyframe),
                                               framing.centres.begin() + long(3 * (clip.first_keyframe + c.keyframes)));
                break;
            }
        }
    }
    if (out.empty())
        throw std::runtime_error(options.processed + ": no primitive whose triangles are OPTIMIZED's" +
                                 (options.nearest > 0 ? " or lie within --nearest " + shown(options.nearest) + " of them"
                                                      : std::string()) +
                                 "; nothing written");
    std::string kept;
    const std::string bytes =
        gltf_with_extension_orders(options.processed, options.output, orders, out, extension == ".glb", &kept);
    write_file_atomically(options.output, bytes);
    if (!kept.empty() && !options.quiet) std::fprintf(stderr, "animorder: note: %s\n", kept.c_str());
    if (unordered_primitives > 0 && !options.quiet)
        std::fprintf(stderr,
                     "animorder: note: %zu primitive(s) of %s (%s: %zu triangles) match no optimised triangle: "
                     "written without orders\n",
                     unordered_primitives, options.processed.c_str(), unordered.c_str(), unordered_triangles);
    std::printf("reapplied %u orders: %zu of %zu triangles matched", orders.buffer_count, m.matched, a_triangles.size());
    if (options.nearest > 0)
        std::printf(", %zu processed triangles placed by the nearest optimised one", near);
    std::printf(", %zu primitive(s)", out.size());
    if (unordered_primitives > 0)
        std::printf(", %zu without orders (%zu triangles no optimised one matches)", unordered_primitives,
                    unordered_triangles);
    std::printf("; wrote %s\n", options.output.c_str());
    return 0;
}

}  // namespace animorder::tool
