// The overdraw engine against the OpenGL reference, in the same process: scoring k = 5 orders
// of a character at a few hundred nodes, ms per node for each and their ratio; then the engine's
// scaling with triangles and resolution. A plain runner. Each figure is the fastest of 5 runs: load
// from other work on this shared machine only ever adds time, and the engine's runs are short
// (tens of milliseconds at 2 threads), so one stall moved a median of 3 by half.
//
//   build/bench/bench_overdraw            (Ganfaul from ../shared/data is used when present)
#include "animorder/animated_mesh.h"
#include "animorder/camera.h"
#include "animorder/overdraw.h"
#include "animorder/procedural_character.h"
#include "animorder/procedural_shapes.h"
#include "animorder/triangle_order.h"
#include "animorder/viewpoints.h"
#ifdef ANIMORDER_HAVE_GL
#include "gl_overdraw.h"
#endif

#include "machine.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <random>
#include <vector>

using namespace animorder;
using Clock = std::chrono::steady_clock;

namespace {

double fastest_seconds(const std::function<void()>& run) {
    double fastest = INFINITY;
    for (int i = 0; i < 5; ++i) {
        const auto start = Clock::now();
        run();
        fastest = std::min(fastest, std::chrono::duration<double>(Clock::now() - start).count());
    }
    return fastest;
}

struct Workload {
    std::vector<OverdrawNode> nodes;
    std::vector<std::vector<uint32_t>> orders;
    std::vector<uint32_t> ranks;
    Framing framing;
};

Workload make_workload(const AnimatedMesh& mesh, size_t keyframe_step, unsigned subdivisions) {
    Workload w;
    w.framing = frame_animated_mesh(mesh);
    const std::vector<float> dirs = icosphere_directions(subdivisions);
    for (uint32_t k = 0; k < mesh.keyframe_count(); k += uint32_t(keyframe_step))
        for (size_t v = 0; v < dirs.size() / 3; ++v) {
            OverdrawNode n;
            n.keyframe = k;
            std::copy(&dirs[3 * v], &dirs[3 * v] + 3, n.direction);
            w.nodes.push_back(n);
        }
    const size_t t = mesh.triangle_count();
    std::mt19937 rng(3);
    for (int o = 0; o < 5; ++o) {
        std::vector<uint32_t> order(t);
        for (size_t i = 0; i < t; ++i) order[i] = uint32_t(i);
        if (o > 0)
            for (size_t i = t; i > 1; --i) std::swap(order[i - 1], order[rng() % i]);
        w.orders.push_back(order);
    }
    std::vector<const uint32_t*> pointers;
    for (const auto& o : w.orders) pointers.push_back(o.data());
    w.ranks = make_rank_table(pointers, t);
    return w;
}

double engine_ms_per_node(const AnimatedMesh& mesh, const Workload& w, unsigned resolution, unsigned threads) {
    std::vector<uint64_t> visible(w.nodes.size()), passed(w.nodes.size() * 5);
    ScoreSettings s;
    s.resolution = resolution;
    s.threads = threads;
    const double seconds = fastest_seconds([&] {
        score_nodes(visible.data(), passed.data(), mesh.keyframe_positions.data(), mesh.vertex_count, w.framing,
                    mesh.indices.data(), mesh.indices.size(), w.nodes.data(), w.nodes.size(), w.ranks.data(), 5, s);
    });
    return 1e3 * seconds / double(w.nodes.size());
}

void compare_with_gl(const AnimatedMesh& mesh, size_t keyframe_step) {
    const Workload w = make_workload(mesh, keyframe_step, 1);
    const double one = engine_ms_per_node(mesh, w, 256, 1), two = engine_ms_per_node(mesh, w, 256, 2);
    std::printf("%-34s %6zu tris %5zu nodes  engine %.3f ms/node (1 thread) %.3f ms/node (2 threads)",
                mesh.name.c_str(), mesh.triangle_count(), w.nodes.size(), one, two);
#ifdef ANIMORDER_HAVE_GL
    try {
        GlOverdrawReference gl(256);
        std::vector<std::vector<uint32_t>> buffers;
        for (const auto& o : w.orders) {
            buffers.emplace_back(mesh.indices.size());
            apply_triangle_order(buffers.back().data(), mesh.indices.data(), o.data(), o.size());
        }
        std::vector<float> clip(mesh.vertex_count * 4);
        const double seconds = fastest_seconds([&] {
            for (const OverdrawNode& n : w.nodes) {
                transform_to_clip(clip.data(), mesh.keyframe(n.keyframe), mesh.vertex_count,
                                  &w.framing.centres[3 * n.keyframe],
                                  node_view_projection(n.direction, w.framing.radius));
                gl.score(clip.data(), mesh.vertex_count, buffers);
            }
        });
        const double gl_ms = 1e3 * seconds / double(w.nodes.size());
        std::printf("  OpenGL (%s) %.3f ms/node  ratio %.1fx\n", gl.renderer().c_str(), gl_ms, gl_ms / two);
    } catch (const std::exception& e) {
        std::printf("  OpenGL unavailable: %s\n", e.what());
    }
#else
    std::printf("  (built without the OpenGL reference)\n");
#endif
}

}  // namespace

int main(int argc, char** argv) {
    if (argc > 1) {  // it takes no option: --help says so, anything else is an error; neither runs it
        const bool help = std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0;
        std::fprintf(help ? stdout : stderr,
                     "usage: bench_overdraw  (no options; Ganfaul from ../shared/data when present)\n");
        return help ? 0 : 2;
    }
    std::printf("machine: %s\n", animorder::bench::machine_description().c_str());
    std::printf("k = 5 orders per node, 256x256, 42 icosphere views per keyframe\n");
    compare_with_gl(make_procedural_character(), 8);
    std::printf("\nScaling (engine, 2 threads, 5 orders, 42 views of a static mesh):\n");
    for (size_t n : {13000u, 55000u, 220000u}) {
        const AnimatedMesh knot = make_torus_knot(n);
        const Workload w = make_workload(knot, 1, 1);
        std::printf("torus-knot %6zu tris: %.3f ms/node at 256^2, %.3f ms/node at 512^2\n", knot.triangle_count(),
                    engine_ms_per_node(knot, w, 256, 2), engine_ms_per_node(knot, w, 512, 2));
    }
    return 0;
}
