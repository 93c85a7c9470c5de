// Tipsify against meshoptimizer's implementation of the same paper
// (meshopt_optimizeVertexCacheFifo), in the same process, on procedural meshes of 10k/50k/200k
// triangles. Both produce a full index buffer (ours: tipsify_index_buffer) from the same
// shuffled input, cache 16, input validation included on our side. After the Google Benchmark table, a summary prints for each
// mesh the time ratio ours/meshoptimizer (≤ 1 means we are at least as fast) and both ACMRs.
//
//   build/bench/bench_tipsify --benchmark_repetitions=5 --benchmark_enable_random_interleaving=true
#include "animorder/animated_mesh.h"
#include "animorder/procedural_character.h"
#include "animorder/procedural_shapes.h"
#include "animorder/tipsify.h"
#include "animorder/triangle_order.h"
#include "animorder/vertex_cache.h"

#include <benchmark/benchmark.h>
#include <meshoptimizer.h>

#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

using namespace animorder;

namespace {

struct Fixture {
    std::string name;
    std::vector<uint32_t> indices;  // triangles shuffled: the optimisers must do real work
    size_t vertex_count = 0;
};

std::vector<uint32_t> shuffle_triangles(const std::vector<uint32_t>& ib) {
    const size_t n = ib.size() / 3;
    std::vector<uint32_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = uint32_t(i);
    std::mt19937 rng(42);
    for (size_t i = n; i > 1; --i) std::swap(order[i - 1], order[rng() % i]);
    std::vector<uint32_t> out(ib.size());
    apply_triangle_order(out.data(), ib.data(), order.data(), n);
    return out;
}

const std::vector<Fixture>& fixtures() {
    static const std::vector<Fixture> all = [] {
        std::vector<Fixture> list;
        for (size_t n : {10000u, 50000u, 200000u}) {
            for (AnimatedMesh mesh : {make_uv_sphere(n), make_torus_knot(n)}) {
                list.push_back({mesh.name + "/" + std::to_string(n / 1000) + "k", shuffle_triangles(mesh.indices),
                                mesh.vertex_count});
            }
        }
        const AnimatedMesh character = make_procedural_character();
        list.push_back({"character/" + std::to_string(character.triangle_count() / 1000) + "k",
                        shuffle_triangles(character.indices), character.vertex_count});
        return list;
    }();
    return all;
}

double acmr_of(const std::vector<uint32_t>& ib, size_t vertex_count) {
    return analyze_vertex_cache(ib.data(), ib.size(), vertex_count, 16).acmr;
}

void bm_animorder_tipsify(benchmark::State& state, const Fixture* f) {
    std::vector<uint32_t> out(f->indices.size());
    for (auto _ : state) {
        tipsify_index_buffer(out.data(), f->indices.data(), f->indices.size(), f->vertex_count, 16);
        benchmark::DoNotOptimize(out.data());
    }
    state.counters["acmr"] = acmr_of(out, f->vertex_count);
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(out.size() / 3));
}

void bm_meshopt_fifo(benchmark::State& state, const Fixture* f) {
    std::vector<uint32_t> out(f->indices.size());
    for (auto _ : state) {
        meshopt_optimizeVertexCacheFifo(out.data(), f->indices.data(), f->indices.size(), f->vertex_count, 16);
        benchmark::DoNotOptimize(out.data());
    }
    state.counters["acmr"] = acmr_of(out, f->vertex_count);
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(out.size() / 3));
}

// Collects per-benchmark mean times (and ACMR) to print the ratio table after the run.
class RatioReporter : public benchmark::ConsoleReporter {
public:
    void ReportRuns(const std::vector<Run>& runs) override {
        ConsoleReporter::ReportRuns(runs);
        for (const Run& run : runs) {
            if (run.error_occurred) continue;
            const bool aggregate = run.run_type == Run::RT_Aggregate;
            if (aggregate && run.aggregate_name != "median") continue;
            Entry& e = entries_[run.run_name.function_name];
            if (aggregate || !e.from_median) {
                e.time_ms = run.GetAdjustedRealTime();
                e.from_median = aggregate;
            }
            auto it = run.counters.find("acmr");
            if (it != run.counters.end()) e.acmr = it->second.value;
        }
    }
    void Finalize() override {
        ConsoleReporter::Finalize();
        std::printf("\n%-22s %12s %12s %8s %10s %10s\n", "mesh", "animorder", "meshopt", "ratio", "ACMR ours",
                    "ACMR meshopt");
        for (const Fixture& f : fixtures()) {
            const Entry& ours = entries_["tipsify/" + f.name];
            const Entry& theirs = entries_["meshopt_fifo/" + f.name];
            if (ours.time_ms <= 0 || theirs.time_ms <= 0) continue;
            std::printf("%-22s %10.3fms %10.3fms %8.3f %10.4f %10.4f\n", f.name.c_str(), ours.time_ms, theirs.time_ms,
                        ours.time_ms / theirs.time_ms, ours.acmr, theirs.acmr);
        }
    }

private:
    struct Entry {
        double time_ms = 0;  // per iteration (the benchmarks run in milliseconds)
        double acmr = 0;
        bool from_median = false;
    };
    std::map<std::string, Entry> entries_;
};

}  // namespace

int main(int argc, char** argv) {
    for (const Fixture& f : fixtures()) {
        benchmark::RegisterBenchmark(("tipsify/" + f.name).c_str(), bm_animorder_tipsify, &f)
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("meshopt_fifo/" + f.name).c_str(), bm_meshopt_fifo, &f)
            ->Unit(benchmark::kMillisecond);
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    RatioReporter reporter;
    benchmark::RunSpecifiedBenchmarks(&reporter);
    benchmark::Shutdown();
    return 0;
}
