// placeBuildings() and meshBuilding(); see buildings.h for the contract and
// docs/reference/buildings.md for the algorithms and the triangle budget.
#include "citygen/buildings.h"
#include "citygen/labels.h"
#include "foundation/units.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "citygen/building_geometry.h"
#include "citygen/footprint_repair.h"
#include "citygen/mesh_builder.h"
#include "citygen/polygon.h"
#include "foundation/rng.h"
#include "citygen/terrain.h"

namespace vista {

namespace {

constexpr double kMinFootprintArea = 30.0;
constexpr double kMinFootprintWidth = 4.0;
constexpr double kDowntown = 0.65;  // density from which buildings are mid/high-rise
constexpr double kSuburb = 0.35;    // density below which buildings are houses

// Keeps the part of `fp` inside the box centred at c with axes (u, v) and
// half sizes (hu, hv): exact line cuts, so the result stays inside fp.
Polygon2 clipToBox(const Polygon2& fp, const glm::dvec2& c, const glm::dvec2& u, const glm::dvec2& v, double hu,
                   double hv) {
    FlaggedPolygon cur{fp, std::vector<uint8_t>(fp.size(), 1)};
    const glm::dvec2 origins[4] = {c - u * hu, c + u * hu, c - v * hv, c + v * hv};
    const glm::dvec2 dirs[4] = {-v, v, u, -u};  // the kept side is to the left of each line
    for (int k = 0; k < 4; ++k) {
        auto pieces = splitPolygonByLine(cur, origins[k], dirs[k]);
        glm::dvec2 nrm(-dirs[k].y, dirs[k].x);
        FlaggedPolygon best;
        double bestArea = 0;
        for (auto& pc : pieces) {
            glm::dvec2 m = centroid(pc.pts);
            double a = std::abs(signedArea(pc.pts));
            if (glm::dot(m - origins[k], nrm) > 0 && a > bestArea) {
                bestArea = a;
                best = pc;
            }
        }
        if (best.pts.size() < 3) return {};
        cur = std::move(best);
    }
    return cleanPolygon(makeCounterClockwise(cur.pts), 1e-6);
}

// Removes convex vertices whose adjacent edges are both very short (cuts a
// tiny corner off, so the result stays inside the input).
Polygon2 simplifyFootprint(Polygon2 p) {
    p = cleanPolygon(makeCounterClockwise(std::move(p)), 1e-6);
    bool changed = true;
    while (changed && p.size() > 4) {
        changed = false;
        for (size_t i = 0; i < p.size(); ++i) {
            size_t n = p.size();
            const glm::dvec2& a = p[(i + n - 1) % n];
            const glm::dvec2& b = p[i];
            const glm::dvec2& c = p[(i + 1) % n];
            double cr = (b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x);
            if (cr > 0 && (glm::length(b - a) < 0.6 || glm::length(c - b) < 0.6) && 0.5 * cr < 0.5) {
                p.erase(p.begin() + long(i));
                changed = true;
                break;
            }
        }
    }
    return cleanPolygon(p, 1e-6);
}

int chooseFloors(Rng& rng, double density, double width, const CityParams& params) {
    int floors;
    if (density >= kDowntown) {
        // Downtown: mostly 6-20 floors (skewed low), a heavy tail of towers up to max_floors.
        floors = 6 + int(15.0 * std::pow(rng.uniform(), 2.2));
        double towerChance = 0.02 + 0.14 * std::clamp((density - kDowntown) / (1.0 - kDowntown), 0.0, 1.0);
        if (rng.chance(towerChance))
            floors = 20 + int(double(std::max(0, params.max_floors - 20)) * std::pow(rng.uniform(), 1.5) + 0.5);
    } else if (density >= kSuburb) {
        floors = 2 + int(4.0 * std::pow(rng.uniform(), 1.5));  // 2-5
    } else {
        floors = 1 + int(rng.range(0, 2)) * int(rng.range(0, 1)) + int(rng.chance(0.5));  // 1-3, mostly 1-2
        floors = std::min(floors, 3);
    }
    // Slenderness: height at most ~7 times the narrow footprint side.
    int slender = std::max(3, int(7.0 * width / params.floor_height_m));
    floors = std::min(floors, slender);
    return std::clamp(floors, std::max(1, params.min_floors),
                      std::max(std::max(1, params.min_floors), params.max_floors));
}

}  // namespace

std::vector<Building> placeBuildings(const std::vector<Lot>& lots, const std::vector<Block>& blocks,
                                     const CityParams& params, Progress* progress) {
    std::vector<Building> out(lots.size());
    std::vector<uint8_t> ok(lots.size(), 0);
    tbb::parallel_for(size_t(0), lots.size(), [&](size_t li) {
        const Lot& lot = lots[li];
        if (lot.outline.size() < 3) return;
        double density = lot.block < blocks.size()
                             ? std::clamp(blocks[lot.block].density, 0.0, 1.0)
                             : std::clamp(populationDensity(params, centroid(lot.outline)), 0.0, 1.0);
        double setback = std::max(0.3, params.setback_m * (1.5 - density));
        auto insets = insetPolygon(lot.outline, setback);
        if (insets.empty()) return;
        size_t best = 0;
        for (size_t i = 1; i < insets.size(); ++i)
            if (signedArea(insets[i]) > signedArea(insets[best])) best = i;
        Polygon2 fp = simplifyFootprint(insets[best]);
        if (fp.size() < 3 || !isSimplePolygon(fp)) return;
        double area = signedArea(fp);
        OrientedBox box = orientedBox(fp);
        if (!(area >= kMinFootprintArea) || 2.0 * box.halfV < kMinFootprintWidth) return;
        Rng rng(params.seed, stableIdOf(centroid(lot.outline)), Stream::Buildings);
        // Houses and small apartment blocks do not fill big lots: clip to a seeded box.
        double maxU = density < kSuburb     ? rng.uniform(9.0, 16.0)
                      : density < kDowntown ? rng.uniform(18.0, 34.0)
                                            : rng.uniform(30.0, 55.0);
        double maxV = density < kSuburb     ? rng.uniform(8.0, 12.0)
                      : density < kDowntown ? rng.uniform(12.0, 20.0)
                                            : rng.uniform(24.0, 45.0);
        if (box.halfU > 0.5 * maxU || box.halfV > 0.5 * maxV) {
            // The box stands on the lot's longest street edge (front yard = setback), else at the OBB centre.
            glm::dvec2 c = box.centre, u = box.u, v = box.v;
            double hu = std::min(box.halfU, 0.5 * maxU), hv = std::min(box.halfV, 0.5 * maxV);
            if (lot.block < blocks.size() && density < kDowntown) {
                const Polygon2 lo = makeCounterClockwise(lot.outline);
                const Polygon2& bo = blocks[lot.block].outline;
                auto onBlock = [&](const glm::dvec2& q) {
                    for (size_t k = 0; k < bo.size(); ++k)
                        if (pointSegmentDistance(q, bo[k], bo[(k + 1) % bo.size()]) < 1e-6) return true;
                    return false;
                };
                double bestLen = 0;
                for (size_t k = 0; k < lo.size(); ++k) {
                    glm::dvec2 a = lo[k], e = lo[(k + 1) % lo.size()];
                    double l = glm::length(e - a);
                    if (l > bestLen && l > 4.0 && onBlock(a) && onBlock(e) && onBlock(0.5 * (a + e))) {
                        bestLen = l;
                        u = (e - a) / l;
                        v = glm::dvec2(-u.y, u.x);
                        hu = 0.5 * maxU;
                        hv = 0.5 * maxV;
                        c = 0.5 * (a + e) + v * (setback + hv);
                    }
                }
            }
            Polygon2 clipped = clipToBox(fp, c, u, v, hu, hv);
            if (clipped.size() >= 3 && isSimplePolygon(clipped)) {
                fp = simplifyFootprint(clipped);
                area = signedArea(fp);
                box = orientedBox(fp);
                if (fp.size() < 3 || !(area >= kMinFootprintArea) || 2.0 * box.halfV < kMinFootprintWidth) return;
            }
        }
        Building b;
        b.lot = uint32_t(li);
        b.floors = chooseFloors(rng, density, 2.0 * box.halfV, params);
        b.height = b.floors * params.floor_height_m;
        double fill = area / std::max(1e-9, 4.0 * box.halfU * box.halfV);
        bool house = b.floors <= 3 && area <= 350.0 && density < kDowntown;
        if (!house) {
            b.roof = RoofType::Flat;
        } else {
            b.roof = (fill > 0.85 && fp.size() <= 6 && !rng.chance(0.3)) ? RoofType::Gabled : RoofType::Hipped;
            double pitch = rng.uniform(25.0, 40.0) * kPi / 180.0;
            b.roof_height = box.halfV * std::tan(pitch);
        }
        double zmin = 1e300;
        for (const auto& p : fp) zmin = std::min(zmin, terrainHeight(params, p));
        b.base_z = std::isfinite(zmin) ? zmin : 0.0;
        b.footprint = std::move(fp);
        out[li] = std::move(b);
        ok[li] = 1;
    });
    std::vector<Building> res;
    for (size_t i = 0; i < out.size(); ++i)
        if (ok[i]) res.push_back(std::move(out[i]));
    if (progress) progress->update(1.0);
    return res;
}

namespace {

glm::dvec3 at(const glm::dvec2& p, double z) { return {p.x, p.y, z}; }

// Quad whose vertex order is chosen so that its normal points along `want`.
void quadFacing(MeshBuilder& mb, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d,
                const glm::dvec3& want) {
    if (glm::dot(glm::cross(c - a, d - b), want) >= 0) mb.quad(a, b, c, d);
    else mb.quad(d, c, b, a);
}

glm::dvec3 newellNormal(const std::vector<glm::dvec3>& p) {
    glm::dvec3 n(0.0);
    for (size_t i = 0; i < p.size(); ++i) {
        const auto& a = p[i];
        const auto& b = p[(i + 1) % p.size()];
        n.x += (a.y - b.y) * (a.z + b.z);
        n.y += (a.z - b.z) * (a.x + b.x);
        n.z += (a.x - b.x) * (a.y + b.y);
    }
    return n;
}

std::vector<glm::dvec3> dedupe(const std::vector<glm::dvec3>& p) {
    std::vector<glm::dvec3> r;
    for (const auto& q : p)
        if (r.empty() || glm::length(q - r.back()) > 1e-7) r.push_back(q);
    while (r.size() > 1 && glm::length(r.front() - r.back()) <= 1e-7) r.pop_back();
    return r;
}

struct FacadeStyle {
    double floorH, sillH, winH, winW, depth, spacing;
    int detail;
    bool shopfront;  // ground floor with wide, tall shop windows
};

// One facade edge a -> b (footprint counter-clockwise, outside on the right),
// from z0 over `floors` floors. The wall is split into horizontal strips
// between window rows and piers between windows, so together with the recess
// backs it covers the facade exactly once.
void meshFacade(MeshBuilder& wall, MeshBuilder& win, const glm::dvec2& a, const glm::dvec2& b, double z0, int floors,
                const FacadeStyle& s) {
    double len = glm::length(b - a);
    double zTop = z0 + floors * s.floorH;
    if (!(len > 1e-6)) return;
    glm::dvec2 t = (b - a) / len;
    glm::dvec3 n3(t.y, -t.x, 0.0), t3(t.x, t.y, 0.0);
    const double margin = 0.35;
    auto P = [&](double x, double z) { return glm::dvec3(a.x + t.x * x, a.y + t.y * x, z); };
    const glm::dvec3 inward = -n3 * s.depth;
    double prevTop = z0;  // top of the last window row (or the base)
    if (s.detail >= 1 && s.winH > 0) {
        for (int f = 0; f < floors; ++f) {
            const bool shop = f == 0 && s.shopfront;
            double sill = shop ? 0.12 * s.floorH : s.sillH, winH = shop ? 0.7 * s.floorH : s.winH;
            double spacing = shop ? 2.0 * s.spacing : s.spacing, wantW = shop ? 2.2 * s.winW : s.winW;
            if (len < wantW + 2 * margin && !(shop && len >= s.winW + 2 * margin)) continue;
            int nWin = std::max(1, int(std::floor(len / spacing)));
            double bay = len / nWin;
            double ww = std::min(wantW, bay - 2 * margin);
            if (ww <= 0.2) continue;
            double zf = z0 + f * s.floorH, zw0 = zf + sill, zw1 = zw0 + winH;
            wall.quad(P(0, prevTop), P(len, prevTop), P(len, zw0), P(0, zw0));  // strip up to the sills
            prevTop = zw1;
            if (s.detail == 1) {
                win.quad(P(0, zw0), P(len, zw0), P(len, zw1), P(0, zw1));  // window band
                continue;
            }
            double prev = 0;
            for (int k = 0; k < nWin; ++k) {
                double xl = bay * (k + 0.5) - 0.5 * ww, xr = xl + ww;
                wall.quad(P(prev, zw0), P(xl, zw0), P(xl, zw1), P(prev, zw1));  // pier
                prev = xr;
                glm::dvec3 o00 = P(xl, zw0), o10 = P(xr, zw0), o11 = P(xr, zw1), o01 = P(xl, zw1);
                glm::dvec3 i00 = o00 + inward, i10 = o10 + inward, i11 = o11 + inward, i01 = o01 + inward;
                quadFacing(wall, o00, i00, i01, o01, t3);          // left jamb faces +t
                quadFacing(wall, o10, i10, i11, o11, -t3);         // right jamb faces -t
                quadFacing(wall, o00, o10, i10, i00, {0, 0, 1});   // bottom faces up
                quadFacing(wall, o01, o11, i11, i01, {0, 0, -1});  // top faces down
                win.quad(i00, i10, i11, i01);                      // glass at the back
                if (s.detail >= 3 && !shop) {                      // protruding sill ledge under the window
                    const double out = 0.14, th = 0.08, ext = 0.12;
                    glm::dvec3 o = n3 * out;
                    glm::dvec3 l0 = P(xl - ext, zw0 - th), r0 = P(xr + ext, zw0 - th), l1 = P(xl - ext, zw0),
                               r1 = P(xr + ext, zw0);
                    quadFacing(wall, l1, r1, r1 + o, l1 + o, {0, 0, 1});   // top
                    quadFacing(wall, l0 + o, r0 + o, r1 + o, l1 + o, n3);  // front
                    quadFacing(wall, l0, r0, r0 + o, l0 + o, {0, 0, -1});  // bottom
                    quadFacing(wall, l0, l0 + o, l1 + o, l1, -t3);         // left end
                    quadFacing(wall, r0, r0 + o, r1 + o, r1, t3);          // right end
                }
            }
            wall.quad(P(prev, zw0), P(len, zw0), P(len, zw1), P(prev, zw1));  // last pier
        }
    }
    if (prevTop < zTop) wall.quad(P(0, prevTop), P(len, prevTop), P(len, zTop), P(0, zTop));  // top strip / plain wall
}

void flatRoof(MeshBuilder& roof, const Polygon2& fp, double z) {
    std::vector<glm::dvec3> top;
    top.reserve(fp.size());
    for (const auto& p : fp) top.push_back(at(p, z));
    roof.polygon(top, {0, 0, 1});
}

void parapetRoof(MeshBuilder& wall, MeshBuilder& roof, const Polygon2& fp, double z, double h, double thick) {
    Polygon2 inner;
    if (!insetPolygonMiter(fp, std::vector<double>(fp.size(), thick), inner) || inner.size() != fp.size()) {
        flatRoof(roof, fp, z);
        return;
    }
    // Vertex i of the inset must correspond to vertex i of the footprint (no vertex
    // split or merged): check position and edge directions, else no parapet.
    size_t n = fp.size();
    for (size_t i = 0; i < n; ++i) {
        glm::dvec2 e = fp[(i + 1) % n] - fp[i], f = inner[(i + 1) % n] - inner[i];
        if (glm::length(inner[i] - fp[i]) > 4.0 * thick || glm::dot(e, f) <= 0) {
            flatRoof(roof, fp, z);
            return;
        }
    }
    for (size_t i = 0; i < n; ++i) {
        const auto& a = fp[i];
        const auto& b = fp[(i + 1) % n];
        const auto& ia = inner[i];
        const auto& ib = inner[(i + 1) % n];
        wall.quad(at(a, z), at(b, z), at(b, z + h), at(a, z + h));            // outer face
        wall.quad(at(a, z + h), at(b, z + h), at(ib, z + h), at(ia, z + h));  // cap
        wall.quad(at(ib, z), at(ia, z), at(ia, z + h), at(ib, z + h));        // inner face
    }
    flatRoof(roof, inner, z);
}

bool gabledRoof(MeshBuilder& wall, MeshBuilder& roof, const Polygon2& fp, double z, double rh) {
    OrientedBox box = orientedBox(fp);
    if (!(box.halfV > 1e-3) || !(rh > 0)) return false;
    auto h = [&](const glm::dvec2& p) {
        return rh * std::max(0.0, 1.0 - std::abs(glm::dot(p - box.centre, box.v)) / box.halfV);
    };
    FlaggedPolygon whole{fp, std::vector<uint8_t>(fp.size(), 1)};
    auto pieces = splitPolygonByLine(whole, box.centre, box.u);
    if (pieces.size() < 2) return false;
    // Gable walls: every footprint edge up to the roof profile above it.
    size_t n = fp.size();
    for (size_t i = 0; i < n; ++i) {
        const auto& a = fp[i];
        const auto& b = fp[(i + 1) % n];
        double sa = glm::dot(a - box.centre, box.v), sb = glm::dot(b - box.centre, box.v);
        std::vector<glm::dvec3> poly{at(a, z), at(b, z), at(b, z + h(b))};
        if ((sa > 0) != (sb > 0) && std::abs(sa - sb) > 1e-12) {
            glm::dvec2 m = a + (b - a) * (sa / (sa - sb));
            poly.push_back(at(m, z + h(m)));
        }
        poly.push_back(at(a, z + h(a)));
        poly = dedupe(poly);
        if (poly.size() < 3) continue;
        glm::dvec2 t = glm::normalize(b - a);
        wall.polygon(poly, {t.y, -t.x, 0.0});
    }
    for (const auto& pc : pieces) {
        std::vector<glm::dvec3> q;
        Polygon2 pp = makeCounterClockwise(pc.pts);
        for (const auto& p : pp) q.push_back(at(p, z + h(p)));
        q = dedupe(q);
        if (q.size() < 3) continue;
        glm::dvec3 nn = newellNormal(q);
        if (!(nn.z > 0)) continue;
        roof.polygon(q, nn);
    }
    return true;
}

bool hippedRoof(MeshBuilder& roof, const Polygon2& fp, double z, double rh) {
    std::vector<std::vector<glm::dvec3>> faces;
    double maxT = 0;
    if (!hippedRoofFaces(fp, faces, maxT) || !(maxT > 1e-6) || !(rh > 0)) return false;
    double slope = rh / maxT;
    for (auto& f : faces) {
        for (auto& p : f) p.z = z + p.z * slope;
        auto q = dedupe(f);
        if (q.size() < 3) continue;
        glm::dvec3 nn = newellNormal(q);
        if (!(glm::length(nn) > 1e-12)) continue;
        roof.polygon(q, nn);
    }
    return true;
}

// Materials effect: facade and roof albedo by district (population density at
// the footprint) and building type (tower, mid-rise, house; roof shape), drawn
// from a stream of its own so the geometry does not change.
struct BuildingPalette {
    glm::dvec3 wall, roof;
};

BuildingPalette buildingPalette(const Building& b, uint32_t buildingId, const CityParams& params) {
    static const glm::dvec3 kTower[] = {{0.55, 0.55, 0.56}, {0.36, 0.42, 0.50}, {0.70, 0.64, 0.52},
                                        {0.31, 0.33, 0.36}, {0.80, 0.80, 0.78}, {0.47, 0.50, 0.47}};
    static const glm::dvec3 kMid[] = {{0.55, 0.28, 0.20}, {0.45, 0.30, 0.22}, {0.72, 0.58, 0.35},
                                      {0.82, 0.76, 0.62}, {0.62, 0.62, 0.60}, {0.66, 0.45, 0.33}};
    static const glm::dvec3 kHouse[] = {{0.85, 0.78, 0.55}, {0.60, 0.70, 0.78}, {0.86, 0.85, 0.82},
                                        {0.62, 0.68, 0.55}, {0.82, 0.62, 0.52}, {0.78, 0.70, 0.60}};
    static const glm::dvec3 kFlatRoof[] = {
        {0.45, 0.45, 0.43}, {0.20, 0.20, 0.22}, {0.55, 0.54, 0.50}, {0.30, 0.42, 0.22}};
    static const glm::dvec3 kPitchedRoof[] = {
        {0.60, 0.30, 0.22}, {0.28, 0.30, 0.34}, {0.42, 0.28, 0.20}, {0.50, 0.22, 0.18}};
    Rng rng(params.seed, buildingId, uint64_t(0x4D415445ull));  // "MATE"
    const double density = populationDensity(params, centroid(b.footprint));
    // Districts: downtown towers in dense areas; the type follows the floors.
    const bool tower = b.floors >= 10 || (density > 0.6 && b.floors >= 6);
    const bool house = !tower && b.floors <= 3;
    const glm::dvec3* walls = tower ? kTower : (house ? kHouse : kMid);
    glm::dvec3 wall = walls[rng.range(0, 5)] * rng.uniform(0.9, 1.1);
    const bool pitched = b.roof != RoofType::Flat;
    glm::dvec3 roof = pitched ? kPitchedRoof[rng.range(0, 3)] : kFlatRoof[rng.range(0, density > 0.5 ? 2 : 3)];
    roof *= rng.uniform(0.92, 1.08);
    const double v = params.effects.materials->variety;
    const double var = rng.uniform(-0.6, 0.6) * 0.18;
    const glm::dvec3 baseWall = materialAlbedo(Material::Wall) * (1.0 + var),
                     baseRoof = materialAlbedo(Material::Roof) * (1.0 + var);
    return {glm::clamp(baseWall + (wall - baseWall) * v, 0.0, 1.0),
            glm::clamp(baseRoof + (roof - baseRoof) * v, 0.0, 1.0)};
}

}  // namespace

void meshBuilding(const Building& b, uint32_t buildingId, const CityParams& params, const Lighting& light,
                  const glm::dvec3& origin, BuildingMeshes out) {
    VISTA_CHECK(out.walls && out.windows && out.roofs);
    Polygon2 fp = cleanPolygon(makeCounterClockwise(b.footprint), 1e-7);
    if (fp.size() < 3 || !(b.height > 0) || !std::isfinite(b.height) || !std::isfinite(b.base_z)) return;
    if (!isSimplePolygon(fp, 1e-9)) return;  // contract: footprints are simple; bad ones add nothing
    if (!(b.min_height >= 0) || !(b.min_height < b.height)) return;
    std::vector<Polygon2> holes;
    for (const auto& h : b.holes) {
        Polygon2 c = cleanPolygon(h, 1e-7);
        if (c.size() < 3) continue;
        if (signedArea(c) > 0) std::reverse(c.begin(), c.end());
        holes.push_back(std::move(c));
    }
    Rng rng(params.seed, buildingId, Stream::Facades);
    double variation = rng.uniform(-0.6, 0.6);
    MeshBuilder wall(*out.walls, origin, Material::Wall, light, variation);
    MeshBuilder win(*out.windows, origin, Material::Window, light, 0.3 * variation);
    MeshBuilder roof(*out.roofs, origin, Material::Roof, light, variation);
    for (MeshBuilder* mb : {&wall, &win, &roof}) mb->setId(makeInstanceId(InstanceKind::Building, buildingId));
    if (params.effects.materials) {
        const BuildingPalette pal = buildingPalette(b, buildingId, params);
        wall.setAlbedo(pal.wall);
        roof.setAlbedo(pal.roof);
    }
    const int floors = std::max(1, b.floors);
    FacadeStyle s;
    s.floorH = (b.height - b.min_height) / floors;
    s.sillH = 0.3 * s.floorH;
    s.winH = 0.48 * s.floorH;
    s.winW = params.window_width_m * rng.uniform(0.85, 1.2);
    s.shopfront = floors >= 6;
    s.depth = params.window_recess_m;
    s.spacing = std::max(s.winW + 0.8, floors <= 3 ? rng.uniform(3.8, 5.0) : rng.uniform(3.3, 4.3));
    s.detail = params.detail;
    const double z0 = b.base_z + b.min_height, zTop = b.base_z + b.height;
    for (size_t i = 0; i < fp.size(); ++i) meshFacade(wall, win, fp[i], fp[(i + 1) % fp.size()], z0, floors, s);
    // Courtyards: the inner rings run clockwise, so their outside (the courtyard) is on the right as for the outer
    // ring.
    for (const auto& h : holes)
        for (size_t i = 0; i < h.size(); ++i) meshFacade(wall, win, h[i], h[(i + 1) % h.size()], z0, floors, s);
    if (b.min_height > 0) {  // a lifted building (OSM min_height): its underside
        if (holes.empty()) {
            std::vector<glm::dvec3> under;
            for (auto it = fp.rbegin(); it != fp.rend(); ++it) under.push_back(at(*it, z0));
            wall.polygon(under, {0, 0, -1});
        } else {
            for (const auto& t : triangulateWithHoles(fp, holes))
                wall.triangle(at(t[0], z0), at(t[2], z0), at(t[1], z0));
        }
    }
    if (!holes.empty()) {  // flat roof over the polygon with holes (pitched shapes were resolved to flat)
        for (const auto& t : triangulateWithHoles(fp, holes))
            roof.triangle(at(t[0], zTop), at(t[1], zTop), at(t[2], zTop));
        return;
    }
    bool done = false;
    if (b.roof == RoofType::Gabled) done = gabledRoof(wall, roof, fp, zTop, b.roof_height);
    else if (b.roof == RoofType::Hipped) done = hippedRoof(roof, fp, zTop, b.roof_height);
    if (done) return;
    if (params.detail >= 2 && floors >= 4) parapetRoof(wall, roof, fp, zTop, 1.0, 0.35);
    else flatRoof(roof, fp, zTop);
}

}  // namespace vista
