// Per-node cost of the overdraw engine on one thread (issue 19): NodeRasterizer::rasterize_validated
// from the keyframe's centred positions (the transform to clip space in its vertex pass; centring,
// once a keyframe, is "transform") and the FacingFilter's candidates (the filter's time included;
// then the widest copy again from every triangle, in the same run, for the filter's worth),
// keep_fragments and score_kept (1 and 5 random patch orders); then every node both from centred
// positions and from clip space (transform_to_clip per node), in turns, for the fused transform's worth;
// as CPU time of this thread (CLOCK_THREAD_CPUTIME_ID, so other processes on a shared machine do
// not count), over a spread of nodes of a character (default protocol: 162 views, 256², λ = 0.85).
// Also prints hashes: the rasteriser's output (raw fragments in order, grouped lists, counts), the
// kept nodes, and the scores: two builds that print the same hash produced the same bits. A plain
// runner, never a test.
//
//   build/bench/bench_raster ../shared/data/glb-xbot/Xbot.glb
//   build/bench/bench_raster ../shared/data/mixamo-ganfaul/Ganfaul.gltf --clip Idle [--keyframes 4] [--repeat 2]
//   ... --simd 0|1|2: at most the rasteriser's portable, AVX2 or AVX-512 copy (NodeRasterizer::Copy;
//       default: the widest this CPU runs, what the pipeline runs, marked "(default)")
//   ... --simd all: every copy this CPU runs, narrowest first, in the same run, with each wide
//       copy's speed against the portable one's and whether their hashes agree
#include "animorder/camera.h"
#include "animorder/facing_filter.h"
#include "animorder/kept_fragments.h"
#include "animorder/load.h"
#include "animorder/mesh_patches.h"
#include "animorder/overdraw.h"
#include "animorder/rasterizer.h"
#include "animorder/triangle_order.h"
#include "animorder/viewpoints.h"

#include "machine.h"

#include <time.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

using namespace animorder;

namespace {

double thread_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// FNV-1a over bytes.
struct Hash {
    uint64_t h = 1469598103934665603ull;
    void add(const void* data, size_t bytes) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
    }
    template <typename T>
    void value(const T& v) {
        add(&v, sizeof v);
    }
};

}  // namespace

int main(int argc, char** argv) try {
    if (argc < 2) {
        std::fprintf(stderr,
                     "usage: bench_raster CHARACTER [--clip NAME] [--keyframes N] [--repeat N] [--simd 0|1|2|all]\n");
        return 1;
    }
    std::vector<std::string> clips;
    size_t keyframe_samples = 4, repeats = 2;
    using Copy = NodeRasterizer::Copy;
    const Copy widest = NodeRasterizer::widest_copy();
    std::vector<Copy> copies = {widest};  // the rasteriser's copies to time
    for (int i = 2; i + 1 < argc; i += 2) {
        if (!std::strcmp(argv[i], "--clip"))
            clips.push_back(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--keyframes"))
            keyframe_samples = std::strtoul(argv[i + 1], nullptr, 10);
        else if (!std::strcmp(argv[i], "--repeat"))
            repeats = std::strtoul(argv[i + 1], nullptr, 10);
        else if (!std::strcmp(argv[i], "--simd") && !std::strcmp(argv[i + 1], "all")) {
            copies.clear();
            for (const Copy c : {Copy::Portable, Copy::Avx2, Copy::Avx512})
                if (c <= widest) copies.push_back(c);
        } else if (!std::strcmp(argv[i], "--simd") && std::strlen(argv[i + 1]) == 1 && argv[i + 1][0] >= '0' &&
                   argv[i + 1][0] <= '2')
            copies = {std::min(widest, Copy(argv[i + 1][0] - '0'))};
        else {
            std::fprintf(stderr, "bench_raster: unknown option %s\n", argv[i]);
            return 1;
        }
    }
    std::printf("machine: %s\n", bench::machine_description().c_str());
    AnimatedMesh mesh = load_character(argv[1]);
    if (!clips.empty()) mesh = select_clips(mesh, clips);
    const Framing framing = frame_animated_mesh(mesh);
    const MeshPatches patches = build_mesh_patches(mesh, 0.85);
    const UnitPartition partition = make_unit_partition(patches.patch_starts.data(), patches.patch_count(),
                                                        patches.cache_order.data(), mesh.triangle_count());
    const std::vector<float> directions = icosphere_directions(icosphere_subdivisions_for(162));
    const size_t views = directions.size() / 3;
    const std::vector<uint8_t> modes = opaque_pass_modes(mesh);
    const size_t step = std::max<size_t>(1, mesh.keyframe_count() / std::max<size_t>(1, keyframe_samples));

    std::vector<float> clip(mesh.vertex_count * 4);
    validate_indices(mesh.indices.data(), mesh.indices.size(), mesh.vertex_count);  // once, as NodeCache does
    struct Timing {
        double rasterize_ms = 0;
        uint64_t hash = 0;
    };
    // Random unit orders (whole patches in their inner order) for timing score_kept.
    std::vector<std::vector<uint32_t>> unit_orders;
    {
        uint64_t state = 12345;
        for (int o = 0; o < 5; ++o) {
            std::vector<uint32_t> patch_order(patches.patch_count());
            for (size_t i = 0; i < patch_order.size(); ++i) patch_order[i] = uint32_t(i);
            for (size_t i = patch_order.size(); i > 1; --i) {
                state = state * 6364136223846793005ULL + 1442695040888963407ULL;
                std::swap(patch_order[i - 1], patch_order[(state >> 33) % i]);
            }
            unit_orders.push_back(patch_order_to_triangle_order(patches, patch_order));
        }
    }
    const auto rank_tables = [&](size_t count) {
        std::vector<const uint32_t*> pointers;
        for (size_t o = 0; o < count; ++o) pointers.push_back(unit_orders[o].data());
        return make_rank_table(pointers, mesh.triangle_count());
    };
    const std::vector<uint32_t> ranks1 = rank_tables(1), ranks5 = rank_tables(5);
    const std::vector<uint16_t> unit_ranks1 = make_unit_rank_table(ranks1.data(), 1, partition),
                                unit_ranks5 = make_unit_rank_table(ranks5.data(), 5, partition);
    // As NodeCache's workers: the keyframe's positions centred once (its share of that is
    // "transform"), the transform to clip space inside the rasteriser's vertex pass.
    const auto measure = [&](Copy copy, bool filtered) {
        NodeRasterizer rasterizer;
        rasterizer.set_copy(copy);
        KeepScratch scratch;
        FacingFilter facing;
        CentredKeyframe centred;
        size_t facing_keyframe = SIZE_MAX;
        double candidates = 0;
        double transform_s = 0, raster_s = 0, keep_s = 0, score1_s = 0, score5_s = 0, replay5_s = 0;
        Hash score_hash;  // the scores of the random unit orders
        size_t nodes = 0, fragments = 0;
        Hash hash;
        Hash kept_hash;  // every KeptNode whole (counts and data): equal between builds = same kept nodes
        double multi = 0, unit_lists = 0, unit_entries = 0, triangle_lists = 0;
        for (size_t rep = 0; rep < repeats; ++rep)
            for (size_t k = 0; k < mesh.keyframe_count(); k += step)
                for (size_t v = 0; v < views; ++v) {
                    const double t0 = thread_seconds();
                    centred.centre(mesh.keyframe(uint32_t(k)), mesh.vertex_count, &framing.centres[3 * k]);
                    const NodeRasterizer::CentredVertices vertices =
                        centred.vertices(node_view_projection(&directions[3 * v], framing.radius));
                    transform_s += thread_seconds() - t0;
                    if (facing_keyframe != k) {  // once per keyframe, as NodeCache's workers do (not timed)
                        facing.build(mesh.keyframe(uint32_t(k)), mesh.vertex_count, mesh.indices.data(),
                                     mesh.indices.size(), &framing.centres[3 * k], framing.radius, 256,
                                     modes.empty() ? nullptr : modes.data());
                        facing_keyframe = k;
                    }
                    const double t1 = thread_seconds();
                    const FacingFilter::Candidates listed =
                        filtered ? facing.candidates(&directions[3 * v]) : FacingFilter::Candidates{nullptr, 0};
                    rasterizer.rasterize_validated(vertices, mesh.vertex_count, mesh.indices.data(),
                                                   mesh.indices.size(), 256, modes.empty() ? nullptr : modes.data(),
                                                   listed.ids, listed.count);
                    const double t2 = thread_seconds();
                    candidates += double(listed.ids ? listed.count : mesh.triangle_count());
                    const NodeRasterizer::FragmentLists lists = rasterizer.fragment_lists();
                    const KeptNode kept = keep_fragments(lists.visible, lists.single, lists.starts, lists.pixels,
                                                         lists.fragments, partition, scratch);
                    const double t3 = thread_seconds();
                    uint64_t passed[5];
                    rasterizer.score(passed, ranks5.data(), 5);  // the engine's own replay (score_nodes)
                    for (const uint64_t p : passed) score_hash.value(p);
                    const double t3b = thread_seconds();
                    replay5_s += t3b - t3;
                    score_kept(passed, kept, unit_ranks1.data(), ranks1.data(), 1);
                    score_hash.value(passed[0]);
                    const double t4 = thread_seconds();
                    score1_s += t4 - t3b;
                    score_kept(passed, kept, unit_ranks5.data(), ranks5.data(), 5);
                    for (const uint64_t p : passed) score_hash.value(p);
                    const double t5 = thread_seconds();
                    score5_s += t5 - t4;
                    raster_s += t2 - t1;
                    keep_s += t3 - t2;
                    ++nodes;
                    fragments += rasterizer.fragments();
                    if (rep == 0) {
                        rasterizer.visit_fragments([&](uint32_t p, uint32_t t, float z) {
                            hash.value(p);
                            hash.value(t);
                            hash.value(z);
                        });
                        hash.value(lists.visible);
                        hash.value(lists.single);
                        hash.value(lists.pixels);
                        if (lists.pixels) {
                            hash.add(lists.starts, (lists.pixels + 1) * 4);
                            hash.add(lists.fragments + lists.starts[0],
                                     (lists.starts[lists.pixels] - lists.starts[0]) * 4);
                        }
                        kept_hash.value(kept.visible);
                        kept_hash.value(kept.single);
                        kept_hash.value(kept.unit_lists);
                        kept_hash.value(kept.unit_entries);
                        kept_hash.value(kept.triangle_lists);
                        kept_hash.value(kept.triangle_entries);
                        kept_hash.add(kept.data.data(), kept.data.size());
                        multi += double(lists.pixels);
                        unit_lists += kept.unit_lists;
                        unit_entries += kept.unit_entries;
                        triangle_lists += kept.triangle_lists;
                    }
                }
        std::printf("%s copy%s%s: ", NodeRasterizer::copy_name(copy), copy == widest ? " (default)" : "",
                    filtered ? "" : ", facing filter off");
        std::printf(
            "%zu triangles, %zu nodes, %.0f fragments/node: transform %.3f ms/node, rasterize %.3f ms/node, "
            "keep %.3f ms/node (thread CPU time); output hash %016llx\n",
            mesh.triangle_count(), nodes, double(fragments) / double(nodes), 1e3 * transform_s / double(nodes),
            1e3 * raster_s / double(nodes), 1e3 * keep_s / double(nodes), (unsigned long long)hash.h);
        std::printf(
            "  score_kept of random patch orders: 1 order %.4f ms/node, 5 orders %.4f ms/node; the rasteriser's "
            "own replay of 5 orders %.4f ms/node; score hash %016llx\n",
            1e3 * score1_s / double(nodes), 1e3 * score5_s / double(nodes), 1e3 * replay5_s / double(nodes),
            (unsigned long long)score_hash.h);
        const double hashed = double(nodes / std::max<size_t>(1, repeats));
        std::printf(
            "  kept per node: %.0f multi-fragment pixels -> %.0f unit lists (%.0f entries), %.0f triangle "
            "lists; kept hash %016llx\n",
            multi / hashed, unit_lists / hashed, unit_entries / hashed, triangle_lists / hashed,
            (unsigned long long)kept_hash.h);
        std::printf("  facing filter %s: %.0f of %zu triangles rasterised per node\n", filtered ? "on" : "off",
                    candidates / double(nodes), mesh.triangle_count());
        return Timing{1e3 * raster_s / double(nodes), hash.h};
    };
    std::vector<Timing> timings;
    for (const Copy copy : copies) timings.push_back(measure(copy, true));
    // The widest copy again from every triangle (the filter off): the filter's worth, same run.
    const Timing unfiltered = measure(copies.back(), false);
    // The transform inside the vertex pass against transforming each node to a clip-space array
    // first (transform_to_clip, then the clip-space entry): every node both ways, in turns (which
    // goes first alternates node by node, so neither gains from going second), in the widest
    // copy from the facing filter's candidates; both must give the same fragments.
    {
        NodeRasterizer rasterizer;
        rasterizer.set_copy(copies.back());
        FacingFilter facing;
        CentredKeyframe centred;
        double seconds[2] = {0, 0};  // centred, clip space
        Hash hashes[2];
        size_t nodes = 0;
        for (size_t k = 0; k < mesh.keyframe_count(); k += step) {
            facing.build(mesh.keyframe(uint32_t(k)), mesh.vertex_count, mesh.indices.data(), mesh.indices.size(),
                         &framing.centres[3 * k], framing.radius, 256, modes.empty() ? nullptr : modes.data());
            for (size_t v = 0; v < views; ++v, ++nodes) {
                const FacingFilter::Candidates listed = facing.candidates(&directions[3 * v]);
                const Mat4d vp = node_view_projection(&directions[3 * v], framing.radius);
                for (size_t turn = 0; turn < 2; ++turn) {
                    const size_t way = (turn + nodes) % 2;
                    const double t0 = thread_seconds();
                    if (way == 0) {
                        centred.centre(mesh.keyframe(uint32_t(k)), mesh.vertex_count, &framing.centres[3 * k]);
                        rasterizer.rasterize_validated(centred.vertices(vp), mesh.vertex_count, mesh.indices.data(),
                                                       mesh.indices.size(), 256,
                                                       modes.empty() ? nullptr : modes.data(), listed.ids,
                                                       listed.count);
                    } else {
                        transform_to_clip(clip.data(), mesh.keyframe(uint32_t(k)), mesh.vertex_count,
                                          &framing.centres[3 * k], vp);
                        rasterizer.rasterize_validated(clip.data(), mesh.vertex_count, mesh.indices.data(),
                                                       mesh.indices.size(), 256,
                                                       modes.empty() ? nullptr : modes.data(), listed.ids,
                                                       listed.count);
                    }
                    seconds[way] += thread_seconds() - t0;
                    rasterizer.visit_fragments([&](uint32_t p, uint32_t t, float z) {
                        hashes[way].value(p);
                        hashes[way].value(t);
                        hashes[way].value(z);
                    });
                }
            }
        }
        const double centred_ms = 1e3 * seconds[0] / double(nodes), clip_ms = 1e3 * seconds[1] / double(nodes);
        std::printf("transform and rasterize (%s copy, each node both ways in turns): %.3f ms/node from centred "
                    "positions, %.3f from clip space: %.2fx; hashes %s\n",
                    NodeRasterizer::copy_name(copies.back()), centred_ms, clip_ms, clip_ms / centred_ms,
                    hashes[0].h == hashes[1].h ? "equal" : "DIFFER");
    }
    std::printf("rasterize: %.2fx faster with the facing filter (%s copy); hashes %s\n",
                unfiltered.rasterize_ms / timings.back().rasterize_ms, NodeRasterizer::copy_name(copies.back()),
                unfiltered.hash == timings.back().hash ? "equal" : "DIFFER");
    for (size_t i = 1; i < timings.size() && copies[0] == Copy::Portable; ++i)
        std::printf("rasterize: %s copy %.2fx the portable copy's speed; hashes %s\n",
                    NodeRasterizer::copy_name(copies[i]), timings[0].rasterize_ms / timings[i].rasterize_ms,
                    timings[0].hash == timings[i].hash ? "equal" : "DIFFER");
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "bench_raster: %s\n", e.what());
    return 1;
}
