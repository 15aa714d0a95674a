// The bench run: set up, warm up, frame loop, summarise, write (bench.h).
#include "cmd/bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <chrono>
#include <fstream>
#include <thread>
#include <memory>

#include <tbb/global_control.h>
#include <unistd.h>

#include "cmd/options.h"
#include "cmd/paged_stream.h"
#include "foundation/timing.h"
#include "foundation/units.h"
#include "nodes/render/city_stream.h"
#include "nodes/render/offscreen.h"
#include "nodes/render/traffic_scene.h"
#include "runtime/engine/metrics.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/engine/ray_set.h"

namespace vista {

namespace {

namespace fs = std::filesystem;

// 1-minute load average (other processes competing for the cores), or -1.
double loadAverage() {
    std::ifstream f("/proc/loadavg");
    double v = -1;
    if (!(f >> v)) return -1;
    return v;
}

// Everything a run renders with; the context outlives the modes (they keep a reference).
struct BenchRun {
    std::unique_ptr<OffscreenRenderer> renderer;
    std::unique_ptr<RayScene> rays;
    std::unique_ptr<CityStream> stream;     // a streamed paged city: its graph and ray scene
    std::unique_ptr<TrafficScene> traffic;  // --traffic
    ModeContext ctx;
    ModeContext clearCtx;  // ctx without run-time effects (BenchConfig::alsoClear)
    std::vector<std::unique_ptr<RenderMode>> modes;
    std::vector<std::string> labels;  // per mode: its name, "+clear" for the twins
    std::vector<SetupTimes> setup;    // per mode: load, bvh, the mode's own
    size_t plainCount = 0;            // modes[0, plainCount) run with the effects, the rest are their twins
};

Result<std::unique_ptr<BenchRun>> setUp(const SceneModel* city, osg::Node* scene, const BenchConfig& cfg) {
    auto run = std::make_unique<BenchRun>();
    auto renderer = OffscreenRenderer::create(cfg.width, cfg.height);
    if (!renderer) return renderer.status();
    run->renderer = std::move(renderer.value());
    run->renderer->setCountFragments(cfg.countFragments);
    run->ctx.city = city;
    run->ctx.scene = scene;
    run->ctx.renderer = run->renderer.get();
    run->ctx.options = cfg.options;
    double bvhMs = -1;
    const bool fxRays = effectsNeedRays(cfg.options.effects);
    const bool needRays = fxRays || std::any_of(cfg.modes.begin(), cfg.modes.end(),
                                                [](const std::string& m) { return findRenderMode(m)->needsRays; });
    if (cfg.streamManifest) {
        // A streamed paged city: the graph and the ray scene follow the camera (advanceStream).
        auto s = CityStream::create(*cfg.streamManifest, cfg.stream, needRays);
        if (!s) return Status::error("setting up the streamed city failed: " + s.status().message());
        run->stream = std::move(s.value());
        // hybrid: the stream keeps the near field, its split index and the horizon grid too.
        if (needRays && std::any_of(cfg.modes.begin(), cfg.modes.end(), modeStreamsNearField))
            run->stream->enableNearField(cfg.options.horizonGrid);
        run->stream->setGraphLevels(streamGraphOf(cfg.modes), streamNearBand(cfg.options));
        holdStreamUnder(*run->stream, cfg.memoryBudgetGb);
        run->ctx.streamedCity = run->stream->graph();
        run->ctx.scene = run->stream->graph();
        run->ctx.stream = run->stream.get();
    }
    run->ctx.paged = cfg.pagedManifest;
    if (needRays) {
        if (!city) return Status::error("modes that cast rays need a loaded city file (no city given)");
        Stopwatch sw;
        if (cfg.streamManifest) {
            run->ctx.rays = run->stream->rays();
        } else {
            auto r = RayScene::build(*city);
            if (!r) return Status::error("building the Embree ray scene failed: " + r.status().message());
            run->rays = std::move(r.value());
            run->ctx.rays = run->rays.get();
        }
        bvhMs = sw.ms();
        if (!cfg.quiet) std::fprintf(stderr, "ray scene built in %.0f ms\n", bvhMs);
    }
    if (cfg.traffic) {
        if (!city) return Status::error("--traffic: needs the city's parameters (no city given)");
        run->traffic = std::make_unique<TrafficScene>(cfg.traffic, city->params, false);
        RayScene* rays = run->stream ? run->stream->rays() : run->rays.get();
        if (rays) VISTA_RETURN_IF_ERROR(run->traffic->attachRays(rays));
        VISTA_RETURN_IF_ERROR(run->traffic->showCitySignals(*city, cfg.pagedManifest));
        run->ctx.traffic = run->traffic.get();
        run->renderer->setOverlay(run->traffic->node(), nullptr);
    }
    auto add = [&](const std::string& name, ModeContext& ctx, const std::string& label) -> Status {
        auto m = createRenderMode(name, ctx);
        if (!m) return m.status();
        SetupTimes s;
        if (cfg.loadMs >= 0) s.push_back({"load", cfg.loadMs});
        if (fxRays || findRenderMode(name)->needsRays) s.push_back({"bvh", bvhMs});
        for (const auto& kv : m.value()->setupMs()) s.push_back(kv);
        run->setup.push_back(s);
        run->modes.push_back(std::move(m.value()));
        run->labels.push_back(label);
        return Status::ok();
    };
    for (const auto& name : cfg.modes) VISTA_RETURN_IF_ERROR(add(name, run->ctx, name));
    run->plainCount = run->modes.size();
    if (cfg.alsoClear) {
        run->clearCtx = run->ctx;  // shares the near field and the bakes the modes above built
        // No run-time effect, as `--effects none` gives: the scene's glass marks are still in its
        // pictures (and cleared there), so both sides pay for finding them.
        run->clearCtx.options.effects = FrameEffects{};
        run->clearCtx.options.effects.glassMarked = run->ctx.options.effects.glassMarked;
        for (const auto& name : cfg.modes) VISTA_RETURN_IF_ERROR(add(name, run->clearCtx, clearTwinName(name)));
    }
    return run;
}

// A streamed city: the ray scene follows the camera of path sample i
// (arrivals and drops between frames); `first` waits for the regions within
// reach and is not counted in the frames' detail. A stream that cannot stream
// is an error (advancePagedStream).
Status advanceStream(BenchRun& run, const Path& path, size_t i, const Camera& cam, BenchResult& result, int* arrived,
                     bool first = false) {
    *arrived = 0;
    if (!run.stream) return Status::ok();
    auto f =
        advancePagedStream(*run.stream, "vista bench", cam.eye, pathVelocity(path, i), &result.streamDamaged, first);
    if (!f) return f.status();
    *arrived = f->arrived;
    if (!first) result.streamDetail.add(*f, path.samples[i].t);
    // What the modes kept of the old scene (hybrid's panoramic cache) goes.
    if (f->arrived > 0 || f->dropped > 0)
        for (auto& m : run.modes) m->sceneChanged(f->changed);
    return Status::ok();
}

Status warmUp(BenchRun& run, const Camera& camera) {
    RayScene* rays = run.stream ? run.stream->rays() : run.rays.get();
    if (rays) VISTA_RETURN_IF_ERROR(rays->placeFrameNear(camera.eye));
    Image img;
    for (auto& m : run.modes) {
        FrameStats s;
        Status st = m->renderFrame(camera, img, s);
        if (!st) return Status::error("mode " + m->name() + ": " + st.message());
    }
    for (auto& m : run.modes) m->reset();
    return Status::ok();
}

// The k x k supersampled image of mode `mi` (`full`, with or without the
// effects) of the camera: the mode's own draw, jittered.
Result<Image> supersampledReference(BenchRun& run, size_t mi, const Camera& cam, int k) {
    std::vector<Image> subs;
    for (int j = 0; j < k; ++j)
        for (int i = 0; i < k; ++i) {
            run.renderer->setSubpixelOffset((i + 0.5) / k - 0.5, (j + 0.5) / k - 0.5);
            FrameStats s;
            Image sub;
            Status st = run.modes[mi]->renderFrame(cam, sub, s);
            if (!st) {
                run.renderer->setSubpixelOffset(0, 0);
                return st;
            }
            subs.push_back(std::move(sub));
        }
    run.renderer->setSubpixelOffset(0, 0);
    return averageImages(subs);
}

// The first image of every mode, every frame with --save-frames, and the N
// lowest-PSNR frames per mode (with their references, written at the end),
// each staged into `batch`: the run's outputs appear together when it
// succeeds, none of them when it fails.
class FrameImages {
public:
    FrameImages(const BenchConfig& cfg, size_t modes, OutputBatch& batch) : _cfg(cfg), _worst(modes), _batch(batch) {}
    // isReference: the mode whose image is `ref` (no difference image of its own).
    Status add(size_t mi, const BenchFrameRecord& rec, const Image& img, const Image& ref, bool isReference) {
        if (_cfg.outDir.empty()) return Status::ok();
        if (rec.frame == 0) VISTA_RETURN_IF_ERROR(writePng(img, stage("first_" + rec.mode + ".png")));
        if (_cfg.saveFrames) {
            char name[64];
            std::snprintf(name, sizeof name, "f%04d_", rec.frame);
            VISTA_RETURN_IF_ERROR(writePng(
                img,
                _batch.stage((std::filesystem::path(_cfg.outDir) / "frames" / (name + rec.mode + ".png")).string())));
        }
        if (_cfg.worstFrames <= 0 || isReference || _cfg.referenceSsaa == kNoReference) return Status::ok();
        auto& w = _worst[mi];
        if (int(w.size()) < _cfg.worstFrames || rec.psnrDb < w.back().psnr) {
            w.push_back({rec.psnrDb, rec.frame, rec.mode, img, ref});
            std::sort(w.begin(), w.end(), [](const Worst& a, const Worst& b) { return a.psnr < b.psnr; });
            if (int(w.size()) > _cfg.worstFrames) w.pop_back();
        }
        return Status::ok();
    }
    Status writeWorst() const {
        for (const auto& list : _worst)
            for (size_t k = 0; k < list.size(); ++k) {
                const Worst& w = list[k];
                const std::string stem =
                    "worst" + std::to_string(k + 1) + "_" + w.mode + "_f" + std::to_string(w.frame);
                VISTA_RETURN_IF_ERROR(writePng(w.image, stage(stem + ".png")));
                VISTA_RETURN_IF_ERROR(writePng(w.reference, stage(stem + "_ref.png")));
                VISTA_RETURN_IF_ERROR(writePng(differenceImage(w.image, w.reference), stage(stem + "_diff.png")));
            }
        return Status::ok();
    }

private:
    struct Worst {
        double psnr;
        int frame;
        std::string mode;
        Image image, reference;
    };
    // The staged file of images/NAME.
    std::string stage(const std::string& name) const {
        return _batch.stage((fs::path(_cfg.outDir) / "images" / name).string());
    }
    const BenchConfig& _cfg;
    std::vector<std::vector<Worst>> _worst;
    OutputBatch& _batch;
};

void reportProgress(const BenchConfig& cfg, size_t done, size_t total, const Stopwatch& sw) {
    if (cfg.quiet || (done % 10 != 0 && done != total)) return;
    const double el = sw.ms() / 1000.0, eta = el * double(total - done) / double(done);
    const bool tty = isatty(2);
    std::fprintf(stderr, tty ? "\rframe %zu/%zu (%.0f s, eta %.0f s)   " : "frame %zu/%zu (%.0f s, eta %.0f s)\n", done,
                 total, el, eta);
    if (tty && done == total) std::fprintf(stderr, "\n");
}

// --dump-rays: the pixels mode `m` (named `label`) traced in frame f as a RaySet file.
Status dumpRays(const RenderMode& m, const std::string& label, int f, const Camera& cam, const BenchConfig& cfg,
                OutputBatch& batch) {
    const std::vector<uint32_t>* traced = m.lastTracedPixels();
    if (cfg.dumpRaysDir.empty() || !traced || f % cfg.dumpRaysEvery != 0) return Status::ok();
    RaySet set;
    set.frame = uint32_t(f);
    set.camera = cam;
    const bool twin = label != m.name();
    set.hazeFar = cfg.options.effects.haze && !twin ? cfg.options.effects.hazeFar() : 0.0;
    set.tnear = m.lastRayStart();
    set.pixels = *traced;
    char name[64];
    std::snprintf(name, sizeof name, "_f%04d.rays", f);
    return writeRaySet(batch.stage((fs::path(cfg.dumpRaysDir) / (label + name)).string()), set);
}

// Images a frame renders into (one per mode), kept across frames so that no mode allocates its
// image in a timed frame; a reference per group (the run's modes, their clear twins).
struct FrameBuffers {
    std::vector<Image> img;
    Image ref[2];
};

// Row `row` of a Williams design for n modes: rows 0 .. n-1 are a Latin
// square (row r is 0, 1, n-1, 2, n-2, ... plus r, mod n) in which each mode
// comes right after each other mode exactly once; for odd n the rows n .. 2n-1
// are those reversed, and the 2n rows then hold each ordered pair twice.
size_t williamsRows(size_t n) { return n % 2 == 0 ? n : 2 * n; }
std::vector<size_t> williamsRow(size_t row, size_t n) {
    std::vector<size_t> order;
    size_t lo = 1, hi = n - 1;
    order.push_back(0);
    for (bool takeLo = true; order.size() < n; takeLo = !takeLo) order.push_back(takeLo ? lo++ : hi--);
    for (size_t& m : order) m = (m + row) % n;
    if (row >= n) std::reverse(order.begin(), order.end());
    return order;
}

// The order in which frame f renders the run's n modes (the first `plain` are
// the run's, the rest their clear twins in the same order). A render runs on
// the caches the one before it left (measured: a mode that always follows
// another drawing the same city is a few percent faster), so the frames go
// through the rows of a Williams design: over them each mode takes every
// place, and comes right after each other mode, equally often. Between frames
// the bench scores every image, so a frame's first render follows that work,
// not a mode. With twins, each mode and its twin run one after the other, the
// twin first on odd frames, every row twice: a mode's predecessors, with and
// without effects swapped, are then its twin's, so neither side of the
// same-frame ratio more often runs on caches another render left warm or cold.
std::vector<size_t> renderOrder(size_t f, size_t n, size_t plain) {
    if (plain == n) return williamsRow(f % williamsRows(plain), plain);
    std::vector<size_t> order;
    for (const size_t mi : williamsRow((f / 2) % williamsRows(plain), plain)) {
        if (f % 2 == 1) {
            order.insert(order.end(), {plain + mi, mi});
        } else {
            order.insert(order.end(), {mi, plain + mi});
        }
    }
    return order;
}

// Renders one frame in every mode of the run, in renderOrder, and scores each
// against its group's reference (the group's first mode, `full`, or its
// supersampled image); records go to recs[mi].
Status renderFrame(BenchRun& run, size_t f, size_t pathIndex, double t, const Camera& cam, const BenchConfig& cfg,
                   std::vector<BenchFrameRecord>& recs, FrameImages& images, OutputBatch& batch, FrameBuffers& buf) {
    const size_t n = run.modes.size(), plain = run.plainCount;
    for (size_t mi = buf.img.size(); mi < n; ++mi) buf.img.emplace_back(cfg.width, cfg.height);
    const size_t groups = plain < n ? 2 : 1;
    if (cfg.referenceSsaa >= 2)
        for (size_t g = 0; g < groups; ++g) {
            auto r = supersampledReference(run, g * plain, cam, cfg.referenceSsaa);
            if (!r) return Status::error("reference, frame " + std::to_string(f) + ": " + r.status().message());
            buf.ref[g] = std::move(r.value());
        }
    int slot = 0;  // the next render's place in the frame
    for (const size_t mi : renderOrder(f, n, plain)) {
        BenchFrameRecord& rec = recs[mi];
        rec.frame = int(f);
        rec.pathIndex = pathIndex;
        rec.t = t;
        rec.mode = run.labels[mi];
        rec.runOrder = slot++;
        Image& img = buf.img[mi];
        Status st = run.modes[mi]->renderFrame(cam, img, rec.stats);
        if (!st) return Status::error("mode " + rec.mode + ", frame " + std::to_string(f) + ": " + st.message());
        VISTA_RETURN_IF_ERROR(dumpRays(*run.modes[mi], rec.mode, int(f), cam, cfg, batch));
        if (!img.valid() || img.width != cfg.width || img.height != cfg.height)
            return Status::error("mode " + rec.mode + " returned an image of the wrong size");
    }
    for (size_t mi = 0; mi < n; ++mi) {
        const size_t begin = mi < plain ? 0 : plain;
        BenchFrameRecord& rec = recs[mi];
        const Image& img = buf.img[mi];
        const bool scored = cfg.referenceSsaa != kNoReference;
        const bool isReference = scored && mi == begin && cfg.referenceSsaa < 2;
        const Image& ref = cfg.referenceSsaa >= 2 ? buf.ref[begin == 0 ? 0 : 1] : buf.img[begin];
        rec.psnrDb = scored ? lumaPsnr(img, ref) : NAN;
        rec.diffFraction = scored ? fractionDiffering(img, ref, cfg.diffThreshold) : NAN;
        VISTA_RETURN_IF_ERROR(images.add(mi, rec, img, ref, isReference));
    }
    return Status::ok();
}

// Renders every frame in every mode (interleaved) and scores it.
Status renderFrames(BenchRun& run, const Path& path, const std::vector<size_t>& idx, const Camera& base,
                    const BenchConfig& cfg, BenchResult& result, FrameImages& images, OutputBatch& batch) {
    Stopwatch sw;
    const size_t n = run.modes.size();
    std::vector<BenchFrameRecord> recs(n);
    FrameBuffers buf;
    Stopwatch paceClock;
    for (size_t f = 0; f < idx.size(); ++f) {
        if (cfg.pace && f > 0) {
            // A drive at the path's own speed: this frame starts at its path time after the first's.
            const double dueMs = 1000.0 * (path.samples[idx[f]].t - path.samples[idx[0]].t) - paceClock.ms();
            if (dueMs > 0) std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(dueMs));
        }
        if (f == 0) paceClock.restart();
        const Camera cam = path.camera(idx[f], base);
        int arrived = 0;
        Stopwatch advanceSw;
        VISTA_RETURN_IF_ERROR(advanceStream(run, path, idx[f], cam, result, &arrived));
        if (run.stream) result.advanceMs.push_back(advanceSw.ms());
        result.framesWithArrivals += arrived > 0 ? 1 : 0;
        // Ray origins near the scene's frame origin: float precision anywhere in the city.
        RayScene* rays = run.stream ? run.stream->rays() : run.rays.get();
        if (rays) VISTA_RETURN_IF_ERROR(rays->placeFrameNear(cam.eye));
        const double t = path.samples[idx[f]].t;
        VISTA_RETURN_IF_ERROR(renderFrame(run, f, idx[f], t, cam, cfg, recs, images, batch, buf));
        for (auto& rec : recs) {
            rec.regionsArrived = arrived;
            result.frames.push_back(std::move(rec));
        }
        recs.assign(n, BenchFrameRecord{});
        reportProgress(cfg, f + 1, idx.size(), sw);
    }
    return Status::ok();
}

}  // namespace

// `full` first: the reference of every frame is rendered before the others.
BenchConfig withFullFirst(BenchConfig cfg) {
    if (cfg.referenceSsaa == kNoReference) return cfg;  // full runs only when listed
    cfg.modes.erase(std::remove(cfg.modes.begin(), cfg.modes.end(), "full"), cfg.modes.end());
    cfg.modes.insert(cfg.modes.begin(), "full");
    return cfg;
}

Status validateBenchConfig(const BenchConfig& c) {
    VISTA_RETURN_IF_ERROR(checkImageSize(c.width, c.height));
    if (c.frames < 1 || c.frames > 1000000)
        return Status::error("--frames " + std::to_string(c.frames) + " out of range 1 .. 1000000");
    VISTA_RETURN_IF_ERROR(checkFov(c.fovYDeg));
    if (c.referenceSsaa != kNoReference && (c.referenceSsaa < 0 || c.referenceSsaa > kMaxReferenceSsaa))
        return Status::error("--reference ssaa:" + std::to_string(c.referenceSsaa) + " out of range 2 .. 8");
    if (c.diffThreshold < 0 || c.diffThreshold > 255)
        return Status::error("--diff-threshold " + std::to_string(c.diffThreshold) + " out of range 0 .. 255");
    if (c.worstFrames < 0 || c.worstFrames > 100)
        return Status::error("--worst " + std::to_string(c.worstFrames) + " out of range 0 .. 100");
    if (c.sampleRuns < 0 || c.sampleRuns > 100000)
        return Status::error("--sampling runs:" + std::to_string(c.sampleRuns) + " out of range 1 .. 100000");
    if (c.dumpRaysEvery < 1 || c.dumpRaysEvery > 1000000)
        return Status::error("--dump-rays-every " + std::to_string(c.dumpRaysEvery) + " out of range 1 .. 1000000");
    if (c.modes.empty()) return Status::error("--modes: no mode given; available modes: " + renderModeNames());
    for (const auto& m : c.modes)
        if (!findRenderMode(m))
            return Status::error("--modes: unknown mode '" + m + "'; available modes: " + renderModeNames());
    return checkModeOptions(c.options);
}

Result<BenchResult> runBenchmark(const SceneModel* city, osg::Node* scene, const Path& path, const BenchConfig& cfgIn) {
    const BenchConfig cfg = withFullFirst(cfgIn);
    VISTA_RETURN_IF_ERROR(validateBenchConfig(cfg));
    if (path.samples.empty()) return Status::error("the walkthrough path has no samples");
    std::unique_ptr<tbb::global_control> threads;
    if (cfg.options.threads > 0)
        threads.reset(
            new tbb::global_control(tbb::global_control::max_allowed_parallelism, size_t(cfg.options.threads)));
    auto run = setUp(city, scene, cfg);
    if (!run) return run.status();
    BenchResult result;
    result.memory = cfg.memoryPhases;
    result.memory.push_back(memoryPhase("setup"));
    if (!cfg.dumpRaysDir.empty()) {
        const auto& ms = (*run)->modes;
        if (std::none_of(ms.begin(), ms.end(), [](const auto& m) { return m->lastTracedPixels() != nullptr; }))
            return Status::error("--dump-rays: no mode among --modes has a far-field ray stage (hybrid has)");
    }
    // Every output file is staged and committed at the end; directories made
    // here that stay empty (a failed run) are removed again.
    OutputBatch batch;
    CreatedDirectories made;
    if (!cfg.dumpRaysDir.empty()) VISTA_RETURN_IF_ERROR(made.create("--dump-rays", cfg.dumpRaysDir));
    if (!cfg.outDir.empty()) {
        VISTA_RETURN_IF_ERROR(made.create("--out", (fs::path(cfg.outDir) / "images").string()));
        if (cfg.saveFrames) VISTA_RETURN_IF_ERROR(made.create("--out", (fs::path(cfg.outDir) / "frames").string()));
    }
    Camera base;
    base.width = cfg.width;
    base.height = cfg.height;
    base.fovY = degToRad(cfg.fovYDeg);
    base.zNear = cfg.zNear;
    const std::vector<size_t> idx = path.frames(size_t(cfg.frames), cfg.sampleRuns);
    result.streamed = (*run)->stream != nullptr;
    if (result.streamed) {
        // The first frame's regions before anything is timed: it always waits for them.
        int arrived = 0;
        VISTA_RETURN_IF_ERROR(advanceStream(**run, path, idx[0], path.camera(idx[0], base), result, &arrived, true));
    }
    if (cfg.warmup) VISTA_RETURN_IF_ERROR(warmUp(**run, path.camera(idx[0], base)));

    result.loadAvgStart = loadAverage();
    FrameImages images(cfg, (*run)->modes.size(), batch);
    VISTA_RETURN_IF_ERROR(renderFrames(**run, path, idx, base, cfg, result, images, batch));
    result.memory.push_back(memoryPhase("frames"));
    if (result.streamed) {
        result.stream = (*run)->stream->stats();
        result.streamOptions = (*run)->stream->options();
        noteStreamDetail("vista bench", result.streamDetail);
    }
    result.loadAvgEnd = loadAverage();
    result.glRenderer = (*run)->renderer->glRenderer();
    result.motion = pathMotion(path, idx);
    const BenchRun& r = **run;
    for (size_t mi = 0; mi < r.modes.size(); ++mi) {
        std::vector<std::string> bases = speedupBases();
        if (mi >= r.plainCount) bases.push_back(r.labels[mi - r.plainCount]);  // the effects' cost ratio
        result.modes.push_back(summariseMode(result, r.labels[mi], bases, double(cfg.width) * double(cfg.height)));
        result.modes.back().setupMs = r.setup[mi];
    }
    if (!cfg.outDir.empty()) {
        VISTA_RETURN_IF_ERROR(writeBenchOutputs(result, cfg, city, path, batch));
        VISTA_RETURN_IF_ERROR(images.writeWorst());
    }
    VISTA_RETURN_IF_ERROR(batch.commit());
    made.keep();
    return result;
}

}  // namespace vista
