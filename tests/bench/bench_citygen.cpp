// Google Benchmark of the generator's stages (not run by ctest).
//   build/tests/bench/bench_citygen --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Each stage is timed on the output of the previous ones for a city of side
// `state.range(0)` metres (default params otherwise, seed 1).
#include <benchmark/benchmark.h>

#include "citygen/blocks.h"
#include "citygen/buildings.h"
#include "citygen/generate.h"
#include "citygen/streets.h"
#include "citygen/trees.h"

using namespace vista;

namespace {

CityParams paramsOf(const benchmark::State& s) {
    CityParams p;
    p.size_m = double(s.range(0));
    p.seed = 1;
    return p;
}

void BM_Streets(benchmark::State& s) {
    CityParams p = paramsOf(s);
    size_t edges = 0;
    for (auto _ : s) edges = growStreets(p, nullptr).edges.size();
    s.counters["edges"] = double(edges);
}

void BM_BlocksAndLots(benchmark::State& s) {
    CityParams p = paramsOf(s);
    StreetGraph g = growStreets(p, nullptr);
    size_t lots = 0;
    for (auto _ : s) lots = subdivideLots(extractBlocks(g, p, nullptr), p, nullptr).size();
    s.counters["lots"] = double(lots);
}

void BM_BuildingMeshes(benchmark::State& s) {
    CityParams p = paramsOf(s);
    p.detail = int(s.range(1));
    StreetGraph g = growStreets(p, nullptr);
    auto blocks = extractBlocks(g, p, nullptr);
    auto lots = subdivideLots(blocks, p, nullptr);
    auto buildings = placeBuildings(lots, blocks, p, nullptr);
    Lighting light(p);
    size_t tris = 0;
    for (auto _ : s) {
        Mesh w, win, r;
        for (uint32_t i = 0; i < buildings.size(); ++i)
            meshBuilding(buildings[i], i, p, light, glm::dvec3(0.0), {&w, &win, &r});
        tris = w.triangleCount() + win.triangleCount() + r.triangleCount();
        benchmark::DoNotOptimize(tris);
    }
    s.counters["triangles"] = double(tris);
    s.counters["tri_per_s"] = benchmark::Counter(double(tris) * double(s.iterations()), benchmark::Counter::kIsRate);
}

void BM_GenerateCity(benchmark::State& s) {
    CityParams p = paramsOf(s);
    size_t tris = 0;
    for (auto _ : s) {
        auto c = generateCity(p);
        tris = countCity(*c).triangles;
    }
    s.counters["triangles"] = double(tris);
    s.counters["tri_per_s"] = benchmark::Counter(double(tris) * double(s.iterations()), benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK(BM_Streets)->Arg(1000)->Arg(2000)->Arg(4000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BlocksAndLots)->Arg(1000)->Arg(2000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BuildingMeshes)
    ->Args({1000, 0})
    ->Args({1000, 1})
    ->Args({1000, 2})
    ->Args({1000, 3})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GenerateCity)->Arg(500)->Arg(1000)->Arg(2000)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK_MAIN();
