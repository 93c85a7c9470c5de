// static-nehab06 (Nehab, Barczak & Sander 2006) timed stage by stage, against static-sander07 as
// a peer in the same run, on torus knots of ~2k, 10k and 70k triangles, the bundled character
// and (when ../shared/data has it) Mixamo's Ganfaul, with 42 and 162 views. Each row also gives
// the mean OVR of static-nehab06, static-sander07 and Tipsify alone over 40 random views at 256²
// (DESIGN.md camera, first keyframe), and ACMR. AMD Tootle took 0.7–3.3 s for 2k–70k triangles
// with 42 views. A plain runner: one run per row (the method's stages are reported inside).
//
//   build/bench/bench_nehab06 [--quick]     (--quick: knots of 2k and 10k only, 42 views)
#include "animorder/animated_mesh.h"
#include "animorder/load.h"
#include "animorder/nehab06.h"
#include "animorder/overdraw.h"
#include "animorder/procedural_character.h"
#include "animorder/procedural_shapes.h"
#include "animorder/static_sander07.h"
#include "animorder/tipsify.h"
#include "animorder/triangle_order.h"
#include "animorder/vertex_cache.h"
#include "animorder/viewpoints.h"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

using namespace animorder;
using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Mean OVR of each order over `views` random directions at the first keyframe.
std::vector<double> mean_ovr(const AnimatedMesh& mesh, const std::vector<const uint32_t*>& orders, size_t views) {
    const Framing framing =
        frame_keyframes(mesh.keyframe_positions.data(), 1, mesh.vertex_count, mesh.indices.data(), mesh.indices.size());
    const std::vector<float> d = random_sphere_directions(views, 20170501);
    std::vector<OverdrawNode> nodes(views);
    for (size_t v = 0; v < views; ++v)
        for (int i = 0; i < 3; ++i) nodes[v].direction[i] = d[3 * v + size_t(i)];
    const std::vector<uint32_t> ranks = make_rank_table(orders, mesh.triangle_count());
    std::vector<uint64_t> visible(views), passed(views * orders.size());
    ScoreSettings settings;
    settings.resolution = 256;
    score_nodes(visible.data(), passed.data(), mesh.keyframe_positions.data(), mesh.vertex_count, framing,
                mesh.indices.data(), mesh.indices.size(), nodes.data(), views, ranks.data(), orders.size(), settings);
    std::vector<double> ovr(orders.size(), 0);
    for (size_t o = 0; o < orders.size(); ++o) {
        size_t counted = 0;
        for (size_t v = 0; v < views; ++v)
            if (visible[v]) {
                ovr[o] += double(passed[v * orders.size() + o]) / double(visible[v]);
                ++counted;
            }
        ovr[o] /= double(counted);
    }
    return ovr;
}

double acmr(const AnimatedMesh& mesh, const std::vector<uint32_t>& order) {
    std::vector<uint32_t> ib(mesh.indices.size());
    apply_triangle_order(ib.data(), mesh.indices.data(), order.data(), order.size());
    return analyze_vertex_cache(ib.data(), ib.size(), mesh.vertex_count).acmr;
}

void row(const std::string& name, const AnimatedMesh& mesh, size_t views) {
    const size_t n = mesh.triangle_count();
    Nehab06Settings settings;
    settings.views = views;
    std::vector<uint32_t> nehab(n), sander(n), tips(n);
    Clock::time_point start = Clock::now();
    const Nehab06Result r =
        order_static_nehab06(nehab.data(), mesh.indices.data(), mesh.indices.size(), mesh.keyframe_positions.data(), 1,
                             mesh.vertex_count, nullptr, 0, settings);
    const double t_nehab = seconds_since(start);
    start = Clock::now();
    order_static_sander07(sander.data(), mesh.indices.data(), mesh.indices.size(), mesh.keyframe_positions.data(),
                          mesh.vertex_count, 12);
    const double t_sander = seconds_since(start);
    tipsify(tips.data(), mesh.indices.data(), mesh.indices.size(), mesh.vertex_count);
    const std::vector<double> ovr = mean_ovr(mesh, {nehab.data(), sander.data(), tips.data()}, 40);
    std::printf(
        "| %-16s | %6zu | %3zu | %4zu | %6.3f | %5.3f | %5.3f | %5.3f | %5.3f | %5.3f | %7.4f | %6.0f× | %.4f | "
        "%.4f | %.4f | %.3f | %.3f |\n",
        name.c_str(), n, views, r.cluster_count, t_nehab, r.seconds_clustering, r.seconds_rasterization,
        r.seconds_graph - r.seconds_rasterization, r.seconds_ordering, r.seconds_selection, t_sander,
        t_nehab / t_sander, ovr[0], ovr[1], ovr[2], acmr(mesh, nehab), acmr(mesh, tips));
    std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
    const bool quick = argc == 2 && std::strcmp(argv[1], "--quick") == 0;
    if (argc > 2 || (argc == 2 && !quick)) {  // --help included: say what it takes, run nothing
        const bool help = std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0;
        std::fprintf(help ? stdout : stderr, "usage: bench_nehab06 [--quick]  (--quick: knots of 2k and 10k only)\n");
        return help ? 0 : 2;
    }
    std::printf("static-nehab06 vs static-sander07 (automatic cluster count, 256², all hardware threads)\n\n");
    std::printf(
        "| mesh | tris | views | clusters | nehab06 s | clustering | raster | pairs | ordering | "
        "selection | sander07 s | ratio | OVR nehab06 | OVR sander07 | OVR tipsify | ACMR nehab06 | "
        "ACMR tipsify |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    std::vector<std::pair<std::string, AnimatedMesh>> meshes;
    for (size_t target : quick ? std::vector<size_t>{2000, 10000} : std::vector<size_t>{2000, 10000, 70000})
        meshes.push_back({"torus knot", make_torus_knot(target)});
    if (!quick) {
        meshes.push_back({"character", make_procedural_character()});
        const std::string ganfaul = ANIMORDER_SOURCE_DIR "/../shared/data/mixamo-ganfaul/Ganfaul.gltf";
        if (std::filesystem::exists(ganfaul))
            meshes.push_back({"Ganfaul", load_character(ganfaul)});
        else
            std::fprintf(stderr, "bench_nehab06: %s not found, skipped\n", ganfaul.c_str());
    }
    for (const auto& [name, mesh] : meshes)
        for (size_t views : quick ? std::vector<size_t>{42} : std::vector<size_t>{42, 162}) row(name, mesh, views);
    return 0;
}
