// Far-field frame pipeline (see far_field.h).
#include "runtime/engine/far_field.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "citygen/lighting.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

enum : uint8_t { kCovered = 0, kHorizon = 1, kCache = 2, kHit = 3, kMiss = 4, kPending = 5 };

// The camera's pixel-centre ray directions, as Camera::rayDirection computes them.
struct RayGen {
    glm::dvec3 f, r, u;
    double t, aspect;
    int W, H;
    explicit RayGen(const Camera& c)
        : f(c.forward()), r(c.right()), u(c.up()), t(std::tan(0.5 * c.fovY)),
          aspect(double(c.width) / double(c.height)), W(c.width), H(c.height) {}
    glm::dvec3 dir(int x, int y) const {
        double sx = (2.0 * (x + 0.5) / W - 1.0) * t * aspect;
        double sy = (1.0 - 2.0 * (y + 0.5) / H) * t;
        return glm::normalize(f + sx * r + sy * u);
    }
};

bool sameCamera(const Camera& a, const Camera& b) {
    return a.eye == b.eye && a.heading == b.heading && a.pitch == b.pitch && a.roll == b.roll && a.fovY == b.fovY &&
           a.width == b.width && a.height == b.height;
}

}  // namespace

FarField::FarField(const RayScene& rays, const HeightGrid* grid, const FarFieldOptions& options)
    : _rays(rays), _grid(grid), _options(options) {}
FarField::~FarField() = default;

void FarField::setOptions(const FarFieldOptions& o) {
    bool cacheChanged = o.cache != _options.cache || o.cacheOversample != _options.cacheOversample;
    _options = o;
    if (cacheChanged) _cache.reset();
}

void FarField::reset() {
    if (_cache) _cache->clear();
    _prev = Image();
    _haveLast = false;
}

void FarField::render(const Camera& camera, const float* depth, Image& out, FrameStats& stats) {
    VISTA_CHECK(camera.width >= 1 && camera.height >= 1);
    const int W = camera.width, H = camera.height;
    const size_t N = size_t(W) * size_t(H);
    if (out.width != W || out.height != H || !out.valid()) out = Image(W, H);
    const RayGen gen(camera);
    const bool moving = _haveLast && !sameCamera(_last, camera);

    // ---- opacity -------------------------------------------------------------
    auto t0 = Clock::now();
    _class.assign(N, kPending);
    std::vector<uint8_t> columnNeeded(size_t(W), 0);
    uint64_t covered = 0;
    if (depth) {
        for (int y = 0; y < H; ++y) {
            const float* d = depth + size_t(y) * size_t(W);
            uint8_t* c = &_class[size_t(y) * size_t(W)];
            for (int x = 0; x < W; ++x) {
                if (d[x] < 1.0f) {
                    c[x] = kCovered;
                    ++covered;
                } else {
                    columnNeeded[size_t(x)] = 1;
                }
            }
        }
    } else {
        std::fill(columnNeeded.begin(), columnNeeded.end(), uint8_t(1));
    }
    stats.stages.add(Stage::Opacity, msSince(t0));

    // ---- seam check: covered pixels beyond the near distance ------------------
    if (depth && covered > 0 && _options.verifySeam && _options.nearIsDistance && _options.nearDistance > 0 &&
        _rays.triangleCount() > 0) {
        auto ts = Clock::now();
        const double n = camera.zNear, f = _options.depthZFar;
        const double nearD = _options.nearDistance;
        std::vector<uint32_t> check;
        std::vector<float> dist;
        for (size_t i = 0; i < N; ++i) {
            if (_class[i] != kCovered) continue;
            double zn = 2.0 * double(depth[i]) - 1.0;
            double ze = f > 0 ? 2.0 * f * n / ((f + n) - zn * (f - n)) : 2.0 * n / (1.0 - zn);
            int x = int(i % size_t(W)), y = int(i / size_t(W));
            double sx = (2.0 * (x + 0.5) / W - 1.0) * gen.t * gen.aspect, sy = (1.0 - 2.0 * (y + 0.5) / H) * gen.t;
            double t = ze * std::sqrt(1.0 + sx * sx + sy * sy);
            if (t > nearD) {
                check.push_back(uint32_t(i));
                dist.push_back(float(t * (1.0 - 1e-3)));
            }
        }
        if (!check.empty()) {
            const glm::vec3 org(camera.eye - _rays.frameOrigin());
            std::vector<RayHit> res(check.size());
            auto body = [&] {
                tbb::parallel_for(tbb::blocked_range<size_t>(0, check.size(), 256), [&](const tbb::blocked_range<size_t>& br) {
                    for (size_t k = br.begin(); k != br.end(); ++k) {
                        uint32_t i = check[k];
                        glm::vec3 d(gen.dir(int(i % uint32_t(W)), int(i / uint32_t(W))));
                        res[k] = _rays.intersect(org, d, 0.0f, dist[k]);
                    }
                });
            };
            if (_options.threads > 0) {
                tbb::task_arena arena(_options.threads);
                arena.execute(body);
            } else {
                body();
            }
            uint64_t replaced = 0;
            for (size_t k = 0; k < check.size(); ++k)
                if (res[k].hit) {
                    uint32_t i = check[k];
                    _class[i] = kHit;
                    out.set(int(i % uint32_t(W)), int(i / uint32_t(W)),
                            glm::u8vec4(res[k].color.x, res[k].color.y, res[k].color.z, 255));
                    ++replaced;
                }
            covered -= replaced;
            stats.pixels.rayHit += replaced;
        }
        stats.stages.add(Stage::Seam, msSince(ts));
    }
    stats.pixels.covered += covered;
    _last = camera;
    _haveLast = true;
    if (covered == N) return;  // no sky, no far field visible: nothing else runs

    // Sky colours for this orientation (cached across frames).
    const double key[4] = {camera.pitch, camera.roll, camera.fovY, double(W) * 65536.0 + H};
    if (!std::equal(key, key + 4, _skyKey)) {
        _sky = Image(W, H);
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                glm::dvec3 d = gen.dir(x, y);
                _sky.set(x, y, skyColor(std::asin(std::clamp(d.z, -1.0, 1.0))));
            }
        std::copy(key, key + 4, _skyKey);
    }
    // Note: the sky image depends on pitch/roll/fov only; heading rotates the
    // world around the vertical axis, which leaves elevations unchanged.

    // ---- far geometry at all? -------------------------------------------------
    bool farGeometry = _grid ? !_grid->empty() : _rays.triangleCount() > 0;
    if (farGeometry && _grid && _options.nearIsDistance && _options.nearDistance > 0) {
        glm::dvec3 e = camera.eye - _grid->frameOrigin(), lo = _grid->boundsMin(), hi = _grid->boundsMax();
        double far2 = 0;
        for (int k = 0; k < 3; ++k) {
            double a = std::max(std::abs(e[k] - lo[k]), std::abs(e[k] - hi[k]));
            far2 += a * a;
        }
        if (far2 < _options.nearDistance * _options.nearDistance) farGeometry = false;
    }
    if (!farGeometry) {
        stats.notes.push_back("rays off: no far geometry beyond the near distance");
        auto tc = Clock::now();
        uint64_t sky = 0;
        for (size_t i = 0; i < N; ++i)
            if (_class[i] == kPending) {
                _class[i] = kHorizon;
                std::copy_n(&_sky.rgba[i * 4], 4, &out.rgba[i * 4]);
                ++sky;
            }
        stats.pixels.horizonCulled += sky;
        stats.stages.add(Stage::Composite, msSince(tc));
        return;
    }

    // ---- horizon --------------------------------------------------------------
    std::vector<int> row(size_t(W), 0);
    if (_options.horizon && _grid) {
        auto th = Clock::now();
        HorizonOptions ho;
        ho.nearDistance = _options.nearIsDistance ? _options.nearDistance : 0.0;
        ho.subsample = moving ? std::max(1, _options.horizonSubsampleMoving) : 1;
        ho.columnNeeded = &columnNeeded;
        HorizonResult hr = traceHorizon(*_grid, camera, ho);
        if (hr.active) {
            row = hr.row;
            stats.stages.add(Stage::Horizon, msSince(th));
        } else {
            stats.notes.push_back(hr.reason);
        }
    } else if (_options.horizon) {
        stats.notes.push_back("horizon off: no height grid");
    }
    uint64_t culled = 0;
    for (int x = 0; x < W; ++x) {
        int r = std::min(row[size_t(x)], H);
        for (int y = 0; y < r; ++y) {
            size_t i = size_t(y) * size_t(W) + size_t(x);
            if (_class[i] == kPending) {
                _class[i] = kHorizon;
                ++culled;
            }
        }
    }
    stats.pixels.horizonCulled += culled;

    // ---- cache ----------------------------------------------------------------
    std::vector<uint32_t> pending;
    for (size_t i = 0; i < N; ++i)
        if (_class[i] == kPending) pending.push_back(uint32_t(i));
    std::vector<uint32_t> traceList;
    std::vector<int64_t> traceCells;
    const bool useCache = _options.cache && _options.pixelBudget >= 0;
    if (useCache && !pending.empty()) {
        auto tc = Clock::now();
        const double cacheKey[4] = {camera.fovY, double(W), double(H), _options.cacheOversample};
        if (!_cache || !std::equal(cacheKey, cacheKey + 4, _cacheKey)) {
            _cache = std::make_unique<PanoramaCache>(PanoramaCache::forCamera(camera, _options.cacheOversample));
            std::copy(cacheKey, cacheKey + 4, _cacheKey);
        }
        _cache->beginFrame(camera);
        std::vector<CacheCandidate> cand(pending.size());
        for (size_t k = 0; k < pending.size(); ++k) {
            uint32_t i = pending[k];
            cand[k].pixel = i;
            cand[k].cell = _cache->index(gen.dir(int(i % uint32_t(W)), int(i / uint32_t(W))));
        }
        std::vector<uint8_t> trace;
        _cache->selectForTracing(cand, _options.pixelBudget, trace);
        uint64_t fromCache = 0;
        for (size_t k = 0; k < pending.size(); ++k) {
            uint32_t i = pending[k];
            if (trace[k]) {
                traceList.push_back(i);
                traceCells.push_back(cand[k].cell);
            } else {
                _class[i] = kCache;
                glm::u8vec4 c = _cache->color(cand[k].cell);
                if (c.w == 0) {  // never traced (budget short): last frame's pixel, else sky, until refined
                    const bool prev = _prev.width == W && _prev.height == H;
                    const uint8_t* s = prev ? &_prev.rgba[size_t(i) * 4] : &_sky.rgba[size_t(i) * 4];
                    c = glm::u8vec4(s[0], s[1], s[2], 255);
                }
                std::copy_n(&c[0], 4, &out.rgba[size_t(i) * 4]);
                ++fromCache;
            }
        }
        stats.pixels.cache += fromCache;
        stats.stages.add(Stage::Cache, msSince(tc));
    } else {
        traceList = pending;
        if (!_options.cache) {
            // nothing
        } else if (!pending.empty()) {
            stats.notes.push_back("cache bypassed: unlimited pixel budget");
        }
    }

    // ---- rays -----------------------------------------------------------------
    std::vector<glm::u8vec4> traced(traceList.size());
    if (!traceList.empty()) {
        auto tr = Clock::now();
        const glm::vec3 org(camera.eye - _rays.frameOrigin());
        std::vector<uint8_t> hit(traceList.size(), 0);
        auto body = [&] {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, traceList.size(), 256), [&](const tbb::blocked_range<size_t>& br) {
                const size_t n = br.size();
                std::vector<glm::vec3> orgs(n, org), dirs(n);
                std::vector<RayHit> res(n);
                for (size_t k = 0; k < n; ++k) {
                    uint32_t i = traceList[br.begin() + k];
                    dirs[k] = glm::vec3(gen.dir(int(i % uint32_t(W)), int(i / uint32_t(W))));
                }
                _rays.intersectMany(orgs.data(), dirs.data(), int(n), res.data());
                for (size_t k = 0; k < n; ++k) {
                    size_t j = br.begin() + k;
                    if (res[k].hit) {
                        traced[j] = glm::u8vec4(res[k].color.x, res[k].color.y, res[k].color.z, 255);
                        hit[j] = 1;
                    } else {
                        uint32_t i = traceList[j];
                        const uint8_t* s = &_sky.rgba[size_t(i) * 4];
                        traced[j] = glm::u8vec4(s[0], s[1], s[2], s[3]);
                    }
                }
            });
        };
        if (_options.threads > 0) {
            tbb::task_arena arena(_options.threads);
            arena.execute(body);
        } else {
            body();
        }
        uint64_t nh = 0;
        for (size_t j = 0; j < traceList.size(); ++j) {
            _class[traceList[j]] = hit[j] ? kHit : kMiss;
            nh += hit[j];
        }
        stats.pixels.rayHit += nh;
        stats.pixels.rayMiss += traceList.size() - nh;
        stats.stages.add(Stage::Rays, msSince(tr));
    }

    // ---- composite ------------------------------------------------------------
    auto tc = Clock::now();
    for (size_t j = 0; j < traceList.size(); ++j) std::copy_n(&traced[j][0], 4, &out.rgba[size_t(traceList[j]) * 4]);
    for (size_t i = 0; i < N; ++i)
        if (_class[i] == kHorizon) std::copy_n(&_sky.rgba[i * 4], 4, &out.rgba[i * 4]);
    if (useCache && _cache && !traceList.empty()) _cache->store(traceCells, traced);
    if (useCache) _prev = out;  // fallback for never-traced cache cells next frame
    stats.stages.add(Stage::Composite, msSince(tc));
}

}  // namespace vista
