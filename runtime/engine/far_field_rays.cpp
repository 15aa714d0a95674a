// Primary rays (far_field_rays.h) and the far field's ray stage (far_field_stages.h).
#include "runtime/engine/far_field_rays.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <vector>

#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include "citygen/lighting.h"
#include "foundation/status.h"
#include "foundation/timing.h"
#include "runtime/engine/far_field_haze.h"
#include "runtime/engine/far_field_stages.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

PixelRays::PixelRays(const Camera& c)
    : _f(c.forward()),
      _r(c.right()),
      _u(c.up()),
      _tanHalf(std::tan(0.5 * c.fovY)),
      _aspect(double(c.width) / double(c.height)),
      _width(c.width),
      _height(c.height) {}

glm::u8vec4 primarySkyColor(const glm::dvec3& dir) { return skyColor(std::asin(std::clamp(dir.z, -1.0, 1.0))); }

double minForwardCosine(const Camera& c) {
    const PixelRays g(c);
    const glm::dvec3 f = c.forward();
    double m = 1.0;
    for (int y : {0, c.height - 1})
        for (int x : {0, c.width - 1}) m = std::min(m, glm::dot(g.dir(x, y), f));
    return std::max(m, 1e-3);
}

namespace {

// Rays per parallel task (whole rows of 640 pixels: 4 rows a task).
constexpr size_t kRaysPerTask = 2048;
constexpr size_t kPacket = 8;  // RayScene::intersectMany's packet width

// The pixel list: explicit indices, or (null) the whole frame in order.
struct PixelList {
    const uint32_t* idx;
    uint32_t operator[](size_t k) const { return idx ? idx[k] : uint32_t(k); }
};

// Casts the entries runs[r] .. runs[r + 1] - 1 of every run r in packets of 8.
void castRuns(const RayScene& scene, const Camera& camera, PixelList pixels, const std::vector<size_t>& runs,
              Image& out, RayCounts& counts, int threads, uint8_t* hit, const RayShading& shading) {
    const size_t nRuns = runs.size() - 1, n = runs.back();
    if (n == 0) return;
    const PixelRays gen(camera);
    static const FrameEffects kNone;
    const FrameEffects& fx = shading.effects ? *shading.effects : kNone;
    const glm::dvec3 fwd = camera.forward();
    // Haze: nothing beyond hazeFar of eye-plane depth is traced (each ray
    // stops where its eye-plane depth reaches it; hits beyond show the sky).
    const double zMax = fx.haze ? fx.hazeFar() : 0.0;
    const glm::vec3 fwdF(fwd);
    const float zMaxF = float(zMax);
    const bool hazeAtWrite = shading.haze && fx.haze;
    const DepthHaze haze(hazeAtWrite ? fx : kNone);
    const uint32_t W = uint32_t(camera.width);
    const glm::vec3 org(camera.eye - scene.frameOrigin());
    const size_t grain = std::max<size_t>(1, (kRaysPerTask * nRuns + n - 1) / n);
    tbb::combinable<uint64_t> hits([] { return uint64_t(0); });
    inArena(threads, [&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, nRuns, grain), [&](const tbb::blocked_range<size_t>& br) {
            std::vector<glm::vec3> orgs, dirs;
            std::vector<glm::dvec3> ddirs;
            std::vector<float> tfars;
            std::vector<RayHit> res;
            std::vector<uint32_t> cols;  // hazeAtWrite: the run's colours and eye depths, hazed before they are written
            std::vector<float> zs;
            uint64_t nh = 0;
            for (size_t r = br.begin(); r != br.end(); ++r) {
                const size_t b = runs[r], m = runs[r + 1] - b;
                orgs.assign(m, org);
                dirs.resize(m);
                ddirs.resize(m);
                res.resize(m);
                if (fx.haze) tfars.resize(m);
                if (hazeAtWrite) {
                    cols.resize(m);
                    zs.resize(m);
                }
                for (size_t k = 0; k < m; ++k) {
                    const uint32_t i = pixels[b + k];
                    ddirs[k] = gen.dir(int(i % W), int(i / W));
                    dirs[k] = glm::vec3(ddirs[k]);
                }
                if (fx.haze)  // apart, so the compiler vectorises it
                    for (size_t k = 0; k < m; ++k) tfars[k] = hazeTfar(dirs[k], fwdF, zMaxF);
                scene.intersectMany(orgs.data(), dirs.data(), int(m), res.data(), 1e30f,
                                    fx.haze ? tfars.data() : nullptr, shading.tnear);
                for (size_t k = 0; k < m; ++k) {
                    const RayHit& h = res[k];
                    const double z = h.hit ? double(h.t) * glm::dot(ddirs[k], fwd) : 0.0;
                    const bool shown = h.hit && !(fx.haze && z > zMax);
                    const glm::u8vec4 c = shown ? h.color : fx.sky(ddirs[k]);
                    if (hazeAtWrite) {
                        std::memcpy(&cols[k], &c[0], 4);
                        zs[k] = shown ? float(z) : INFINITY;
                    } else {
                        std::copy_n(&c[0], 4, &out.rgba[size_t(pixels[b + k]) * 4]);
                    }
                    if (shading.depth) shading.depth[b + k] = shown ? float(z) : INFINITY;
                    if (shading.keys)
                        shading.keys[b + k] = shown ? SurfaceKey{h.geomId, h.primId, h.instId} : SurfaceKey{};
                    if (hit) hit[b + k] = shown ? 1 : 0;
                    nh += shown ? 1 : 0;
                }
                if (hazeAtWrite) {
                    haze(cols.data(), zs.data(), m);
                    for (size_t k = 0; k < m; ++k) std::memcpy(&out.rgba[size_t(pixels[b + k]) * 4], &cols[k], 4);
                }
            }
            hits.local() += nh;
        });
    });
    counts.rays += n;
    counts.hits += hits.combine(std::plus<uint64_t>());
}

}  // namespace

void castPrimaryRays(const RayScene& scene, const Camera& camera, const uint32_t* pixels, size_t n, Image& out,
                     RayCounts& counts, int threads, uint8_t* hit, const RayShading& shading) {
    VISTA_CHECK(out.width == camera.width && out.height == camera.height && out.valid());
    const uint32_t N = uint32_t(size_t(camera.width) * size_t(camera.height));
    for (size_t k = 0; k < n; ++k) VISTA_CHECK(pixels[k] < N);
    castRuns(scene, camera, PixelList{pixels}, coherentRuns(pixels, n, camera.width), out, counts, threads, hit,
             shading);
}

void castPixelRuns(const RayScene& scene, const Camera& camera, const uint32_t* pixels, const std::vector<size_t>& runs,
                   Image& out, RayCounts& counts, int threads, uint8_t* hit, const RayShading& shading) {
    castRuns(scene, camera, PixelList{pixels}, runs, out, counts, threads, hit, shading);
}

std::vector<size_t> coherentRuns(const uint32_t* pixels, size_t n, int width) {
    const uint32_t W = uint32_t(width);
    // A new run starts at a row change once the current one fills a packet
    // (dense rows stay alone; sparse rows share packets).
    std::vector<size_t> runs;
    for (size_t k = 0; k < n; ++k)
        if (k == 0 || (pixels[k] / W != pixels[k - 1] / W && k - runs.back() >= kPacket)) runs.push_back(k);
    runs.push_back(n);
    return runs;
}

PrimaryRays primaryRays(const Camera& camera, const glm::dvec3& frameOrigin, const uint32_t* pixels, size_t n,
                        double hazeFar, double tnear) {
    const PixelRays gen(camera);
    const glm::dvec3 fwd = camera.forward();
    const uint32_t W = uint32_t(camera.width);
    PrimaryRays r;
    r.org = glm::vec3(camera.eye - frameOrigin);
    r.tnear = float(tnear);
    r.dirs.resize(n);
    r.tfars.assign(n, 1e30f);
    for (size_t k = 0; k < n; ++k) {
        r.dirs[k] = glm::vec3(gen.dir(int(pixels[k] % W), int(pixels[k] / W)));
        if (hazeFar > 0) r.tfars[k] = hazeTfar(r.dirs[k], glm::vec3(fwd), float(hazeFar));
    }
    return r;
}

// ---- the far field's ray stage -------------------------------------------------

namespace {

// rayStep 2: rays for the entries on the even lattice (x and y even) first;
// an entry between lattice entries whose lattice neighbours (2 on a lattice
// row or column, else the 4 around it) were all cast this frame and all
// showed the same triangle takes their perspective-correct blend (colour
// and depth: 1/z is affine in screen space on a plane), or the sky of its own
// direction when they all showed sky; every other entry casts its own ray.
// Returns the number of interpolated entries; `hit`, `depth`, `keys` get one
// value per entry of f.trace, colours go to f.out.
uint64_t castOnLattice(FarFrame& f, FarFieldMemory& m, const RayScene& rays, int threads, float tnear,
                       RayCounts& counts, uint8_t* hit, float* depth) {
    const size_t n = f.trace.size();
    const uint32_t W = uint32_t(f.width), H = uint32_t(f.height);
    std::vector<uint32_t> lattice, rest;  // indices into f.trace
    lattice.reserve(n / 4 + 1);
    rest.reserve(n);
    for (size_t j = 0; j < n; ++j) {
        const uint32_t i = f.trace[j];
        ((i % W) % 2 == 0 && (i / W) % 2 == 0 ? lattice : rest).push_back(uint32_t(j));
    }
    auto castSubset = [&](const std::vector<uint32_t>& sub, std::vector<SurfaceKey>* keys) {
        if (sub.empty()) return;
        std::vector<uint32_t> pix(sub.size());
        std::vector<uint8_t> h(sub.size());
        std::vector<float> d(sub.size());
        for (size_t k = 0; k < sub.size(); ++k) pix[k] = f.trace[sub[k]];
        RayShading sh;
        sh.effects = f.fx;
        sh.depth = d.data();
        sh.tnear = tnear;
        if (keys) {
            keys->resize(sub.size());
            sh.keys = keys->data();
        }
        castPrimaryRays(rays, f.camera, pix.data(), pix.size(), f.out, counts, threads, h.data(), sh);
        for (size_t k = 0; k < sub.size(); ++k) {
            hit[sub[k]] = h[k];
            depth[sub[k]] = d[k];
        }
    };
    std::vector<SurfaceKey> latticeKeys;
    castSubset(lattice, &latticeKeys);
    // Which pixels were cast on the lattice this frame: slot into lattice (kept
    // across frames all ~0, reset below).
    std::vector<uint32_t>& slot = m.raySlot;
    if (slot.size() != f.pixelCount) slot.assign(f.pixelCount, ~0u);
    for (size_t k = 0; k < lattice.size(); ++k) slot[f.trace[lattice[k]]] = uint32_t(k);
    std::vector<uint8_t> done(rest.size(), 0);
    tbb::combinable<uint64_t> blended([] { return uint64_t(0); });
    inArena(threads, [&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, rest.size(), 4096), [&](const tbb::blocked_range<size_t>& br) {
            uint64_t nb = 0;
            for (size_t r = br.begin(); r != br.end(); ++r) {
                const uint32_t j = rest[r], i = f.trace[j], x = i % W, y = i / W;
                // Lattice neighbours: x (even) or x -+ 1 (odd), times the same for y.
                const uint32_t xs[2] = {x & 1u ? x - 1 : x, x + 1}, ys[2] = {y & 1u ? y - 1 : y, y + 1};
                const int nx = int(x & 1u) + 1, ny = int(y & 1u) + 1;
                uint32_t nbr[4];
                int cnt = 0;
                bool ok = true;
                for (int a = 0; a < ny && ok; ++a)
                    for (int b = 0; b < nx && ok; ++b) {
                        if (xs[b] >= W || ys[a] >= H) {
                            ok = false;
                            break;
                        }
                        const uint32_t s = slot[ys[a] * W + xs[b]];
                        if (s == ~0u || (cnt > 0 && !(latticeKeys[s] == latticeKeys[nbr[0]]))) ok = false;
                        else nbr[cnt++] = s;
                    }
                if (!ok || cnt == 0) continue;
                uint8_t* px = &f.out.rgba[size_t(i) * 4];
                if (latticeKeys[nbr[0]].sky()) {
                    const glm::u8vec4 c = f.fx->sky(f.rays.dir(int(x), int(y)));
                    std::copy_n(&c[0], 4, px);
                    hit[j] = 0;
                    depth[j] = INFINITY;
                } else {
                    double wsum = 0, c[4] = {0, 0, 0, 0};
                    for (int k = 0; k < cnt; ++k) {
                        const float z = depth[lattice[nbr[k]]];
                        const double w = 1.0 / std::max(double(z), 1e-6);
                        const uint8_t* q = &f.out.rgba[size_t(f.trace[lattice[nbr[k]]]) * 4];
                        for (int ch = 0; ch < 3; ++ch) c[ch] += w * q[ch];
                        wsum += w;
                    }
                    for (int ch = 0; ch < 3; ++ch) px[ch] = uint8_t(std::clamp(c[ch] / wsum + 0.5, 0.0, 255.0));
                    px[3] = f.out.rgba[size_t(f.trace[lattice[nbr[0]]]) * 4 + 3];  // glass mark: one triangle, one mark
                    hit[j] = 1;
                    depth[j] = float(double(cnt) / wsum);
                }
                done[r] = 1;
                ++nb;
            }
            blended.local() += nb;
        });
    });
    for (size_t k = 0; k < lattice.size(); ++k) slot[f.trace[lattice[k]]] = ~0u;
    std::vector<uint32_t> left;
    for (size_t r = 0; r < rest.size(); ++r)
        if (!done[r]) left.push_back(rest[r]);
    castSubset(left, nullptr);
    return blended.combine(std::plus<uint64_t>());
}

}  // namespace

void raysStage(FarFrame& f, FarFieldMemory& m, const RayScene& rays, const FarFieldOptions& o, FrameStats& stats) {
    Stopwatch sw;
    const size_t n = f.trace.size();
    std::vector<uint8_t> hit(n, 0);
    const bool lattice = o.rayStep >= 2;
    std::vector<float> depth(lattice || !f.farDepth.empty() ? n : 0);
    RayCounts counts;
    uint64_t blended = 0, hits = 0, misses = 0;
    if (lattice) {
        blended = castOnLattice(f, m, rays, o.threads, farRayStart(o), counts, hit.data(), depth.data());
        hits = counts.hits;
        misses = counts.rays - counts.hits;
    } else {
        RayShading shading;
        shading.effects = f.fx;
        shading.tnear = farRayStart(o);
        shading.haze = true;  // each task hazes what it writes (the speculative rays too)
        // The entries the speculative rays did not cast (all of them without speculation).
        const bool spec = m.spec.active();
        std::vector<uint32_t> left;
        if (spec) left = takeSpeculation(f, m, o, hit.data(), depth.empty() ? nullptr : depth.data(), stats);
        if (!spec || left.size() == n) {
            shading.depth = depth.empty() ? nullptr : depth.data();
            castPrimaryRays(rays, f.camera, f.trace.data(), n, f.out, counts, o.threads, hit.data(), shading);
        } else if (!left.empty()) {
            std::vector<uint32_t> pix(left.size());
            std::vector<uint8_t> h(left.size());
            std::vector<float> d(depth.empty() ? 0 : left.size());
            for (size_t k = 0; k < left.size(); ++k) pix[k] = f.trace[left[k]];
            shading.depth = d.empty() ? nullptr : d.data();
            castPrimaryRays(rays, f.camera, pix.data(), pix.size(), f.out, counts, o.threads, h.data(), shading);
            for (size_t k = 0; k < left.size(); ++k) {
                hit[left[k]] = h[k];
                if (!d.empty()) depth[left[k]] = d[k];
            }
        }
        // Every entry is cast now (here or ahead; speculative rays are in raysCast already).
        hits = uint64_t(std::count(hit.begin(), hit.end(), uint8_t(1)));
        misses = n - hits;
    }
    for (size_t j = 0; j < n; ++j) f.cls[f.trace[j]] = hit[j] ? kFarRayHit : kFarRayMiss;
    stats.raysCast += counts.rays;
    stats.pixels.rayHit += hits;
    stats.pixels.rayMiss += misses;
    stats.pixels.interpolated += blended;
    stats.stages.add(Stage::Rays, sw.ms());
    if (!f.farDepth.empty())
        for (size_t j = 0; j < n; ++j) f.farDepth[f.trace[j]] = depth[j];
    // The lattice blends its neighbours' unhazed colours, then hazes every entry at its depth; the
    // other casts hazed what they wrote (their time is the stage's).
    if (f.fx->haze && lattice) hazeStage(*f.fx, f.trace.data(), n, depth.data(), f.out, stats);
    else if (f.fx->haze) stats.effects.add(EffectId::Haze, 0.0);
}

}  // namespace vista
