#include "cmd/bench.h"
#include "foundation/atomic_file.h"
#include "foundation/units.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <thread>

#include <osg/Group>
#include <osg/MatrixTransform>
#include <osgSim/Impostor>
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "citygen/lighting.h"
#include "runtime/scene/city_file.h"
#include "runtime/engine/metrics.h"
#include "nodes/render/offscreen.h"
#include "cmd/plot.h"
#include "runtime/engine/ray_scene.h"
// Hooks for the modes of later issues (add the include with the table entry):
#include "nodes/render/mode_hybrid.h"   // Result<std::unique_ptr<BenchMode>> makeHybridMode(BenchContext&)

namespace vista {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// ---- full: every triangle, far plane at infinity ----------------------------
class FullMode : public BenchMode {
public:
    explicit FullMode(BenchContext& ctx) : _ctx(ctx) {}
    std::string name() const override { return "full"; }
    Status renderFrame(const Camera& camera, Image& out, FrameStats& stats) override {
        return _ctx.renderer->render(_ctx.scene, camera, 0.0, &out, nullptr, stats);
    }

private:
    BenchContext& _ctx;
};

// ---- near: only what lies within the near distance (far clip plane) --------
// Drawables beyond the plane are frustum-culled by OSG, the rest is clipped
// per pixel. The proper near/far split node comes with the far field.
class NearMode : public BenchMode {
public:
    explicit NearMode(BenchContext& ctx) : _ctx(ctx) {}
    std::string name() const override { return "near"; }
    Status renderFrame(const Camera& camera, Image& out, FrameStats& stats) override {
        double d = _ctx.options.nearDistance > 0 ? _ctx.options.nearDistance : 100.0;
        if (_ctx.options.nearDistance <= 0) stats.notes.push_back("near distance auto -> 100 m");
        return _ctx.renderer->render(_ctx.scene, camera, std::max(d, camera.zNear * 2), &out, nullptr, stats);
    }

private:
    BenchContext& _ctx;
};

// ---- raycast: every pixel cast with Embree, prelit colours, sky on a miss ---
class RaycastMode : public BenchMode {
public:
    explicit RaycastMode(BenchContext& ctx) : _ctx(ctx) {}
    std::string name() const override { return "raycast"; }
    Status renderFrame(const Camera& camera, Image& out, FrameStats& stats) override {
        if (!_ctx.rays) return Status::error("raycast mode: no ray scene (the city could not be loaded for Embree)");
        auto t0 = Clock::now();
        const RayScene& rays = *_ctx.rays;
        if (out.width != camera.width || out.height != camera.height) out = Image(camera.width, camera.height);
        const glm::vec3 org(camera.eye - rays.frameOrigin());
        const int W = camera.width;
        // Camera::rayDirection with the basis hoisted out of the pixel loop
        // (same operations in the same order: bit-identical directions).
        const glm::dvec3 fw = camera.forward(), rt = camera.right(), up = camera.up();
        const double tanHalf = std::tan(0.5 * camera.fovY), aspect = double(camera.width) / double(camera.height);
        tbb::combinable<uint64_t> hits([] { return uint64_t(0); });
        tbb::parallel_for(tbb::blocked_range<int>(0, camera.height, 4), [&](const tbb::blocked_range<int>& r) {
            const size_t n = static_cast<size_t>(W);
            std::vector<glm::vec3> orgs(n, org), dirs(n);
            std::vector<glm::dvec3> ddirs(n);
            std::vector<RayHit> res(n);
            uint64_t nh = 0;
            for (int y = r.begin(); y != r.end(); ++y) {
                for (int x = 0; x < W; ++x) {
                    double sx = (2.0 * (x + 0.5) / camera.width - 1.0) * tanHalf * aspect;
                    double sy = (1.0 - 2.0 * (y + 0.5) / camera.height) * tanHalf;
                    ddirs[size_t(x)] = glm::normalize(fw + sx * rt + sy * up);
                    dirs[size_t(x)] = glm::vec3(ddirs[size_t(x)]);
                }
                rays.intersectMany(orgs.data(), dirs.data(), W, res.data());
                for (int x = 0; x < W; ++x) {
                    const RayHit& h = res[size_t(x)];
                    if (h.hit) {
                        out.set(x, y, glm::u8vec4(h.color.x, h.color.y, h.color.z, 255));
                        ++nh;
                    } else {
                        out.set(x, y, skyColor(std::asin(std::clamp(ddirs[size_t(x)].z, -1.0, 1.0))));
                    }
                }
            }
            hits.local() += nh;
        });
        stats.frameMs = msSince(t0);
        stats.drawMs = stats.frameMs;
        stats.pixels.rayHit = hits.combine(std::plus<uint64_t>());
        stats.pixels.rayMiss = uint64_t(camera.width) * uint64_t(camera.height) - stats.pixels.rayHit;
        stats.stages.set(Stage::Rays, stats.frameMs);
        return Status::ok();
    }

private:
    BenchContext& _ctx;
};

// ---- osgimpostor: stock osgSim::Impostor (an osg::LOD) on every tile ---------
// What an OSG user would do today: each tile beyond the near distance is drawn
// as an impostor sprite, re-rendered when the view changes too much.
class OsgImpostorMode : public BenchMode {
public:
    explicit OsgImpostorMode(BenchContext& ctx) : _ctx(ctx) {
        double nearD = ctx.options.nearDistance > 0 ? ctx.options.nearDistance : 100.0;
        _root = new osg::Group;
        auto wrap = [&](osg::Group* parent, osg::Node* child, const std::vector<osg::ref_ptr<osg::Node>>& kids) {
            osg::ref_ptr<osgSim::Impostor> imp = new osgSim::Impostor;
            for (const auto& k : kids) imp->addChild(k.get(), 0.0f, std::numeric_limits<float>::max());
            imp->setImpostorThreshold(float(nearD + imp->getBound().radius()));
            (void)child;
            parent->addChild(imp.get());
            ++_impostors;
        };
        osg::Group* g = ctx.scene ? ctx.scene->asGroup() : nullptr;
        if (!g) {
            if (ctx.scene) wrap(_root.get(), ctx.scene, {ctx.scene});
            return;
        }
        for (unsigned i = 0; i < g->getNumChildren(); ++i) {
            osg::Node* c = g->getChild(i);
            if (auto* mt = dynamic_cast<osg::MatrixTransform*>(c)) {
                osg::ref_ptr<osg::MatrixTransform> copy = new osg::MatrixTransform(mt->getMatrix());
                copy->setName(mt->getName());
                copy->setStateSet(mt->getStateSet());
                std::vector<osg::ref_ptr<osg::Node>> kids;
                for (unsigned k = 0; k < mt->getNumChildren(); ++k) kids.push_back(mt->getChild(k));
                wrap(copy.get(), c, kids);
                _root->addChild(copy.get());
            } else {
                wrap(_root.get(), c, {c});
            }
        }
        _root->setStateSet(g->getStateSet());
    }
    std::string name() const override { return "osgimpostor"; }
    Status renderFrame(const Camera& camera, Image& out, FrameStats& stats) override {
        return _ctx.renderer->render(_root.get(), camera, 0.0, &out, nullptr, stats);
    }

private:
    BenchContext& _ctx;
    osg::ref_ptr<osg::Group> _root;
    int _impostors = 0;
};

Result<std::unique_ptr<BenchMode>> makeFull(BenchContext& c) { return std::unique_ptr<BenchMode>(new FullMode(c)); }
Result<std::unique_ptr<BenchMode>> makeNear(BenchContext& c) { return std::unique_ptr<BenchMode>(new NearMode(c)); }
Result<std::unique_ptr<BenchMode>> makeRaycast(BenchContext& c) {
    if (!c.rays) return Status::error("mode raycast needs the city's ray scene, which is not available");
    return std::unique_ptr<BenchMode>(new RaycastMode(c));
}
Result<std::unique_ptr<BenchMode>> makeOsgImpostor(BenchContext& c) {
    return std::unique_ptr<BenchMode>(new OsgImpostorMode(c));
}

// ---- the mode table ----------------------------------------------------------
// Modes of libraries that depend on runtime (the bake's `impostor`) are added
// at start-up with registerBenchMode() (the `vista` tool's main does it).
std::vector<ModeInfo> kModeTable = {
    {"full", "all geometry, far plane at infinity (the reference)", false, makeFull},
    {"near", "only the near field within --near metres", false, makeNear},
    {"raycast", "every pixel ray cast with Embree, prelit colours", true, makeRaycast},
    {"osgimpostor", "stock osgSim::Impostor on every tile beyond --near", false, makeOsgImpostor},
    {"hybrid", "near field + ray-cast far field (issue 4)", true, makeHybridMode},
};

std::string joinModes() {
    std::string s;
    for (const auto& m : kModeTable) s += (s.empty() ? "" : ", ") + std::string(m.name);
    return s;
}

std::string cpuModel() {
    std::ifstream f("/proc/cpuinfo");
    std::string line;
    while (std::getline(f, line))
        if (line.rfind("model name", 0) == 0) {
            auto p = line.find(':');
            if (p != std::string::npos) return line.substr(p + 2);
        }
    return "unknown";
}

// 1-minute load average (other processes competing for the cores), or -1.
double loadAverage() {
    std::ifstream f("/proc/loadavg");
    double v = -1;
    if (!(f >> v)) return -1;
    return v;
}

struct Worst {
    double psnr;
    int frame;
    Image image, reference;
};

}  // namespace

const std::vector<ModeInfo>& modeTable() { return kModeTable; }

void registerBenchMode(const ModeInfo& mode) {
    for (auto& m : kModeTable)
        if (std::string(m.name) == mode.name) {
            m = mode;
            return;
        }
    kModeTable.push_back(mode);
}

std::vector<std::string> availableModes() {
    std::vector<std::string> v;
    for (const auto& m : kModeTable) v.push_back(m.name);
    return v;
}

const ModeInfo* findMode(const std::string& name) {
    for (const auto& m : kModeTable)
        if (name == m.name) return &m;
    return nullptr;
}

Result<std::unique_ptr<BenchMode>> makeMode(const std::string& name, BenchContext& ctx) {
    const ModeInfo* m = findMode(name);
    if (!m) return Status::error("unknown mode '" + name + "'; available modes: " + joinModes());
    return m->make(ctx);
}

Result<std::vector<std::string>> parseModeList(const std::string& list) {
    std::vector<std::string> out;
    std::stringstream ss(list);
    std::string item;
    while (std::getline(ss, item, ',')) {
        item.erase(0, item.find_first_not_of(" \t"));
        if (!item.empty()) item.erase(item.find_last_not_of(" \t") + 1);
        if (item.empty()) continue;
        if (!findMode(item)) return Status::error("--modes: unknown mode '" + item + "'; available modes: " + joinModes());
        if (std::find(out.begin(), out.end(), item) != out.end())
            return Status::error("--modes: mode '" + item + "' listed twice");
        out.push_back(item);
    }
    if (out.empty()) return Status::error("--modes '" + list + "': no mode given; available modes: " + joinModes());
    return out;
}

Status validateBenchConfig(const BenchConfig& c) {
    if (c.width < 1 || c.height < 1 || c.width > 8192 || c.height > 8192)
        return Status::error("--size " + std::to_string(c.width) + "x" + std::to_string(c.height) +
                             " out of range 1x1 .. 8192x8192");
    if (c.frames < 1 || c.frames > 1000000)
        return Status::error("--frames " + std::to_string(c.frames) + " out of range 1 .. 1000000");
    if (!(c.fovYDeg > 1 && c.fovYDeg < 179)) return Status::error("--fov " + std::to_string(c.fovYDeg) + " out of range (1, 179) degrees");
    if (c.referenceSsaa < 0 || c.referenceSsaa > 8)
        return Status::error("--reference ssaa:" + std::to_string(c.referenceSsaa) + " out of range 1 .. 8");
    if (c.diffThreshold < 0 || c.diffThreshold > 255)
        return Status::error("--diff-threshold " + std::to_string(c.diffThreshold) + " out of range 0 .. 255");
    if (c.modes.empty()) return Status::error("--modes: no mode given; available modes: " + joinModes());
    for (const auto& m : c.modes)
        if (!findMode(m)) return Status::error("--modes: unknown mode '" + m + "'; available modes: " + joinModes());
    const BenchOptions& o = c.options;
    if (!(o.nearDistance < 0) && !(o.nearDistance >= kMinNearDistance && o.nearDistance <= kMaxNearDistance))
        return Status::error("--near " + std::to_string(o.nearDistance) + " out of range 1 .. 100000 metres (or 'auto')");
    if (o.pixelBudget > kMaxPixelBudget)
        return Status::error("--budget " + std::to_string(o.pixelBudget) + " out of range 0 .. " +
                             std::to_string(kMaxPixelBudget) + " rays per frame (or 'unlimited' / -1)");
    if (o.horizonGrid < 1 || o.horizonGrid > 8192)
        return Status::error("--horizon-grid " + std::to_string(o.horizonGrid) + " out of range 1 .. 8192 cells per side");
    if (o.threads < 0 || o.threads > 1024)
        return Status::error("--threads " + std::to_string(o.threads) + " out of range 0 .. 1024 (0 = all cores)");
    return Status::ok();
}

Result<double> parseNearDistance(const std::string& s) {
    if (s == "auto") return -1.0;
    char* end = nullptr;
    double v = std::strtod(s.c_str(), &end);
    if (s.empty() || !end || *end || !std::isfinite(v))
        return Status::error("--near '" + s + "': expected a distance in metres (1 .. 100000) or 'auto'");
    if (v < kMinNearDistance || v > kMaxNearDistance)
        return Status::error("--near " + s + " out of range 1 .. 100000 metres (or 'auto')");
    return v;
}

Result<int64_t> parsePixelBudget(const std::string& s) {
    const std::string range = " rays per frame, or 'unlimited' / -1";
    if (s == "unlimited" || s == "-1") return int64_t(-1);
    char* end = nullptr;
    errno = 0;
    long long v = std::strtoll(s.c_str(), &end, 10);
    if (s.empty() || !end || *end || errno == ERANGE)
        return Status::error("--budget '" + s + "': expected an integer 0 .. " + std::to_string(kMaxPixelBudget) + range);
    if (v < 0 || v > kMaxPixelBudget)
        return Status::error("--budget " + s + " out of range 0 .. " + std::to_string(kMaxPixelBudget) + range);
    return int64_t(v);
}

double percentile(std::vector<double> v, double p) {
    v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
    if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
    std::sort(v.begin(), v.end());
    double pos = std::clamp(p, 0.0, 1.0) * double(v.size() - 1);
    size_t i = size_t(std::floor(pos));
    double f = pos - double(i);
    return i + 1 < v.size() ? v[i] * (1 - f) + v[i + 1] * f : v[i];
}

Result<BenchResult> runBenchmark(const SceneModel* city, osg::Node* scene, const Path& path, const BenchConfig& cfgIn) {
    BenchConfig cfg = cfgIn;
    VISTA_RETURN_IF_ERROR(validateBenchConfig(cfg));
    if (path.samples.empty()) return Status::error("the walkthrough path has no samples");
    if (std::find(cfg.modes.begin(), cfg.modes.end(), "full") == cfg.modes.end())
        cfg.modes.insert(cfg.modes.begin(), "full");  // the reference is always rendered
    else {  // render the reference first in every frame
        cfg.modes.erase(std::find(cfg.modes.begin(), cfg.modes.end(), "full"));
        cfg.modes.insert(cfg.modes.begin(), "full");
    }
    std::unique_ptr<tbb::global_control> threads;
    if (cfg.options.threads > 0)
        threads.reset(new tbb::global_control(tbb::global_control::max_allowed_parallelism, size_t(cfg.options.threads)));

    auto rendererR = OffscreenRenderer::create(cfg.width, cfg.height);
    if (!rendererR) return rendererR.status();
    std::unique_ptr<OffscreenRenderer> renderer = std::move(rendererR.value());

    BenchContext ctx;
    ctx.city = city;
    ctx.scene = scene;
    ctx.renderer = renderer.get();
    ctx.options = cfg.options;
    std::unique_ptr<RayScene> rays;
    bool needRays = false;
    for (const auto& m : cfg.modes) needRays = needRays || findMode(m)->needsRays;
    if (needRays) {
        if (!city) return Status::error("modes that cast rays need a loaded city file (no city given)");
        auto t0 = Clock::now();
        auto r = RayScene::build(*city);
        if (!r) return Status::error("building the Embree ray scene failed: " + r.status().message());
        rays = std::move(r.value());
        ctx.rays = rays.get();
        if (!cfg.quiet) std::fprintf(stderr, "ray scene built in %.0f ms\n", msSince(t0));
    }
    std::vector<std::unique_ptr<BenchMode>> modes;
    for (const auto& m : cfg.modes) {
        auto r = makeMode(m, ctx);
        if (!r) return r.status();
        modes.push_back(std::move(r.value()));
    }

    namespace fs = std::filesystem;
    if (!cfg.outDir.empty()) {
        std::error_code ec;
        fs::create_directories(fs::path(cfg.outDir) / "images", ec);
        if (ec) return Status::error("--out '" + cfg.outDir + "': cannot create directory: " + ec.message());
    }

    Camera base;
    base.width = cfg.width;
    base.height = cfg.height;
    base.fovY = cfg.fovYDeg * kPi / 180.0;
    base.zNear = cfg.zNear;
    std::vector<size_t> idx = path.spread(size_t(cfg.frames));

    BenchResult result;
    const size_t M = modes.size();
    std::vector<std::vector<Worst>> worst(M);
    Image img, ref;
    if (cfg.warmup) {
        Camera c = path.camera(idx[0], base);
        for (auto& m : modes) {
            FrameStats s;
            Status st = m->renderFrame(c, img, s);
            if (!st) return Status::error("mode " + m->name() + ": " + st.message());
        }
        for (auto& m : modes) m->reset();
    }
    const double loadStart = loadAverage();
    auto tStart = Clock::now();
    for (size_t f = 0; f < idx.size(); ++f) {
        Camera cam = path.camera(idx[f], base);
        if (cfg.referenceSsaa >= 2) {
            int k = cfg.referenceSsaa;
            std::vector<Image> subs;
            for (int j = 0; j < k; ++j)
                for (int i = 0; i < k; ++i) {
                    renderer->setSubpixelOffset((i + 0.5) / k - 0.5, (j + 0.5) / k - 0.5);
                    FrameStats s;
                    Image sub;
                    VISTA_RETURN_IF_ERROR(renderer->render(scene, cam, 0.0, &sub, nullptr, s));
                    subs.push_back(std::move(sub));
                }
            renderer->setSubpixelOffset(0, 0);
            ref = averageImages(subs);
        }
        for (size_t mi = 0; mi < M; ++mi) {
            BenchFrameRecord rec;
            rec.frame = int(f);
            rec.pathIndex = idx[f];
            rec.t = path.samples[idx[f]].t;
            rec.mode = modes[mi]->name();
            Status st = modes[mi]->renderFrame(cam, img, rec.stats);
            if (!st) return Status::error("mode " + rec.mode + ", frame " + std::to_string(f) + ": " + st.message());
            if (!img.valid() || img.width != cfg.width || img.height != cfg.height)
                return Status::error("mode " + rec.mode + " returned an image of the wrong size");
            if (mi == 0 && cfg.referenceSsaa < 2) ref = img;
            rec.psnrDb = lumaPsnr(img, ref);
            rec.diffFraction = fractionDiffering(img, ref, cfg.diffThreshold);
            if (f == 0 && !cfg.outDir.empty())
                VISTA_RETURN_IF_ERROR(writePng(img, (fs::path(cfg.outDir) / "images" / ("first_" + rec.mode + ".png")).string()));
            if (cfg.worstFrames > 0 && !cfg.outDir.empty() && (mi > 0 || cfg.referenceSsaa >= 2)) {
                auto& w = worst[mi];
                if (int(w.size()) < cfg.worstFrames || rec.psnrDb < w.back().psnr) {
                    w.push_back({rec.psnrDb, int(f), img, ref});
                    std::sort(w.begin(), w.end(), [](const Worst& a, const Worst& b) { return a.psnr < b.psnr; });
                    if (int(w.size()) > cfg.worstFrames) w.pop_back();
                }
            }
            result.frames.push_back(std::move(rec));
        }
        if (!cfg.quiet && ((f + 1) % 10 == 0 || f + 1 == idx.size())) {
            const double el = msSince(tStart) / 1000.0, eta = el * double(idx.size() - f - 1) / double(f + 1);
            const bool tty = isatty(2);
            std::fprintf(stderr, tty ? "\rframe %zu/%zu (%.0f s, eta %.0f s)   " : "frame %zu/%zu (%.0f s, eta %.0f s)\n", f + 1,
                         idx.size(), el, eta);
            if (tty && f + 1 == idx.size()) std::fprintf(stderr, "\n");
        }
    }
    result.glRenderer = renderer->glRenderer();

    // Summaries.
    for (size_t mi = 0; mi < M; ++mi) {
        ModeSummary s;
        s.mode = modes[mi]->name();
        std::vector<double> ms, speed, psnr, diff, tri, calls, cull, draw;
        for (size_t f = 0; f < idx.size(); ++f) {
            const auto& r = result.frames[f * M + mi];
            const auto& full = result.frames[f * M + 0];
            ms.push_back(r.stats.frameMs);
            speed.push_back(r.stats.frameMs > 0 ? full.stats.frameMs / r.stats.frameMs : std::nan(""));
            psnr.push_back(r.psnrDb);
            diff.push_back(r.diffFraction);
            tri.push_back(double(r.stats.triangles));
            calls.push_back(double(r.stats.drawCalls));
            cull.push_back(r.stats.cullMs);
            draw.push_back(r.stats.drawMs);
        }
        s.frameMsMedian = percentile(ms, 0.5);
        s.frameMsP95 = percentile(ms, 0.95);
        double sum = 0;
        for (double v : ms) sum += v;
        s.frameMsMean = sum / double(ms.size());
        s.speedupVsFullMedian = percentile(speed, 0.5);
        s.psnrDbMedian = percentile(psnr, 0.5);
        s.psnrDbMin = *std::min_element(psnr.begin(), psnr.end());
        s.diffFractionMedian = percentile(diff, 0.5);
        s.trianglesMedian = percentile(tri, 0.5);
        s.drawCallsMedian = percentile(calls, 0.5);
        s.cullMsMedian = percentile(cull, 0.5);
        s.drawMsMedian = percentile(draw, 0.5);
        // Pixel classes and stage times.
        {
            const double npx = double(cfg.width) * double(cfg.height);
            PixelClassSummary* cls[5] = {&s.covered, &s.horizonCulled, &s.cache, &s.rayHit, &s.rayMiss};
            double sumPct[5] = {0, 0, 0, 0, 0}, sumCount[5] = {0, 0, 0, 0, 0};
            for (int k = 0; k < 5; ++k) cls[k]->minPct = std::numeric_limits<double>::infinity();
            std::map<std::string, double> stageSum;
            for (size_t f = 0; f < idx.size(); ++f) {
                const FrameStats& frs = result.frames[f * M + mi].stats;
                const PixelCounts& p = frs.pixels;
                const uint64_t c[5] = {p.covered, p.horizonCulled, p.cache, p.rayHit, p.rayMiss};
                for (int k = 0; k < 5; ++k) {
                    const double pct = 100.0 * double(c[k]) / npx;
                    cls[k]->minPct = std::min(cls[k]->minPct, pct);
                    cls[k]->maxPct = std::max(cls[k]->maxPct, pct);
                    sumPct[k] += pct;
                    sumCount[k] += double(c[k]);
                    if (c[k] > 0) s.hasPixels = true;
                }
                frs.stages.forEach([&](Stage stage, double ms) {
                    stageSum[stageName(stage)] += ms;
                    ++s.stageRuns[stageName(stage)];
                });
            }
            for (int k = 0; k < 5; ++k) {
                cls[k]->meanPct = sumPct[k] / double(idx.size());
                cls[k]->meanCount = sumCount[k] / double(idx.size());
            }
            for (const auto& kv : stageSum) s.stagesMsMean[kv.first] = kv.second / double(s.stageRuns[kv.first]);
        }
        result.modes.push_back(s);
    }
    if (cfg.outDir.empty()) return result;

    // frames.csv
    std::ostringstream csv;
    csv << "frame,path_index,t_s,mode,frame_ms,cull_ms,draw_ms,triangles,draw_calls,psnr_db,diff_fraction,"
           "px_covered,px_horizon_culled,px_cache,px_ray_hit,px_ray_miss,stages_ms,notes\n";
    char buf[512];
    for (const auto& r : result.frames) {
        std::snprintf(buf, sizeof(buf), "%d,%zu,%.4f,%s,%.3f,%.3f,%.3f,%llu,%llu,%.3f,%.6f,%llu,%llu,%llu,%llu,%llu,", r.frame,
                      r.pathIndex, r.t, r.mode.c_str(), r.stats.frameMs, r.stats.cullMs, r.stats.drawMs,
                      (unsigned long long)r.stats.triangles, (unsigned long long)r.stats.drawCalls, r.psnrDb,
                      r.diffFraction, (unsigned long long)r.stats.pixels.covered,
                      (unsigned long long)r.stats.pixels.horizonCulled, (unsigned long long)r.stats.pixels.cache,
                      (unsigned long long)r.stats.pixels.rayHit, (unsigned long long)r.stats.pixels.rayMiss);
        csv << buf;
        std::string st;
        r.stats.stages.forEach([&](Stage stage, double ms) {
            std::snprintf(buf, sizeof(buf), "%s%s=%.3f", st.empty() ? "" : ";", stageName(stage), ms);
            st += buf;
        });
        std::string notes;
        for (const auto& n : r.stats.notes) notes += (notes.empty() ? "" : ";") + n;
        std::replace(notes.begin(), notes.end(), ',', ' ');
        csv << st << "," << notes << "\n";
    }
    VISTA_RETURN_IF_ERROR(writeFileAtomic((fs::path(cfg.outDir) / "frames.csv").string(), csv.str()));

    // summary.json
    nlohmann::json j;
    j["command"] = cfg.command;
    j["city"] = cfg.cityLabel;
    j["city_triangles"] = city ? city->triangles : 0;
    j["size"] = {cfg.width, cfg.height};
    j["frames"] = cfg.frames;
    j["fov_y_deg"] = cfg.fovYDeg;
    j["near_m"] = cfg.options.nearDistance;  // < 0 = auto (kept for older readers; see "options")
    j["options"] = {
        {"near_m", cfg.options.nearDistance < 0 ? nlohmann::json("auto") : nlohmann::json(cfg.options.nearDistance)},
        {"pixel_budget", cfg.options.pixelBudget < 0 ? nlohmann::json("unlimited") : nlohmann::json(cfg.options.pixelBudget)},
        {"horizon_grid", cfg.options.horizonGrid},
        {"cache", cfg.options.cache},
        {"threads", cfg.options.threads}};
    j["reference"] = cfg.referenceSsaa >= 2 ? "ssaa:" + std::to_string(cfg.referenceSsaa) : std::string("full");
    j["psnr_cap_db"] = kPsnrCapDb;
    j["diff_threshold"] = cfg.diffThreshold;
    j["path_samples"] = path.samples.size();
    j["machine"] = {{"gl_renderer", result.glRenderer},
                    {"cpu", cpuModel()},
                    {"hardware_threads", std::thread::hardware_concurrency()},
                    {"load_avg_1min_start", loadStart},
                    {"load_avg_1min_end", loadAverage()}};
    nlohmann::json jm = nlohmann::json::object();
    for (const auto& s : result.modes) {
        auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
        jm[s.mode] = {{"frame_ms_median", num(s.frameMsMedian)},
                      {"frame_ms_p95", num(s.frameMsP95)},
                      {"frame_ms_mean", num(s.frameMsMean)},
                      {"speedup_vs_full_median", num(s.speedupVsFullMedian)},
                      {"psnr_db_median", num(s.psnrDbMedian)},
                      {"psnr_db_min", num(s.psnrDbMin)},
                      {"diff_fraction_median", num(s.diffFractionMedian)},
                      {"triangles_median", num(s.trianglesMedian)},
                      {"draw_calls_median", num(s.drawCallsMedian)},
                      {"cull_ms_median", num(s.cullMsMedian)},
                      {"draw_ms_median", num(s.drawMsMedian)}};
        if (s.hasPixels) {
            auto cls = [&](const PixelClassSummary& c) {
                return nlohmann::json{{"min_pct", num(c.minPct)},
                                      {"mean_pct", num(c.meanPct)},
                                      {"max_pct", num(c.maxPct)},
                                      {"mean_count", num(c.meanCount)}};
            };
            jm[s.mode]["pixels"] = {{"covered", cls(s.covered)},
                                    {"horizon_culled", cls(s.horizonCulled)},
                                    {"cache", cls(s.cache)},
                                    {"ray_hit", cls(s.rayHit)},
                                    {"ray_miss", cls(s.rayMiss)}};
        }
        nlohmann::json stages = nlohmann::json::object(), runs = nlohmann::json::object();
        for (const auto& kv : s.stagesMsMean) stages[kv.first] = num(kv.second);
        for (const auto& kv : s.stageRuns) runs[kv.first] = kv.second;
        jm[s.mode]["stages_ms"] = stages;
        jm[s.mode]["stage_runs"] = runs;
    }
    j["modes"] = jm;
    std::vector<std::string> order;
    for (const auto& s : result.modes) order.push_back(s.mode);
    j["mode_order"] = order;
    VISTA_RETURN_IF_ERROR(writeFileAtomic((fs::path(cfg.outDir) / "summary.json").string(), j.dump(2) + "\n"));

    // Plots: frame time per frame (thesis Fig. 4.8) and quality per frame.
    PlotSpec pt, pq;
    pt.title = "Frame time per frame";
    pt.xLabel = "frame";
    pt.yLabel = "ms";
    pq.title = "Quality vs reference (luma PSNR, cap 99 dB)";
    pq.xLabel = "frame";
    pq.yLabel = "dB";
    pq.yFromZero = false;
    for (size_t mi = 0; mi < M; ++mi) {
        PlotSeries st, sq;
        st.label = sq.label = modes[mi]->name();
        st.color = sq.color = plotColor(mi);
        for (size_t f = 0; f < idx.size(); ++f) {
            const auto& r = result.frames[f * M + mi];
            st.x.push_back(double(f));
            st.y.push_back(r.stats.frameMs);
            sq.x.push_back(double(f));
            sq.y.push_back(r.psnrDb);
        }
        pt.series.push_back(st);
        if (mi > 0 || cfg.referenceSsaa >= 2) pq.series.push_back(sq);
    }
    VISTA_RETURN_IF_ERROR(writePng(renderPlot(pt), (fs::path(cfg.outDir) / "frame_time.png").string()));
    VISTA_RETURN_IF_ERROR(writePng(renderPlot(pq), (fs::path(cfg.outDir) / "quality.png").string()));

    // Difference images of the worst frames.
    for (size_t mi = 0; mi < M; ++mi)
        for (size_t k = 0; k < worst[mi].size(); ++k) {
            const Worst& w = worst[mi][k];
            std::string stem = (fs::path(cfg.outDir) / "images" /
                                ("worst" + std::to_string(k + 1) + "_" + modes[mi]->name() + "_f" + std::to_string(w.frame)))
                                   .string();
            VISTA_RETURN_IF_ERROR(writePng(w.image, stem + ".png"));
            VISTA_RETURN_IF_ERROR(writePng(w.reference, stem + "_ref.png"));
            VISTA_RETURN_IF_ERROR(writePng(differenceImage(w.image, w.reference), stem + "_diff.png"));
        }
    return result;
}

}  // namespace vista
