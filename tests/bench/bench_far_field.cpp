// Google Benchmark: Embree ray casting (packets vs single rays) and horizon
// tracing on a loaded city. Usage:
//   bench_far_field --city city.osgb [--benchmark_filter=...]
// Without --city a synthetic random box city is used.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <string>

#include <tbb/parallel_for.h>

#include "runtime/scene/city_file.h"
#include "runtime/engine/far_field.h"
#include "runtime/engine/far_field_haze.h"
#include "runtime/engine/far_field_stages.h"
#include "runtime/engine/horizon.h"
#include "runtime/engine/ray_scene.h"

using namespace vista;

namespace {

std::string gCityPath;
struct World {
    SceneModel city;
    std::unique_ptr<RayScene> rays;
};

SceneModel syntheticCity() {
    SceneModel c;
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> pos(-900, 900), sz(5, 30), h(5, 80);
    SceneMesh m;
    auto quad = [&](glm::vec3 a, glm::vec3 b, glm::vec3 cc, glm::vec3 d) {
        uint32_t base = uint32_t(m.positions.size());
        for (auto p : {a, b, cc, d}) {
            m.positions.push_back(p);
            m.colors.push_back({120, 120, 120, 255});
        }
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
    };
    quad({-1000, -1000, 0}, {1000, -1000, 0}, {1000, 1000, 0}, {-1000, 1000, 0});
    for (int i = 0; i < 20000; ++i) {
        glm::vec3 lo(pos(rng), pos(rng), 0), hi = lo + glm::vec3(sz(rng), sz(rng), h(rng));
        quad({lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, lo.y, hi.z}, {lo.x, lo.y, hi.z});
        quad({hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {hi.x, lo.y, hi.z});
        quad({hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z});
        quad({lo.x, hi.y, lo.z}, {lo.x, lo.y, lo.z}, {lo.x, lo.y, hi.z}, {lo.x, hi.y, hi.z});
        quad({lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z});
    }
    c.meshes.push_back(m);
    return c;
}

World& world() {
    static World w = [] {
        World x;
        if (!gCityPath.empty()) {
            auto c = loadCityFile(gCityPath);
            if (!c) {
                std::fprintf(stderr, "%s\n", c.status().message().c_str());
                std::exit(2);
            }
            x.city = std::move(*c);
        } else {
            x.city = syntheticCity();
        }
        auto r = RayScene::build(x.city);
        if (!r) {
            std::fprintf(stderr, "%s\n", r.status().message().c_str());
            std::exit(2);
        }
        x.rays = std::move(*r);
        return x;
    }();
    return w;
}

Camera streetCamera(int w, int h) {
    Camera c;
    c.eye = glm::dvec3(world().city.params.origin_x + 3.0, world().city.params.origin_y + 1.0, 1.7);
    c.heading = 0.3;
    c.width = w;
    c.height = h;
    c.fovY = 60.0 * M_PI / 180.0;
    return c;
}

void BM_PrimaryPackets(benchmark::State& st) {
    Camera cam = streetCamera(640, 480);
    const RayScene& rs = *world().rays;
    glm::vec3 org(cam.eye - rs.frameOrigin());
    std::vector<glm::vec3> orgs(640 * 480, org), dirs(640 * 480);
    for (int y = 0; y < 480; ++y)
        for (int x = 0; x < 640; ++x) dirs[size_t(y) * 640 + size_t(x)] = glm::vec3(cam.rayDirection(x + 0.5, y + 0.5));
    std::vector<RayHit> hits(640);
    for (auto _ : st) {
        for (int y = 0; y < 480; ++y) rs.intersectMany(orgs.data() + y * 640, dirs.data() + y * 640, 640, hits.data());
    }
    st.SetItemsProcessed(int64_t(st.iterations()) * 640 * 480);
}
BENCHMARK(BM_PrimaryPackets)->Unit(benchmark::kMillisecond);

void BM_PrimarySingle(benchmark::State& st) {
    Camera cam = streetCamera(640, 480);
    const RayScene& rs = *world().rays;
    glm::vec3 org(cam.eye - rs.frameOrigin());
    std::vector<glm::vec3> dirs(640 * 480);
    for (int y = 0; y < 480; ++y)
        for (int x = 0; x < 640; ++x) dirs[size_t(y) * 640 + size_t(x)] = glm::vec3(cam.rayDirection(x + 0.5, y + 0.5));
    for (auto _ : st) {
        for (const auto& d : dirs) benchmark::DoNotOptimize(rs.intersect(org, d));
    }
    st.SetItemsProcessed(int64_t(st.iterations()) * 640 * 480);
}
BENCHMARK(BM_PrimarySingle)->Unit(benchmark::kMillisecond);

void BM_Horizon(benchmark::State& st) {
    const int cells = int(st.range(0));
    HeightGrid g = HeightGrid::build(world().city, world().rays->frameOrigin(), cells);
    Camera cam = streetCamera(640, 480);
    for (auto _ : st) benchmark::DoNotOptimize(traceHorizon(g, cam));
}
BENCHMARK(BM_Horizon)->Arg(64)->Arg(128)->Arg(256)->Arg(512)->Arg(1024)->Unit(benchmark::kMillisecond);

// One horizon 2D ray per azimuth step around the eye (street level, 80 m near
// distance), walking blocks (arg 1 = 1) or every cell (arg 1 = 0): the same
// bound (tested), the cost of the walk.
void BM_HorizonRayWalk(benchmark::State& st) {
    const int cells = int(st.range(0));
    const bool blocks = st.range(1) != 0;
    HeightGrid g = HeightGrid::build(world().city, world().rays->frameOrigin(), cells);
    const glm::dvec3 eye = streetCamera(640, 480).eye - g.frameOrigin();
    const int n = 4096;
    for (auto _ : st) {
        double sum = 0;
        for (int k = 0; k < n; ++k) {
            const double a = 2.0 * M_PI * k / n;
            const double b = blocks ? g.traceRay(eye, a, 80.0) : g.traceRayFlat(eye, a, 80.0);
            if (std::isfinite(b)) sum += b;
        }
        benchmark::DoNotOptimize(sum);
    }
    st.SetItemsProcessed(int64_t(st.iterations()) * n);
}
BENCHMARK(BM_HorizonRayWalk)
    ->Args({512, 0})
    ->Args({512, 1})
    ->Args({1024, 0})
    ->Args({1024, 1})
    ->Unit(benchmark::kMillisecond);

// The haze of a 640x480 frame: the covered pixels of a street view (below a
// skyline of buildings 16 to 64 columns wide, sky above it) hazed from their window
// depth, as the far field does after the near-field draw (arg 0: threads,
// 0 = all; the stage started and waited for at once).
void BM_HazeCovered(benchmark::State& st) {
    const int W = 640, H = 480;
    Camera cam = streetCamera(W, H);
    Image out(W, H);
    std::vector<uint8_t> cls(size_t(W) * H, kFarCovered);
    std::vector<float> depth(size_t(W) * H);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> d(0.5f, 0.9999f);
    std::uniform_int_distribution<int> skyline(100, 220), facade(16, 64);
    uint64_t covered = 0;
    int top = 0, left = 0;
    for (int x = 0; x < W; ++x) {
        if (--left <= 0) {
            top = skyline(rng);
            left = facade(rng);
        }
        for (int y = 0; y < H; ++y) {
            const size_t i = size_t(y) * W + x;
            const bool sky = y < top;
            depth[i] = sky ? 1.0f : d(rng);
            cls[i] = sky ? kFarRayMiss : kFarCovered;
            covered += sky ? 0 : 1;
        }
    }
    FarFrame f(cam, depth.data(), out, cls);
    f.covered = covered;
    FarFieldOptions o;
    o.hazeCovered = true;
    o.effects.haze = true;
    o.effects.visibility = 600.0;
    o.depthZFar = 600.0;
    o.threads = int(st.range(0));
    FrameStats stats;
    for (auto _ : st) {
        CoveredHaze haze;
        haze.start(f, o);
        haze.finish(stats);
    }
    st.SetItemsProcessed(int64_t(st.iterations()) * W * H);
}
BENCHMARK(BM_HazeCovered)->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond)->UseRealTime();

// The haze the ray tasks apply as they write: a 640x480 frame of eye-plane
// depths (a fifth of them sky) hazed row by row (a ray task's runs) by
// DepthHaze, on arg 0 threads (0 = all).
void BM_HazeAtDepth(benchmark::State& st) {
    constexpr size_t W = 640, H = 480;
    std::vector<uint32_t> px(W * H, 0xff336699u);
    std::vector<float> depth(W * H);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> d(1.0f, 700.0f);
    for (size_t i = 0; i < depth.size(); ++i) depth[i] = i % 5 == 0 ? INFINITY : d(rng);
    FrameEffects fx;
    fx.haze = true;
    fx.visibility = 600.0;
    const DepthHaze haze(fx);
    for (auto _ : st)
        inArena(int(st.range(0)), [&] {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, H, 4), [&](const tbb::blocked_range<size_t>& r) {
                for (size_t y = r.begin(); y != r.end(); ++y) haze(&px[y * W], &depth[y * W], W);
            });
        });
    st.SetItemsProcessed(int64_t(st.iterations()) * W * H);
}
BENCHMARK(BM_HazeAtDepth)->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
    for (int i = 1; i < argc; ++i)
        if (std::strncmp(argv[i], "--city=", 7) == 0) gCityPath = argv[i] + 7;
        else if (std::strcmp(argv[i], "--city") == 0 && i + 1 < argc) gCityPath = argv[++i];
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    return 0;
}
