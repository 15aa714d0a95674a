// Baked lighting (baked_lighting.h): shadows, ambient occlusion and street
// light pools into the prelit vertex colours, with refinement where light changes.
#include "bake/gen/baked_lighting.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <optional>
#include <unordered_map>

#include <glm/gtc/matrix_transform.hpp>
#include <tbb/parallel_for.h>

#include "citygen/lighting.h"
#include "citygen/street_lights.h"
#include "foundation/hash.h"
#include "foundation/timing.h"
#include "foundation/units.h"
#include "runtime/engine/ray_scene.h"

namespace vista {
namespace {

constexpr double kGoldenAngle = 2.399963229728653;
constexpr double kLampIntensity = 1.2;
constexpr double kDirectTolerance = 0.12;  // light units (0..1) between neighbouring vertices
constexpr double kAoTolerance = 0.10;      // open-sky share
constexpr double kLampTolerance = 0.10;
constexpr double kLampResolution = 2.0;  // metres
constexpr double kProbeFactor = 4.0;     // edges longer than 4x the resolution probe their midpoint
constexpr size_t kMaxGrowth = 64;        // a mesh never grows past 64x its triangles (+ 4096)
const glm::dvec3 kLampColour(1.0, 0.84, 0.62);

struct Sample {
    float direct = 0;   // sun visibility x max(0, n.s): 0..1
    float open = 1;     // ambient factor after occlusion: 0..1
    glm::vec3 lamp{0};  // street-light light (linear RGB)
    float lampLum() const { return (lamp.x + lamp.y + lamp.z) / 3.0f; }
};

uint64_t pointHash(const glm::dvec3& p) {
    auto q = [](double v) { return uint64_t(int64_t(std::llround(v * 1000.0))); };
    return hashKeys(q(p.x), q(p.y), q(p.z));
}

double unit01(uint64_t h) { return double(h >> 11) * (1.0 / 9007199254740992.0); }

void basis(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b) {
    t = std::abs(n.z) < 0.9 ? glm::normalize(glm::cross(glm::dvec3(0, 0, 1), n))
                            : glm::normalize(glm::cross(glm::dvec3(1, 0, 0), n));
    b = glm::cross(n, t);
}

struct Context {
    const RayScene& rays;
    const glm::dvec3 frame;  // ray-scene frame origin (city frame): 0
    Lighting light;
    std::optional<SunShadowsEffect> shadows;
    std::optional<AmbientOcclusionEffect> ao;
    std::optional<NightEffect> night;
    glm::dvec3 su{0}, sv{0};
    double tanR = 0;
    const std::vector<glm::dvec3>* lamps = nullptr;
    std::unordered_map<uint64_t, std::vector<uint32_t>> lampCells;
    double lampCell = 1;
    std::atomic<uint64_t> rayCount{0};

    Context(const RayScene& r, const CityParams& p, const std::vector<glm::dvec3>& lampList)
        : rays(r),
          frame(0.0),
          light(p),
          shadows(p.effects.sun_shadows),
          ao(p.effects.ambient_occlusion),
          night(p.effects.night),
          lamps(&lampList) {
        basis(light.sunDir, su, sv);
        if (shadows) tanR = std::tan(0.5 * degToRad(shadows->softness_deg));
        if (night && !lampList.empty()) {
            lampCell = night->light_radius_m;
            for (uint32_t i = 0; i < lampList.size(); ++i) lampCells[cellKey(lampList[i])].push_back(i);
        }
        if (light.sun <= 0) shadows.reset();  // night: no sun, nothing to shadow
    }
    uint64_t cellKey(const glm::dvec3& p) const {
        return hashKeys(uint64_t(int64_t(std::floor(p.x / lampCell))), uint64_t(int64_t(std::floor(p.y / lampCell))),
                        0x1A3Bull);
    }
    uint64_t cellKey(int64_t x, int64_t y) const { return hashKeys(uint64_t(x), uint64_t(y), 0x1A3Bull); }

    Sample evaluate(const glm::dvec3& p, const glm::dvec3& n) {
        Sample s;
        const uint64_t h = pointHash(p);
        const double rot = unit01(h) * 2.0 * kPi;
        const glm::vec3 org(p + n * (0.02 + 1e-6 * glm::length(p)));
        uint64_t cast = 0;
        const double cosS = glm::dot(n, light.sunDir);
        if (light.sun > 0 && cosS > 0) {
            if (shadows) {
                int lit = 0;
                const int N = shadows->samples;
                int tried = 0;
                for (int i = 0; i < N; ++i) {
                    // Four samples that agree (all lit or all blocked) stand for the rest.
                    if (i == 4 && (lit == 0 || lit == tried)) {
                        lit = lit == 0 ? 0 : N;
                        tried = N;
                        break;
                    }
                    ++tried;
                    const double r = N == 1 ? 0.0 : std::sqrt((i + 0.5) / N), th = i * kGoldenAngle + rot;
                    const glm::dvec3 d =
                        glm::normalize(light.sunDir + tanR * r * (std::cos(th) * su + std::sin(th) * sv));
                    if (glm::dot(d, n) <= 0) continue;  // below the surface: self-shadowed
                    ++cast;
                    if (!rays.occluded(org, glm::vec3(d), 0.0f, 1e30f)) ++lit;
                }
                s.direct = float(cosS * lit / N);
            } else {
                s.direct = float(cosS);
            }
        }
        if (ao) {
            glm::dvec3 t, b;
            basis(n, t, b);
            const int N = ao->samples;
            int blocked = 0;
            for (int i = 0; i < N; ++i) {
                const double u1 = (i + 0.5) / N, r = std::sqrt(u1), ph = i * kGoldenAngle + rot;
                const glm::dvec3 d = r * std::cos(ph) * t + r * std::sin(ph) * b + std::sqrt(1.0 - u1) * n;
                ++cast;
                if (rays.occluded(org, glm::vec3(glm::normalize(d)), 0.0f, float(ao->radius_m))) ++blocked;
            }
            s.open = float(1.0 - ao->strength * double(blocked) / N);
        }
        if (night && !lampCells.empty()) {
            const double R = night->light_radius_m;
            const int64_t cx = int64_t(std::floor(p.x / lampCell)), cy = int64_t(std::floor(p.y / lampCell));
            glm::dvec3 sum(0.0);
            for (int64_t dy = -1; dy <= 1; ++dy)
                for (int64_t dx = -1; dx <= 1; ++dx) {
                    auto it = lampCells.find(cellKey(cx + dx, cy + dy));
                    if (it == lampCells.end()) continue;
                    for (uint32_t li : it->second) {
                        const glm::dvec3 q = (*lamps)[li] + glm::dvec3(0, 0, kStreetLightHeight);
                        const glm::dvec3 v = q - p;
                        const double d = glm::length(v);
                        if (!(d < R) || d < 1e-6) continue;
                        const double w = (1 - (d / R) * (d / R)), lambert = std::max(0.0, glm::dot(n, v / d));
                        sum += kLampIntensity * w * w * lambert * kLampColour;
                    }
                }
            s.lamp = glm::vec3(sum);
        }
        rayCount += cast;
        return s;
    }
};

struct Vert {
    glm::dvec3 p;  // city frame
    glm::vec3 n;
    glm::u8vec4 c;
    Sample s;
    uint32_t id = 0;  // ground-truth label (citygen/labels.h), kept by refinement
};

struct Refine {
    double direct = 1e300, ao = 1e300, lamp = 1e300;  // resolution (edge length) per criterion
    double coarse = 1e300;
    // Occlusion is estimated from `samples` rays: two neighbours differ by
    // about 0.7 strength / sqrt(samples) from sampling noise alone, so the
    // tolerance is twice that (never below kAoTolerance): refinement follows
    // occlusion, not its noise.
    double aoTolerance = kAoTolerance;
};

uint64_t edgeKey(const Vert& a, const Vert& b) {
    uint64_t ka = pointHash(a.p) ^ (uint64_t(a.c.x) << 8 | uint64_t(a.c.y) << 16 | uint64_t(a.c.z) << 24);
    uint64_t kb = pointHash(b.p) ^ (uint64_t(b.c.x) << 8 | uint64_t(b.c.y) << 16 | uint64_t(b.c.z) << 24);
    auto qn = [](float v) { return uint64_t(int64_t(std::lround(v * 1000.0f))); };
    // Entities never share a midpoint (labels stay exact); id 0 leaves the key as it was.
    const uint64_t h = hashKeys(std::min(ka, kb), std::max(ka, kb), hashKeys(qn(a.n.x), qn(a.n.y), qn(a.n.z)));
    return a.id == 0 ? h : hashKeys(h, uint64_t(a.id), 0x1abe1ull);
}

// Refines `mesh` (positions relative to origin) where light changes, then relights every vertex.
void refineAndRelight(Mesh& mesh, const glm::dvec3& origin, const Refine& rf, Context& ctx) {
    if (mesh.empty()) return;
    std::vector<Vert> vs(mesh.positions.size());
    for (size_t i = 0; i < vs.size(); ++i) {
        vs[i].p = origin + glm::dvec3(mesh.positions[i]);
        vs[i].n = mesh.normals.size() == vs.size() ? mesh.normals[i] : glm::vec3(0, 0, 1);
        vs[i].c = mesh.colors[i];
        vs[i].id = mesh.ids.size() == vs.size() ? mesh.ids[i] : 0u;
        vs[i].s = ctx.evaluate(vs[i].p, glm::dvec3(vs[i].n));
    }
    std::vector<uint32_t> idx = mesh.indices;
    const size_t cap = idx.size() / 3 * kMaxGrowth + 4096;
    const double minRes = std::min({rf.direct, rf.ao, rf.lamp});
    constexpr uint32_t kNone = 0xFFFFFFFFu;
    for (int level = 0; level < 16 && minRes < 1e300; ++level) {
        std::unordered_map<uint64_t, uint32_t> mids;
        // The decision for an edge is made at its first lookup and cached by
        // its key, so neighbours sharing the edge split it alike (no cracks).
        // forced: the asking triangle is large and this is its longest edge.
        auto mid = [&](uint32_t a, uint32_t b, bool forced) -> uint32_t {
            const double len = glm::length(vs[a].p - vs[b].p);
            if (!(len > minRes)) return kNone;
            const uint64_t key = edgeKey(vs[a], vs[b]);
            auto it = mids.find(key);
            if (it != mids.end()) return it->second;
            const Sample &sa = vs[a].s, &sb = vs[b].s;
            const bool endsDiffer = (len > rf.direct && std::abs(sa.direct - sb.direct) > kDirectTolerance) ||
                                    (len > rf.ao && std::abs(sa.open - sb.open) > rf.aoTolerance) ||
                                    (len > rf.lamp && std::abs(sa.lampLum() - sb.lampLum()) > kLampTolerance);
            // Probe the midpoint only on long edges whose ends agree (a feature between them).
            const bool probe = !forced && !endsDiffer && len > kProbeFactor * minRes;
            if (!forced && !endsDiffer && !probe) {
                mids.emplace(key, kNone);
                return kNone;
            }
            Vert m;
            m.p = 0.5 * (vs[a].p + vs[b].p);
            m.n = vs[a].n;
            m.id = vs[a].id;
            m.c = glm::u8vec4((glm::uvec4(vs[a].c) + glm::uvec4(vs[b].c) + 1u) / 2u);
            m.s = ctx.evaluate(m.p, glm::dvec3(m.n));
            auto bent = [](double x, double y, double z, double tol) { return std::abs(z - 0.5 * (x + y)) > tol; };
            const bool split = forced || endsDiffer ||
                               (len > rf.direct && bent(sa.direct, sb.direct, m.s.direct, kDirectTolerance)) ||
                               (len > rf.ao && bent(sa.open, sb.open, m.s.open, rf.aoTolerance)) ||
                               (len > rf.lamp && bent(sa.lampLum(), sb.lampLum(), m.s.lampLum(), kLampTolerance));
            uint32_t r = kNone;
            if (split) {
                r = uint32_t(vs.size());
                vs.push_back(m);
            }
            mids.emplace(key, r);
            return r;
        };
        std::vector<uint32_t> out;
        out.reserve(idx.size() * 2);
        bool any = false;
        for (size_t t = 0; t + 2 < idx.size(); t += 3) {
            uint32_t v[3] = {idx[t], idx[t + 1], idx[t + 2]};
            double len[3];
            for (int e = 0; e < 3; ++e) len[e] = glm::length(vs[v[e]].p - vs[v[(e + 1) % 3]].p);
            const int longest = len[0] >= len[1] && len[0] >= len[2] ? 0 : (len[1] >= len[2] ? 1 : 2);
            const double area = 0.5 * glm::length(glm::cross(vs[v[1]].p - vs[v[0]].p, vs[v[2]].p - vs[v[0]].p));
            const bool big = area > 0.5 * rf.coarse * rf.coarse;
            uint32_t m[3];
            for (int e = 0; e < 3; ++e) m[e] = mid(v[e], v[(e + 1) % 3], big && e == longest);
            const int n = (m[0] != kNone) + (m[1] != kNone) + (m[2] != kNone);
            if (n == 0) {
                out.insert(out.end(), v, v + 3);
                continue;
            }
            any = true;
            if (n == 3) {
                out.insert(out.end(), {v[0], m[0], m[2], m[0], v[1], m[1], m[2], m[1], v[2], m[0], m[1], m[2]});
                continue;
            }
            // Rotate so that edge 0 (v0-v1) is split and, for two splits, edge 1 too.
            int r = 0;
            if (n == 1) r = m[0] != kNone ? 0 : (m[1] != kNone ? 1 : 2);
            else r = m[2] == kNone ? 0 : (m[0] == kNone ? 1 : 2);
            const uint32_t a = v[r], b = v[(r + 1) % 3], c = v[(r + 2) % 3], mab = m[r], mbc = m[(r + 1) % 3];
            if (n == 1) out.insert(out.end(), {a, mab, c, mab, b, c});
            else out.insert(out.end(), {mab, b, mbc, a, mab, mbc, a, mbc, c});
        }
        idx.swap(out);
        if (!any || idx.size() / 3 > cap) break;
    }
    // Relight: scale each colour by (new light) / (light it was prelit with).
    mesh.positions.resize(vs.size());
    mesh.normals.resize(vs.size());
    mesh.colors.resize(vs.size());
    const bool tagged = !mesh.ids.empty();
    if (tagged) mesh.ids.resize(vs.size());
    const Lighting& L = ctx.light;
    for (size_t i = 0; i < vs.size(); ++i) {
        const Vert& v = vs[i];
        mesh.positions[i] = glm::vec3(v.p - origin);
        mesh.normals[i] = v.n;
        if (tagged) mesh.ids[i] = v.id;
        const double l0 = lightLevel(glm::dvec3(v.n), L);
        const double l = L.ambient * v.s.open + (1.0 - L.ambient) * L.sun * v.s.direct;
        glm::u8vec4 c = v.c;
        for (int k = 0; k < 3; ++k) {
            const double f = l0 > 1e-9 ? (l + v.s.lamp[k]) / l0 : 1.0;
            c[k] = encodeSrgb(decodeSrgb(v.c[k]) * f);
        }
        mesh.colors[i] = c;
    }
    mesh.indices.swap(idx);
}

TriangleSoup occluders(const City& city) {
    TriangleSoup soup;
    auto add = [&](const Mesh& m, const glm::dmat4& xf) {
        const uint32_t base = uint32_t(soup.positions.size());
        for (const auto& p : m.positions) soup.positions.push_back(glm::vec3(xf * glm::dvec4(glm::dvec3(p), 1.0)));
        soup.colors.resize(soup.positions.size(), glm::u8vec4(255));
        for (uint32_t i : m.indices) soup.indices.push_back(base + i);
    };
    for (const Tile& t : city.tiles)
        for (const Mesh& m : t.meshes) add(m, glm::translate(glm::dmat4(1.0), t.origin));
    for (const TreeInstance& tr : city.trees) {
        if (tr.prototype >= city.treePrototypes.size()) continue;
        glm::dmat4 m = glm::translate(glm::dmat4(1.0), tr.position);
        m = glm::rotate(m, double(tr.yaw), glm::dvec3(0, 0, 1));
        m = glm::scale(m, glm::dvec3(double(tr.scale)));
        add(city.treePrototypes[tr.prototype].mesh, m);
    }
    return soup;
}

}  // namespace

bool bakedLightingCalledFor(const CityParams& p) {
    const Effects& e = p.effects;
    const bool lamps = e.night && e.night->street_light_spacing_m > 0;
    return (e.sun_shadows && !e.night) || e.ambient_occlusion || lamps;
}

Status bakeLighting(City& city, Progress* progress, BakedLightingStats& stats) {
    stats = BakedLightingStats();
    if (!bakedLightingCalledFor(city.params)) return Status::ok();
    Stopwatch sw;
    for (const Tile& t : city.tiles)
        for (const Mesh& m : t.meshes) stats.trianglesBefore += m.triangleCount();
    std::unique_ptr<RayScene> scene;
    {
        TriangleSoup soup = occluders(city);
        SoupSceneOptions o;
        o.quality = RayBuildQuality::Medium;
        o.cullBackFaces = false;
        auto r = RayScene::build(soup, o);
        if (!r) return Status::error("baked lighting: " + r.status().message());
        scene = std::move(*r);
    }
    stats.sceneSeconds = sw.ms() / 1000.0;
    Context ctx(*scene, city.params, city.streetLights);
    Refine rf;
    if (ctx.shadows) rf.direct = ctx.shadows->resolution_m;
    if (ctx.ao) {
        rf.ao = ctx.ao->resolution_m;
        rf.aoTolerance = std::max(kAoTolerance, 1.4 * ctx.ao->strength / std::sqrt(double(ctx.ao->samples)));
    }
    if (ctx.night && !city.streetLights.empty()) rf.lamp = kLampResolution;
    rf.coarse = std::max(4.0, 8.0 * std::min({rf.direct, rf.ao, rf.lamp}));

    // One task per (tile, relit material).
    std::vector<std::pair<size_t, int>> tasks;
    for (size_t t = 0; t < city.tiles.size(); ++t)
        for (int m = 0; m < kMaterialCount; ++m) {
            const Material mat = Material(m);
            // Small fixtures and parked cars keep their prelit colours (they still cast shadows: occluders()).
            if (mat == Material::Lamp || mat == Material::TrafficLight || mat == Material::TrafficSign ||
                mat == Material::Car)
                continue;
            if (mat == Material::Trunk || mat == Material::Leaves) continue;
            if (mat == Material::Window && ctx.night) continue;
            if (!city.tiles[t].meshes[size_t(m)].empty()) tasks.emplace_back(t, m);
        }
    std::atomic<size_t> done{0};
    std::mutex pm;
    tbb::parallel_for(size_t(0), tasks.size(), [&](size_t k) {
        Tile& tile = city.tiles[tasks[k].first];
        refineAndRelight(tile.meshes[size_t(tasks[k].second)], tile.origin, rf, ctx);
        const size_t d = ++done;
        if (progress) {
            std::lock_guard<std::mutex> lock(pm);
            progress->update(double(d) / double(tasks.size()));
        }
    });
    for (const Tile& t : city.tiles)
        for (const Mesh& m : t.meshes) stats.trianglesAfter += m.triangleCount();
    stats.rays = ctx.rayCount.load();
    stats.ran = true;
    stats.seconds = sw.ms() / 1000.0;
    return Status::ok();
}

}  // namespace vista
