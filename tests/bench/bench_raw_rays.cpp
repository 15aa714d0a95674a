// Google Benchmark: the far field's ray stage against raw Embree on exactly
// the rays real frames cast (docs/measurements/raw-rays.md, made by docs/tools/raw_rays.sh).
// Usage:
//   bench_raw_rays --city CITY.osgb --rays DIR [--benchmark_...]
// (or VISTA_CITY / VISTA_RAYS in the environment). DIR holds RaySet files
// (`vista bench CITY --modes hybrid --dump-rays DIR`); each iteration casts
// every ray of every set, so items_per_second is rays/s. Variants, each with
// threads:1 (a one-worker arena; CPU time) and threads:0 (all cores; wall
// time):
//   Raw1       rtcIntersect1 one ray at a time (rays from precomputed arrays)
//   Raw8       rtcIntersect8 in the stage's packets (coherentRuns), the SoA
//              packet filled from precomputed arrays
//   Raw8Dense  rtcIntersect8 on every 8 consecutive rays regardless of rows
//              (full packets, but packets that straddle row breaks)
//   Raw8Serial Raw8 in a plain loop, no TBB (threads:1 only: Raw8 minus
//              Raw8Serial = the one-worker arena and parallel_for)
//   Raw8Color  Raw8 plus every hit's colour (RayScene::hitColor: the colour
//              fetch and interpolation the wrapper does per hit)
//   Many       RayScene::intersectMany on the stage's runs (the wrapper: lane
//              fill, and per hit the colour, normal and RayHit fill)
//   Dirs       the rays' directions and tfars from the pixel list
//              (primaryRays: the stage's own arithmetic)
//   Stage      castPrimaryRays on the pixel list: the in-frame path
//              (directions, intersectMany, shading, colour writes), with
//              the frame's haze limit and a hit list as raysStage passes
// Interleaved runs every variant on one core frame by frame (counters
// <Variant>_ns = CPU ns per ray). Counters: rays (per iteration), frames,
// packet_fill (rays / (8 x packets)).
// Before timing, the variants' hit counts are compared (printed on stderr).
#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>
#include <pmmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "runtime/engine/far_field_rays.h"
#include "runtime/engine/far_field_stages.h"  // inArena: the stage's arena
#include "runtime/engine/ray_packet.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/engine/ray_set.h"
#include "runtime/scene/city_file.h"

using namespace vista;

namespace {

// Rays per parallel task, as castPrimaryRays cuts its runs (far_field_rays.cpp).
constexpr size_t kRaysPerTask = 2048;

std::string gCityPath, gRaysDir;

struct Frame {
    RaySet set;
    PrimaryRays rays;
    std::vector<size_t> runs;     // the stage's packet runs
    std::vector<glm::vec3> orgs;  // one origin per ray (intersectMany's input)
    FrameEffects fx;              // the haze limit of the set (nothing else changes the rays)
    Image out;
    std::vector<uint8_t> hit;
    std::vector<float> depth;  // eye-plane depth per ray when hazed (raysStage passes it)
};

struct World {
    SceneModel city;
    std::unique_ptr<RayScene> scene;
    std::vector<Frame> frames;
    size_t rays = 0, packets = 0;
};

[[noreturn]] void fail(const std::string& msg) {
    std::fprintf(stderr, "bench_raw_rays: %s\n", msg.c_str());
    std::exit(2);
}

World& world() {
    static World w = [] {
        World x;
        if (gCityPath.empty() || gRaysDir.empty())
            fail("give --city CITY.osgb and --rays DIR (or VISTA_CITY / VISTA_RAYS)");
        auto c = loadCityFile(gCityPath);
        if (!c) fail(c.status().message());
        x.city = std::move(*c);
        auto r = RayScene::build(x.city);
        if (!r) fail(r.status().message());
        x.scene = std::move(*r);
        std::vector<std::string> files;
        std::error_code ec;
        for (const auto& e : std::filesystem::directory_iterator(gRaysDir, ec))
            if (e.path().extension() == ".rays") files.push_back(e.path().string());
        if (ec) fail("--rays '" + gRaysDir + "': " + ec.message());
        std::sort(files.begin(), files.end());
        for (const auto& file : files) {
            auto s = readRaySet(file);
            if (!s) fail(s.status().message());
            if (s->pixels.empty()) continue;
            Frame f;
            f.set = std::move(*s);
            const size_t n = f.set.pixels.size();
            f.rays =
                primaryRays(f.set.camera, x.scene->frameOrigin(), f.set.pixels.data(), n, f.set.hazeFar, f.set.tnear);
            f.runs = coherentRuns(f.set.pixels.data(), n, f.set.camera.width);
            f.orgs.assign(n, f.rays.org);
            f.fx.haze = f.set.hazeFar > 0;
            f.fx.visibility = f.fx.haze ? f.set.hazeFar : 1e30;
            f.out = Image(f.set.camera.width, f.set.camera.height);
            f.hit.assign(n, 0);
            if (f.fx.haze) f.depth.assign(n, 0.0f);
            for (size_t r = 0; r + 1 < f.runs.size(); ++r) x.packets += (f.runs[r + 1] - f.runs[r] + 7) / 8;
            x.rays += n;
            x.frames.push_back(std::move(f));
        }
        if (x.rays == 0) fail("--rays '" + gRaysDir + "': no ray set with rays (*.rays)");
        std::fprintf(stderr, "bench_raw_rays: %zu frames, %zu rays, %zu triangles\n", x.frames.size(), x.rays,
                     x.scene->triangleCount());
        return x;
    }();
    return w;
}

void enableFtzDaz() {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

// Parallel over [0, n) in blocks of `grain`; f(begin, end) returns its hit count.
template <class F>
uint64_t parallelHits(int threads, size_t n, size_t grain, const F& f) {
    std::atomic<uint64_t> hits{0};
    inArena(threads, [&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, std::max<size_t>(1, grain)),
                          [&](const tbb::blocked_range<size_t>& br) {
                              enableFtzDaz();
                              hits += f(br.begin(), br.end());
                          });
    });
    return hits.load();
}

// Raw rtcIntersect1 on rays [b, e) of a frame.
uint64_t raw1(RTCScene scene, const PrimaryRays& r, size_t b, size_t e) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    uint64_t hits = 0;
    for (size_t k = b; k < e; ++k) {
        RTCRayHit rh;
        rh.ray.org_x = r.org.x;
        rh.ray.org_y = r.org.y;
        rh.ray.org_z = r.org.z;
        rh.ray.dir_x = r.dirs[k].x;
        rh.ray.dir_y = r.dirs[k].y;
        rh.ray.dir_z = r.dirs[k].z;
        rh.ray.tnear = r.tnear;
        rh.ray.tfar = r.tfars[k];
        rh.ray.time = 0.0f;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.ray.id = 0;
        rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene, &ctx, &rh);
        hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
    return hits;
}

// Raw rtcIntersect8 on rays [b, e) of a frame, in packets of 8 from b.
// colours (optional): each hit's colour fetched through RayScene::hitColor.
uint64_t raw8(RTCScene scene, const Frame& f, size_t b, size_t e, const RayScene* colours = nullptr) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    alignas(32) RTCRayHit8 rh;
    alignas(32) int valid[8];
    uint64_t hits = 0;
    for (size_t p = b; p < e; p += 8) {
        const int m = int(std::min<size_t>(8, e - p));
        fillPacket8(rh, valid, f.orgs.data(), f.rays.dirs.data(), f.rays.tfars.data(), 0.0f, p, m, f.rays.tnear);
        rtcIntersect8(valid, scene, &ctx, &rh);
        for (int k = 0; k < m; ++k) hits += rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
        if (!colours) continue;
        glm::vec3 sum(0.0f);
        for (int k = 0; k < m; ++k) {
            if (rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) continue;
            RayHit h;
            h.hit = true;
            h.geomId = rh.hit.geomID[k];
            h.primId = rh.hit.primID[k];
            h.instId = rh.hit.instID[0][k];
            h.u = rh.hit.u[k];
            h.v = rh.hit.v[k];
            sum += colours->hitColor(h);
        }
        benchmark::DoNotOptimize(sum);
    }
    return hits;
}

// The stage's grain over runs: about kRaysPerTask rays a task.
size_t runGrain(const Frame& f) {
    const size_t nRuns = f.runs.size() - 1, n = f.runs.back();
    return std::max<size_t>(1, (kRaysPerTask * nRuns + n - 1) / n);
}

// One pass of a variant over every frame; returns the hit count.
enum class Variant { Raw1, Raw8, Raw8Dense, Raw8Serial, Raw8Color, Many, Dirs, Stage };

constexpr Variant kVariants[] = {Variant::Raw1,      Variant::Raw8, Variant::Raw8Dense, Variant::Raw8Serial,
                                 Variant::Raw8Color, Variant::Many, Variant::Dirs,      Variant::Stage};
constexpr const char* kVariantNames[] = {"Raw1",      "Raw8", "Raw8Dense", "Raw8Serial",
                                         "Raw8Color", "Many", "Dirs",      "Stage"};

// One variant on one frame; returns the hit count.
uint64_t passFrame(Variant v, Frame& f, int threads) {
    World& w = world();
    RTCScene scene = w.scene->embreeScene();
    uint64_t hits = 0;
    {
        const size_t n = f.runs.back(), nRuns = f.runs.size() - 1;
        switch (v) {
            case Variant::Raw1:
                hits += parallelHits(threads, n, kRaysPerTask,
                                     [&](size_t b, size_t e) { return raw1(scene, f.rays, b, e); });
                break;
            case Variant::Raw8:
                hits += parallelHits(threads, nRuns, runGrain(f), [&](size_t b, size_t e) {
                    uint64_t h = 0;
                    for (size_t r = b; r < e; ++r) h += raw8(scene, f, f.runs[r], f.runs[r + 1]);
                    return h;
                });
                break;
            case Variant::Raw8Serial:
                enableFtzDaz();
                for (size_t r = 0; r < nRuns; ++r) hits += raw8(scene, f, f.runs[r], f.runs[r + 1]);
                break;
            case Variant::Raw8Color:
                hits += parallelHits(threads, nRuns, runGrain(f), [&](size_t b, size_t e) {
                    uint64_t h = 0;
                    for (size_t r = b; r < e; ++r) h += raw8(scene, f, f.runs[r], f.runs[r + 1], w.scene.get());
                    return h;
                });
                break;
            case Variant::Raw8Dense:
                hits += parallelHits(threads, (n + 7) / 8, kRaysPerTask / 8,
                                     [&](size_t b, size_t e) { return raw8(scene, f, 8 * b, std::min(n, 8 * e)); });
                break;
            case Variant::Many:
                hits += parallelHits(threads, nRuns, runGrain(f), [&](size_t b, size_t e) {
                    std::vector<RayHit> res;
                    uint64_t h = 0;
                    for (size_t r = b; r < e; ++r) {
                        const size_t s = f.runs[r], m = f.runs[r + 1] - s;
                        res.resize(m);
                        w.scene->intersectMany(f.orgs.data() + s, f.rays.dirs.data() + s, int(m), res.data(), 1e30f,
                                               f.rays.tfars.data() + s, f.rays.tnear);
                        for (const RayHit& x : res) h += x.hit ? 1 : 0;
                    }
                    return h;
                });
                break;
            case Variant::Dirs: {
                const PrimaryRays r = primaryRays(f.set.camera, w.scene->frameOrigin(), f.set.pixels.data(), n,
                                                  f.set.hazeFar, f.set.tnear);
                benchmark::DoNotOptimize(r.dirs.data());
                break;
            }
            case Variant::Stage: {
                RayCounts counts;
                RayShading shading;
                shading.effects = &f.fx;
                shading.depth = f.depth.empty() ? nullptr : f.depth.data();
                shading.tnear = float(f.set.tnear);
                castPrimaryRays(*w.scene, f.set.camera, f.set.pixels.data(), n, f.out, counts, threads, f.hit.data(),
                                shading);
                hits += counts.hits;
                break;
            }
        }
    }
    return hits;
}

// One variant on every frame.
uint64_t pass(Variant v, int threads) {
    uint64_t hits = 0;
    for (Frame& f : world().frames) hits += passFrame(v, f, threads);
    return hits;
}

double threadCpuNs() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) * 1e9 + double(ts.tv_nsec);
}

// Every variant on one core, interleaved frame by frame (the order rotates
// from frame to frame), each call timed by this thread's CPU clock (a
// one-worker arena runs on the calling thread): the variants see the same
// machine load, so their differences are the steadiest attribution.
// Counters <Variant>_ns: CPU ns per ray.
void BM_Interleaved(benchmark::State& st) {
    World& w = world();
    constexpr size_t kN = sizeof(kVariants) / sizeof(kVariants[0]);
    double ns[kN] = {};
    size_t rot = 0;
    for (auto _ : st)
        for (Frame& f : w.frames) {
            for (size_t j = 0; j < kN; ++j) {
                const size_t i = (j + rot) % kN;
                const double t0 = threadCpuNs();
                benchmark::DoNotOptimize(passFrame(kVariants[i], f, 1));
                ns[i] += threadCpuNs() - t0;
            }
            ++rot;
        }
    st.SetItemsProcessed(int64_t(st.iterations()) * int64_t(w.rays));
    for (size_t i = 0; i < kN; ++i)
        st.counters[std::string(kVariantNames[i]) + "_ns"] = ns[i] / (double(st.iterations()) * double(w.rays));
    st.counters["rays"] = double(w.rays);
    st.counters["frames"] = double(w.frames.size());
    st.counters["packet_fill"] = double(w.rays) / (8.0 * double(w.packets));
}

void run(benchmark::State& st, Variant v) {
    World& w = world();
    const int threads = int(st.range(0));
    for (auto _ : st) benchmark::DoNotOptimize(pass(v, threads));
    st.SetItemsProcessed(int64_t(st.iterations()) * int64_t(w.rays));
    st.counters["rays"] = double(w.rays);
    st.counters["frames"] = double(w.frames.size());
    if (v == Variant::Raw8 || v == Variant::Raw8Serial || v == Variant::Many || v == Variant::Stage)
        st.counters["packet_fill"] = double(w.rays) / (8.0 * double(w.packets));
}

void BM_Raw1(benchmark::State& st) { run(st, Variant::Raw1); }
void BM_Raw8(benchmark::State& st) { run(st, Variant::Raw8); }
void BM_Raw8Dense(benchmark::State& st) { run(st, Variant::Raw8Dense); }
void BM_Raw8Serial(benchmark::State& st) { run(st, Variant::Raw8Serial); }
void BM_Many(benchmark::State& st) { run(st, Variant::Many); }
void BM_Dirs(benchmark::State& st) { run(st, Variant::Dirs); }
void BM_Stage(benchmark::State& st) { run(st, Variant::Stage); }

// One core: this thread's CPU time (steady when other jobs share the cores;
// a one-worker arena runs on the calling thread); all cores: wall time (the
// frame's throughput).
#define VISTA_RAW_BENCH1(fn) BENCHMARK(fn)->ArgName("threads")->Arg(1)->Unit(benchmark::kMillisecond)
#define VISTA_RAW_BENCH(fn) \
    VISTA_RAW_BENCH1(fn);   \
    BENCHMARK(fn)->ArgName("threads")->Arg(0)->UseRealTime()->Unit(benchmark::kMillisecond)
VISTA_RAW_BENCH(BM_Raw1);
VISTA_RAW_BENCH(BM_Raw8);
VISTA_RAW_BENCH(BM_Raw8Dense);
VISTA_RAW_BENCH1(BM_Raw8Serial);
VISTA_RAW_BENCH(BM_Many);
VISTA_RAW_BENCH1(BM_Dirs);
VISTA_RAW_BENCH(BM_Stage);
BENCHMARK(BM_Interleaved)->Unit(benchmark::kMillisecond);

// The variants trace the same rays: their hit counts agree (Stage counts
// shown hits, which haze may lower; the raw casts stop at the same tfar).
void compareHits() {
    const uint64_t h1 = pass(Variant::Raw1, 0), h8 = pass(Variant::Raw8, 0), hd = pass(Variant::Raw8Dense, 0),
                   hm = pass(Variant::Many, 0), hs = pass(Variant::Stage, 0);
    std::fprintf(stderr,
                 "bench_raw_rays: hits raw1 %llu, raw8 %llu, raw8 dense %llu, intersectMany %llu, stage %llu%s\n",
                 (unsigned long long)h1, (unsigned long long)h8, (unsigned long long)hd, (unsigned long long)hm,
                 (unsigned long long)hs, (h1 == h8 && h8 == hd && hd == hm) ? "" : "  (DIFFER)");
}

}  // namespace

int main(int argc, char** argv) {
    if (const char* e = std::getenv("VISTA_CITY")) gCityPath = e;
    if (const char* e = std::getenv("VISTA_RAYS")) gRaysDir = e;
    std::vector<char*> rest;
    for (int i = 0; i < argc; ++i) {
        auto value = [&](const char* flag, std::string& out) {
            const size_t l = std::strlen(flag);
            if (std::strncmp(argv[i], flag, l) == 0 && argv[i][l] == '=') return out = argv[i] + l + 1, true;
            if (std::strcmp(argv[i], flag) == 0 && i + 1 < argc) return out = argv[++i], true;
            return false;
        };
        if (i > 0 && (value("--city", gCityPath) || value("--rays", gRaysDir))) continue;
        rest.push_back(argv[i]);
    }
    int n = int(rest.size());
    benchmark::Initialize(&n, rest.data());
    if (benchmark::ReportUnrecognizedArguments(n, rest.data())) return 2;
    compareHits();
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
