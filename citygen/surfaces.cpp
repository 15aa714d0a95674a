// Ground, roads, markings and sidewalks of one tile. See surfaces.h for the
// contract and docs/reference/trees-and-surfaces.md for the assignment rules.
//
// Exactly-once assignment: a road piece (<= 50 m) belongs to the tile of its
// midpoint, a junction polygon to the tile of its node, a sidewalk segment to
// the tile of its midpoint (all through TileGrid::tileOf, which clamps outside
// positions to the border tiles), a park polygon is clipped to the tile
// rectangle. The ground grid covers the tile rectangle.
#include "citygen/surfaces.h"
#include "foundation/units.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "citygen/labels.h"
#include "citygen/lanes.h"
#include "citygen/polygon.h"
#include "citygen/terrain.h"

namespace vista {

namespace {

constexpr double kRoadLift = 0.02;       // carriageway above ground
constexpr double kJunctionLift = 0.025;  // junction polygons above the carriageways they overlap
constexpr double kMarkingLift = 0.03;    // markings above ground
constexpr double kGrassLift = 0.05;      // park lawn above ground
constexpr double kSidewalkLift = 0.12;   // sidewalk top above ground
constexpr double kMaxPiece = 50.0;       // longest road piece
constexpr double kMinArea = 1e-6;        // smallest triangle emitted (m^2)
// Markings (metres): line width, dashes, stop lines, zebra crossings.
constexpr double kLineWidth = 0.15;  // as the OpenDRIVE road marks
constexpr double kDashPeriod = 9.0, kDash = 3.0;
constexpr double kZebraStripe = 0.5, kZebraGap = 0.6;

bool finitePolygon(const Polygon2& p) {
    for (const auto& q : p)
        if (!std::isfinite(q.x) || !std::isfinite(q.y)) return false;
    return true;
}

struct Rect {
    double x0, y0, x1, y1;
    bool overlaps(const glm::dvec2& lo, const glm::dvec2& hi) const {
        return hi.x >= x0 && lo.x <= x1 && hi.y >= y0 && lo.y <= y1;
    }
};

class SurfaceContext {
public:
    SurfaceContext(const City& city, const TileGrid& grid, int tile, const Lighting& light, Tile& out,
                   const SurfaceIndex* index)
        : P(city.params), city(city), grid(grid), tile(tile), out(out), light(light) {
        if (index) {
            edgeList = &index->edges[size_t(tile)];
            blockList = &index->blocks[size_t(tile)];
            parkList = &index->parks[size_t(tile)];
            lanes = &index->lanes;
        } else {
            ownLanes = buildLaneModel(city.streets, city.params, &city.blocks);
            lanes = &ownLanes;
        }
        const double T = P.tile_size_m, half = 0.5 * P.size_m;
        glm::dvec3 o = grid.origin(tile);
        rect = {o.x, o.y, std::min(o.x + T, half), std::min(o.y + T, half)};
        const double inf = std::numeric_limits<double>::infinity();
        // Region whose points tileOf() maps to this tile (border tiles extend outwards).
        claim = {grid.ix(tile) == 0 ? -inf : o.x, grid.iy(tile) == 0 ? -inf : o.y,
                 grid.ix(tile) == grid.countX() - 1 ? inf : o.x + T,
                 grid.iy(tile) == grid.countY() - 1 ? inf : o.y + T};
        flat = !(P.hills_amplitude_m > 0);
        // Chord error of a piecewise-linear surface over a cell of side s is
        // about k s^2 / 4 with curvature k <= 25 A / lambda^2 (value noise with
        // smoothstep, two octaves); aim at ~1 cm, cells between 8 and 25 m.
        step = 25.0;
        if (!flat) {
            double k = 25.0 * P.hills_amplitude_m / (P.hills_wavelength_m * P.hills_wavelength_m);
            step = std::clamp(std::sqrt(0.04 / std::max(k, 1e-12)), 8.0, 25.0);
        }
    }

    double ground(const glm::dvec2& p) const { return flat ? 0.0 : terrainHeight(P, p); }
    glm::dvec3 at(const glm::dvec2& p, double lift) const { return {p, ground(p) + lift}; }
    bool mine(const glm::dvec2& p) const { return grid.tileOf(p) == tile; }
    Mesh& mesh(Material m) { return out.meshes[size_t(m)]; }

    // Emits a triangle if its area is not negligible; orientation as given.
    static void tri(MeshBuilder& b, const glm::dvec3& a, const glm::dvec3& c1, const glm::dvec3& c2) {
        if (!(glm::length(glm::cross(c1 - a, c2 - a)) > 2 * kMinArea)) return;
        b.triangle(a, c1, c2);
    }
    // A junction fan triangle at kJunctionLift, split on hills into sub-triangles no longer than
    // `step` (the carriageways' sampling), so that it follows the ground as closely as they do and
    // stays above them where the two overlap.
    void fanTriangle(MeshBuilder& b, const glm::dvec2& c, const glm::dvec2& p, const glm::dvec2& q) const {
        const double longest = std::max({glm::length(p - c), glm::length(q - c), glm::length(q - p)});
        const int n = flat ? 1 : std::max(1, int(std::ceil(longest / step)));
        auto P = [&](int i, int j) {
            return at(c + (p - c) * (double(i) / n) + (q - c) * (double(j) / n), kJunctionLift);
        };
        for (int i = 0; i < n; ++i)
            for (int j = 0; i + j < n; ++j) {
                tri(b, P(i, j), P(i + 1, j), P(i, j + 1));
                if (i + j < n - 1) tri(b, P(i + 1, j), P(i + 1, j + 1), P(i, j + 1));
            }
    }
    static void quad(MeshBuilder& b, const glm::dvec3& a, const glm::dvec3& c1, const glm::dvec3& c2,
                     const glm::dvec3& c3) {
        tri(b, a, c1, c2);
        tri(b, a, c2, c3);
    }

    void groundMesh();
    void edgeMarkings(MeshBuilder& mark, size_t e, const glm::dvec2& A, const glm::dvec2& d, double L, int pieces);
    void parks();
    void roads();
    // Draws the carriageway and markings of every edge this tile claims;
    // collects (node of this tile, incident edge) pairs for the junctions.
    void carriageways(MeshBuilder& road, MeshBuilder& mark, std::vector<std::pair<uint32_t, uint32_t>>& nodeEdges);
    // The points whose convex hull is the junction polygon of `node`, from its
    // incident edges nodeEdges[i, j): carriageway corners, a dead end's round
    // cap, and where consecutive edges' carriageway borders meet.
    Polygon2 junctionPoints(uint32_t node, const std::vector<std::pair<uint32_t, uint32_t>>& nodeEdges, size_t i,
                            size_t j) const;
    // Adds the carriageway of the lane model's link roads at `node` (junction
    // turns, degree-2 transitions): samples of their outer driving-lane borders.
    void linkRoadBorders(uint32_t node, Polygon2& pts) const;
    void sidewalks();

    const CityParams& P;
    const City& city;
    const TileGrid& grid;
    int tile;
    Tile& out;
    const Lighting& light;
    Rect rect{}, claim{};
    // Candidate lists from a SurfaceIndex (null: scan everything).
    const std::vector<uint32_t>* edgeList = nullptr;
    const std::vector<uint32_t>* blockList = nullptr;
    const std::vector<uint32_t>* parkList = nullptr;
    const LaneModel* lanes = nullptr;  // the index's, or ownLanes
    LaneModel ownLanes;
    template <class F>
    void forEach(const std::vector<uint32_t>* list, size_t n, F f) const {
        if (list) {
            for (uint32_t i : *list)
                if (i < n) f(size_t(i));
        } else {
            for (size_t i = 0; i < n; ++i) f(i);
        }
    }
    bool flat = true;
    double step = 25.0;
};

void SurfaceContext::groundMesh() {
    MeshBuilder b(mesh(Material::Ground), out.origin, Material::Ground, light);
    double w = rect.x1 - rect.x0, h = rect.y1 - rect.y0;
    if (!(w > 1e-6 && h > 1e-6)) return;
    int nx = flat ? 1 : std::max(1, int(std::ceil(w / step))), ny = flat ? 1 : std::max(1, int(std::ceil(h / step)));
    for (int j = 0; j < ny; ++j) {
        for (int i = 0; i < nx; ++i) {
            glm::dvec2 a(rect.x0 + w * i / nx, rect.y0 + h * j / ny),
                c(rect.x0 + w * (i + 1) / nx, rect.y0 + h * (j + 1) / ny);
            quad(b, at(a, 0), at({c.x, a.y}, 0), at(c, 0), at({a.x, c.y}, 0));
        }
    }
}

// Sutherland-Hodgman clip of a polygon to an axis-aligned rectangle.
Polygon2 clipToRect(const Polygon2& poly, const Rect& r) {
    Polygon2 cur = poly;
    for (int edge = 0; edge < 4 && !cur.empty(); ++edge) {
        auto inside = [&](const glm::dvec2& p) {
            switch (edge) {
                case 0: return p.x >= r.x0;
                case 1: return p.x <= r.x1;
                case 2: return p.y >= r.y0;
                default: return p.y <= r.y1;
            }
        };
        auto cut = [&](const glm::dvec2& a, const glm::dvec2& b) {
            double t;
            switch (edge) {
                case 0: t = (r.x0 - a.x) / (b.x - a.x); break;
                case 1: t = (r.x1 - a.x) / (b.x - a.x); break;
                case 2: t = (r.y0 - a.y) / (b.y - a.y); break;
                default: t = (r.y1 - a.y) / (b.y - a.y); break;
            }
            glm::dvec2 p = a + (b - a) * std::clamp(t, 0.0, 1.0);
            // Snap exactly onto the clip line.
            if (edge == 0) p.x = r.x0;
            else if (edge == 1) p.x = r.x1;
            else if (edge == 2) p.y = r.y0;
            else p.y = r.y1;
            return p;
        };
        Polygon2 next;
        for (size_t i = 0, n = cur.size(); i < n; ++i) {
            const glm::dvec2& a = cur[i];
            const glm::dvec2& b = cur[(i + 1) % n];
            bool ia = inside(a), ib = inside(b);
            if (ia) next.push_back(a);
            if (ia != ib) next.push_back(cut(a, b));
        }
        cur = std::move(next);
    }
    return cur;
}

void SurfaceContext::parks() {
    // Each park is ear-clipped as a whole; every triangle is clipped to the
    // tile rectangle (and, with hills, to the ground cells), which is convex,
    // so each piece is a convex polygon drawn as a fan. Tiles partition the
    // city, so every part of a park is drawn exactly once.
    MeshBuilder b(mesh(Material::Grass), out.origin, Material::Grass, light);
    std::vector<Rect> cells;
    if (flat) {
        cells.push_back(rect);
    } else {
        double w = rect.x1 - rect.x0, h = rect.y1 - rect.y0;
        int nx = std::max(1, int(std::ceil(w / step))), ny = std::max(1, int(std::ceil(h / step)));
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                cells.push_back({rect.x0 + w * i / nx, rect.y0 + h * j / ny, rect.x0 + w * (i + 1) / nx,
                                 rect.y0 + h * (j + 1) / ny});
    }
    forEach(parkList, city.blocks.size(), [&](size_t bi) {
        const Block& blk = city.blocks[bi];
        if (!blk.park || blk.outline.size() < 3 || !finitePolygon(blk.outline)) return;
        b.setId(makeInstanceId(InstanceKind::Park, bi));
        glm::dvec2 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
        for (const auto& q : blk.outline) lo = glm::min(lo, q), hi = glm::max(hi, q);
        if (!rect.overlaps(lo, hi)) return;
        Polygon2 poly = cleanPolygon(blk.outline, 1e-7);
        if (poly.size() < 3) return;
        auto tris = triangulate(poly);
        for (size_t t = 0; t + 2 < tris.size(); t += 3) {
            Polygon2 tr{poly[tris[t]], poly[tris[t + 1]], poly[tris[t + 2]]};
            glm::dvec2 tlo = glm::min(glm::min(tr[0], tr[1]), tr[2]), thi = glm::max(glm::max(tr[0], tr[1]), tr[2]);
            if (!rect.overlaps(tlo, thi)) continue;
            for (const Rect& c : cells) {
                if (!c.overlaps(tlo, thi)) continue;
                Polygon2 piece = clipToRect(tr, c);
                for (size_t k = 1; k + 1 < piece.size(); ++k)
                    tri(b, at(piece[0], kGrassLift), at(piece[k], kGrassLift), at(piece[k + 1], kGrassLift));
            }
        }
    });
}

double safeWidth(const StreetEdge& e) { return carriagewayWidth(e); }

// Lane markings of edge e from the lane model (lanes.h), in the frame of its
// trimmed reference line (s along it from L.start, t to the left): centre
// line at the centre lane (double solid on highways, solid on arterials,
// dashed on local streets), dashed dividers between lanes of one direction,
// and at every junction end a stop line across the incoming lanes and a
// zebra crossing between the stop line and the junction, where the
// sidewalks of the neighbouring streets meet. Every marking piece belongs to
// the road piece (<= kMaxPiece, same split as the carriageway) it lies on,
// so it is drawn by exactly one tile: the one that draws that road piece.
void SurfaceContext::edgeMarkings(MeshBuilder& mark, size_t e, const glm::dvec2& A, const glm::dvec2& d, double L,
                                  int pieces) {
    if (!lanes || e >= lanes->edges.size()) return;
    const EdgeLanes& ln = lanes->edges[e];
    if (!ln.valid) return;
    const StreetEdge& E = city.streets.edges[e];
    const glm::dvec2 n(-d.y, d.x);
    const double pieceLen = L / pieces;
    // The tile of the road piece at distance u from node a.
    auto ownsAt = [&](double u) {
        int k = std::clamp(int(std::floor(u / pieceLen)), 0, pieces - 1);
        return mine(A + d * ((k + 0.5) * pieceLen));
    };
    auto point = [&](double s, double t) { return A + d * (ln.trimA + s) + n * t; };
    // A quad from s0 to s1 (reference line s) and t0 to t1, drawn by the
    // owner of its middle; subdivided along s to follow the terrain.
    auto rect = [&](double s0, double s1, double t0, double t1) {
        if (!(s1 - s0 > 0.02) || !ownsAt(ln.trimA + 0.5 * (s0 + s1))) return;
        int sub = flat ? 1 : std::max(1, int(std::ceil((s1 - s0) / step)));
        for (int k = 0; k < sub; ++k) {
            double a0 = s0 + (s1 - s0) * k / sub, a1 = s0 + (s1 - s0) * (k + 1) / sub;
            quad(mark, at(point(a0, t0), kMarkingLift), at(point(a1, t0), kMarkingLift),
                 at(point(a1, t1), kMarkingLift), at(point(a0, t1), kMarkingLift));
        }
    };
    // A line of half width hw at lateral t from s0 to s1, cut at the road pieces.
    auto strip = [&](double s0, double s1, double t, double hw) {
        for (int k = 0; k < pieces; ++k) {
            double a = std::max(s0, k * pieceLen - ln.trimA), b = std::min(s1, (k + 1) * pieceLen - ln.trimA);
            if (b > a) rect(a, b, t - hw, t + hw);
        }
    };
    auto dashed = [&](double s0, double s1, double t, double hw) {
        for (double k0 = std::floor(s0 / kDashPeriod) * kDashPeriod; k0 < s1; k0 += kDashPeriod) {
            double a = std::max(k0, s0), b = std::min(k0 + kDash, s1);
            if (b - a > 0.3) strip(a, b, t, hw);
        }
    };
    const double Lr = ln.length, lw = ln.laneWidth, off = ln.offset, hw = ln.halfWidth();
    const double lineHw = 0.5 * kLineWidth;
    const bool jA = stopLine(ln, false), jB = stopLine(ln, true);
    const auto& deg = lanes->degree;
    // Lines stop behind the stop lines at junctions and short of a dead end's cap.
    double s0 = jA ? kStopSetback + kStopDepth : (deg[E.a] == 1 ? hw : 0.0);
    double s1 = Lr - (jB ? kStopSetback + kStopDepth : (deg[E.b] == 1 ? hw : 0.0));
    if (s1 > s0) {
        if (E.cls == RoadClass::Highway) {
            strip(s0, s1, off - 0.15, lineHw);
            strip(s0, s1, off + 0.15, lineHw);
        } else if (E.cls == RoadClass::Arterial) {
            strip(s0, s1, off, lineHw);
        } else {
            dashed(s0, s1, off, lineHw);
        }
        for (int k = 1; k < ln.right; ++k) dashed(s0, s1, off - k * lw, lineHw);
        for (int k = 1; k < ln.left; ++k) dashed(s0, s1, off + k * lw, lineHw);
    }
    // Stop lines at junction ends and the crossings the lane model places
    // there (crossingBand).
    auto zebra = [&](double sNear, double sFar) {  // s range of the crossing band
        const int stripes = std::max(1, int(std::floor((2 * hw - kZebraGap) / (kZebraStripe + kZebraGap) + 1e-9)));
        const double total = stripes * kZebraStripe + (stripes - 1) * kZebraGap, first = -0.5 * total;
        for (int k = 0; k < stripes; ++k) {
            double t0 = first + k * (kZebraStripe + kZebraGap);
            rect(sNear, sFar, t0, t0 + kZebraStripe);
        }
    };
    double c0 = 0, c1 = 0;
    if (jA && Lr > 2 * (kStopSetback + kStopDepth))
        rect(kStopSetback, kStopSetback + kStopDepth, off, off + ln.left * lw);
    if (jB && Lr > 2 * (kStopSetback + kStopDepth))
        rect(Lr - kStopSetback - kStopDepth, Lr - kStopSetback, off - ln.right * lw, off);
    if (crossingBand(ln, false, c0, c1)) zebra(c0, c1);
    if (crossingBand(ln, true, c0, c1)) zebra(c0, c1);
}

void SurfaceContext::roads() {
    MeshBuilder road(mesh(Material::Road), out.origin, Material::Road, light);
    MeshBuilder mark(mesh(Material::Marking), out.origin, Material::Marking, light);
    std::vector<std::pair<uint32_t, uint32_t>> nodeEdges;  // (node of this tile, incident edge)
    carriageways(road, mark, nodeEdges);
    // Junction polygons, drawn by the node's tile: the convex hull of the
    // carriageway corners at the node and a sidewalk width further along every
    // incident edge, plus, between angularly consecutive edges, the point where
    // their facing carriageway borders meet (fills the outer side of bends and
    // the ground under rounded sidewalk corners). Dead ends get a round cap.
    std::sort(nodeEdges.begin(), nodeEdges.end());
    for (size_t i = 0; i < nodeEdges.size();) {
        size_t j = i;
        while (j < nodeEdges.size() && nodeEdges[j].first == nodeEdges[i].first) ++j;
        const uint32_t node = nodeEdges[i].first;
        Polygon2 pts = junctionPoints(node, nodeEdges, i, j);
        linkRoadBorders(node, pts);
        Polygon2 hull = convexHull(pts, 1e-12);
        if (hull.size() < 3) hull.clear();
        if (hull.size() >= 3) {
            road.setId(makeInstanceId(InstanceKind::Junction, node));
            glm::dvec2 m(0.0);
            for (const auto& q : hull) m += q;
            const glm::dvec2 centre = m / double(hull.size());
            for (size_t k = 0; k < hull.size(); ++k) fanTriangle(road, centre, hull[k], hull[(k + 1) % hull.size()]);
        }
        i = j;
    }
}

void SurfaceContext::carriageways(MeshBuilder& road, MeshBuilder& mark,
                                  std::vector<std::pair<uint32_t, uint32_t>>& nodeEdges) {
    const StreetGraph& g = city.streets;
    const size_t nodeCount = g.nodes.size();
    const size_t edgeCount = edgeList ? edgeList->size() : g.edges.size();
    for (size_t ei = 0; ei < edgeCount; ++ei) {
        const size_t e = edgeList ? size_t((*edgeList)[ei]) : ei;
        if (e >= g.edges.size()) continue;
        const StreetEdge& E = g.edges[e];
        if (E.a >= nodeCount || E.b >= nodeCount) continue;
        const glm::dvec2 A = g.nodes[E.a], B = g.nodes[E.b];
        if (!std::isfinite(A.x + A.y + B.x + B.y)) continue;
        if (!claim.overlaps(glm::min(A, B) - 1.0, glm::max(A, B) + 1.0)) continue;
        if (mine(A)) nodeEdges.emplace_back(E.a, uint32_t(e));
        if (mine(B)) nodeEdges.emplace_back(E.b, uint32_t(e));
        double L = glm::length(B - A);
        if (!(L > 1e-6)) continue;
        const glm::dvec2 d = (B - A) / L, n(-d.y, d.x);
        road.setId(makeInstanceId(InstanceKind::Road, e));
        mark.setId(makeInstanceId(InstanceKind::Road, e));
        const double hw = 0.5 * safeWidth(E);
        const int pieces = std::max(1, int(std::ceil(L / kMaxPiece)));
        for (int k = 0; k < pieces; ++k) {
            double t0 = L * k / pieces, t1 = L * (k + 1) / pieces;
            if (!mine(A + d * (0.5 * (t0 + t1)))) continue;
            int sub = flat ? 1 : std::max(1, int(std::ceil((t1 - t0) / step)));
            for (int s = 0; s < sub; ++s) {
                double u0 = t0 + (t1 - t0) * s / sub, u1 = t0 + (t1 - t0) * (s + 1) / sub;
                glm::dvec2 p0 = A + d * u0, p1 = A + d * u1;
                quad(road, at(p0 - n * hw, kRoadLift), at(p1 - n * hw, kRoadLift), at(p1 + n * hw, kRoadLift),
                     at(p0 + n * hw, kRoadLift));
            }
        }
        edgeMarkings(mark, e, A, d, L, pieces);
    }
}

Polygon2 SurfaceContext::junctionPoints(uint32_t node, const std::vector<std::pair<uint32_t, uint32_t>>& nodeEdges,
                                        size_t i, size_t j) const {
    const StreetGraph& g = city.streets;
    const double sw = std::max(0.0, P.sidewalk_m);
    struct Arm {
        double angle;
        glm::dvec2 d;
        double hw;
    };
    std::vector<Arm> arms;
    const glm::dvec2 c = g.nodes[node];
    Polygon2 pts;
    double r = 0;
    for (size_t k = i; k < j; ++k) {
        const StreetEdge& E = g.edges[nodeEdges[k].second];
        glm::dvec2 o = g.nodes[E.a == node ? E.b : E.a];
        double L = glm::length(o - c);
        if (!(L > 1e-6)) continue;
        glm::dvec2 d = (o - c) / L, n(-d.y, d.x);
        double hw = 0.5 * safeWidth(E), s = std::min(hw + sw, 0.5 * L);
        r = std::max(r, hw);
        pts.push_back(c + n * hw);
        pts.push_back(c - n * hw);
        pts.push_back(c + d * s + n * hw);
        pts.push_back(c + d * s - n * hw);
        arms.push_back({std::atan2(d.y, d.x), d, hw});
    }
    if (arms.size() == 1) {
        // Dead end: round cap of the carriageway's half width.
        const int capN = 12;
        for (int k = 0; k < capN; ++k) {
            double a = 2 * kPi * k / capN;
            pts.push_back(c + arms[0].hw * glm::dvec2(std::cos(a), std::sin(a)));
        }
    } else if (arms.size() > 1) {
        std::sort(arms.begin(), arms.end(), [](const Arm& a, const Arm& b) { return a.angle < b.angle; });
        for (size_t k = 0; k < arms.size(); ++k) {
            const Arm& a = arms[k];
            const Arm& b = arms[(k + 1) % arms.size()];
            // Left border of a: c + n_a hw_a + t d_a; right border of b: c - n_b hw_b + u d_b.
            glm::dvec2 na(-a.d.y, a.d.x), nb(-b.d.y, b.d.x);
            double den = a.d.x * b.d.y - a.d.y * b.d.x;
            if (std::abs(den) < 1e-6) continue;
            glm::dvec2 rhs = -nb * b.hw - na * a.hw;
            double t = (rhs.x * b.d.y - rhs.y * b.d.x) / den;
            glm::dvec2 q = c + na * a.hw + a.d * t;
            if (glm::length(q - c) <= r + sw + 1e-9) pts.push_back(q);
        }
    }
    return pts;
}

void SurfaceContext::linkRoadBorders(uint32_t node, Polygon2& pts) const {
    if (lanes && node < lanes->nodeLinks.size()) {
        for (uint32_t k : lanes->nodeLinks[node]) {
            const LinkRoad& r = lanes->links[k];
            const double len = r.length();
            const int steps = std::max(2, int(std::ceil(len / 1.0)));
            for (int q = 0; q <= steps; ++q) {
                const double u = len * q / steps, h = r.heading(u);
                double tl = r.laneOffset(u), tr = tl;
                for (const LinkRoad::Lane& l : r.left) tl += l.sidewalk ? 0.0 : r.width(l, u);
                for (const LinkRoad::Lane& l : r.right) tr -= l.sidewalk ? 0.0 : r.width(l, u);
                const glm::dvec2 c0 = r.point(u), nl(-std::sin(h), std::cos(h));
                pts.push_back(c0 + nl * tl);
                pts.push_back(c0 + nl * tr);
            }
        }
    }
}

void SurfaceContext::sidewalks() {
    const double sw = P.sidewalk_m;
    if (!(sw > 0.01)) return;
    const double half = 0.5 * P.size_m;
    MeshBuilder b(mesh(Material::Sidewalk), out.origin, Material::Sidewalk, light);
    auto onBorder = [&](const glm::dvec2& p, const glm::dvec2& q) {
        const double e = 1e-6;
        return (std::abs(p.x - q.x) < e && std::abs(std::abs(p.x) - half) < e) ||
               (std::abs(p.y - q.y) < e && std::abs(std::abs(p.y) - half) < e);
    };
    // Top strip and the two kerb faces (outer towards the road, inner towards
    // the block) between inner points p0, p1 and outer points o0, o1.
    auto segment = [&](const glm::dvec2& p0, const glm::dvec2& p1, const glm::dvec2& o0, const glm::dvec2& o1) {
        int sub = flat ? 1 : std::max(1, int(std::ceil(glm::length(p1 - p0) / step)));
        for (int s = 0; s < sub; ++s) {
            double f0 = double(s) / sub, f1 = double(s + 1) / sub;
            glm::dvec2 a = glm::mix(p0, p1, f0), bb = glm::mix(p0, p1, f1);
            glm::dvec2 oa = glm::mix(o0, o1, f0), ob = glm::mix(o0, o1, f1);
            quad(b, at(a, kSidewalkLift), at(oa, kSidewalkLift), at(ob, kSidewalkLift), at(bb, kSidewalkLift));
            quad(b, at(oa, 0), at(ob, 0), at(ob, kSidewalkLift), at(oa, kSidewalkLift));
            quad(b, at(bb, 0), at(a, 0), at(a, kSidewalkLift), at(bb, kSidewalkLift));
        }
    };
    const size_t blockCount = blockList ? blockList->size() : city.blocks.size();
    for (size_t bi = 0; bi < blockCount; ++bi) {
        const size_t bidx = blockList ? size_t((*blockList)[bi]) : bi;
        if (bidx >= city.blocks.size()) continue;
        const Polygon2& raw = city.blocks[bidx].outline;
        const size_t n0 = raw.size();
        if (n0 < 3 || !finitePolygon(raw)) continue;
        bool any = false;
        for (size_t i = 0; i < n0 && !any; ++i) {
            glm::dvec2 m = 0.5 * (raw[i] + raw[(i + 1) % n0]);
            any = m.x >= claim.x0 && m.x <= claim.x1 && m.y >= claim.y0 && m.y <= claim.y1;
        }
        if (!any) continue;
        Polygon2 poly = cleanPolygon(raw, 1e-7);
        if (poly.size() < 3) continue;
        if (signedArea(poly) < 0) std::reverse(poly.begin(), poly.end());
        b.setId(makeInstanceId(InstanceKind::Sidewalk, bidx));
        const size_t n = poly.size();
        std::vector<glm::dvec2> dir(n), nrm(n);  // per segment i: poly[i] -> poly[i+1]; outward = right
        for (size_t i = 0; i < n; ++i) {
            glm::dvec2 d = poly[(i + 1) % n] - poly[i];
            double L = glm::length(d);
            dir[i] = L > 0 ? d / L : glm::dvec2(1, 0);
            nrm[i] = glm::dvec2(dir[i].y, -dir[i].x);
        }
        // Outer start/end points of every segment: mitred at reflex corners,
        // plain offsets (joined by a round wedge) at convex corners.
        std::vector<glm::dvec2> oStart(n), oEnd(n);
        std::vector<bool> convex(n);
        for (size_t i = 0; i < n; ++i) {
            size_t prev = (i + n - 1) % n;
            double turn = dir[prev].x * dir[i].y - dir[prev].y * dir[i].x;  // > 0: left turn = convex vertex (CCW)
            convex[i] = turn > 1e-9;
            if (convex[i]) {
                oStart[i] = poly[i] + nrm[i] * sw;
            } else {
                glm::dvec2 m = nrm[prev] + nrm[i];
                double ml = glm::length(m);
                glm::dvec2 mu = ml > 1e-9 ? m / ml : nrm[i];
                double c = std::max(0.35, glm::dot(mu, nrm[i]));
                oStart[i] = poly[i] + mu * (sw / c);
            }
        }
        for (size_t i = 0; i < n; ++i) {
            size_t next = (i + 1) % n;
            oEnd[i] = convex[next] ? poly[next] + nrm[i] * sw : oStart[next];
        }
        for (size_t i = 0; i < n; ++i) {
            const glm::dvec2 p0 = poly[i], p1 = poly[(i + 1) % n];
            if (!mine(0.5 * (p0 + p1))) continue;
            if (!onBorder(p0, p1)) segment(p0, p1, oStart[i], oEnd[i]);
            // Round corner wedge at the start vertex of this segment.
            size_t prev = (i + n - 1) % n;
            if (!convex[i] || onBorder(poly[prev], p0) || onBorder(p0, p1)) continue;
            double a0 = std::atan2(nrm[prev].y, nrm[prev].x), a1 = std::atan2(nrm[i].y, nrm[i].x);
            double da = a1 - a0;
            while (da <= 0) da += 2 * kPi;
            while (da > 2 * kPi) da -= 2 * kPi;
            if (da < 1e-3 || da > kPi) continue;
            int k = std::max(1, int(std::ceil(da / (kPi / 6))));
            for (int s = 0; s < k; ++s) {
                double b0 = a0 + da * s / k, b1 = a0 + da * (s + 1) / k;
                glm::dvec2 q0 = p0 + sw * glm::dvec2(std::cos(b0), std::sin(b0));
                glm::dvec2 q1 = p0 + sw * glm::dvec2(std::cos(b1), std::sin(b1));
                tri(b, at(p0, kSidewalkLift), at(q0, kSidewalkLift), at(q1, kSidewalkLift));
                quad(b, at(q0, 0), at(q1, 0), at(q1, kSidewalkLift), at(q0, kSidewalkLift));
            }
        }
    }
}

}  // namespace

SurfaceIndex buildSurfaceIndex(const City& city, const TileGrid& grid) {
    SurfaceIndex idx;
    idx.tiles = grid.count();
    idx.edges.resize(size_t(idx.tiles));
    idx.blocks.resize(size_t(idx.tiles));
    idx.parks.resize(size_t(idx.tiles));
    idx.lanes = buildLaneModel(city.streets, city.params, &city.blocks);
    const StreetGraph& g = city.streets;
    auto addUnique = [](std::vector<uint32_t>& v, uint32_t i) {
        if (v.empty() || v.back() != i) v.push_back(i);
    };
    std::vector<int> touched;
    for (size_t e = 0; e < g.edges.size(); ++e) {
        const StreetEdge& E = g.edges[e];
        if (E.a >= g.nodes.size() || E.b >= g.nodes.size()) continue;
        const glm::dvec2 A = g.nodes[E.a], B = g.nodes[E.b];
        if (!std::isfinite(A.x + A.y + B.x + B.y)) continue;
        // Same piece split as SurfaceContext::roads(), plus both end nodes.
        touched.clear();
        touched.push_back(grid.tileOf(A));
        touched.push_back(grid.tileOf(B));
        double L = glm::length(B - A);
        if (L > 1e-6) {
            int pieces = std::max(1, int(std::ceil(L / kMaxPiece)));
            for (int k = 0; k < pieces; ++k) touched.push_back(grid.tileOf(A + (B - A) * ((k + 0.5) / pieces)));
        }
        std::sort(touched.begin(), touched.end());
        touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
        for (int t : touched) idx.edges[size_t(t)].push_back(uint32_t(e));
    }
    for (size_t b = 0; b < city.blocks.size(); ++b) {
        const Polygon2& o = city.blocks[b].outline;
        if (o.size() < 3 || !finitePolygon(o)) continue;
        touched.clear();
        glm::dvec2 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
        for (size_t i = 0; i < o.size(); ++i) {
            touched.push_back(grid.tileOf(0.5 * (o[i] + o[(i + 1) % o.size()])));
            lo = glm::min(lo, o[i]);
            hi = glm::max(hi, o[i]);
        }
        std::sort(touched.begin(), touched.end());
        touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
        for (int t : touched) addUnique(idx.blocks[size_t(t)], uint32_t(b));
        if (!city.blocks[b].park) continue;
        int t0 = grid.tileOf(lo), t1 = grid.tileOf(hi);
        for (int y = grid.iy(t0); y <= grid.iy(t1); ++y)
            for (int x = grid.ix(t0); x <= grid.ix(t1); ++x)
                idx.parks[size_t(y * grid.countX() + x)].push_back(uint32_t(b));
    }
    return idx;
}

void meshSurfaces(const City& city, const TileGrid& grid, int tile, const Lighting& light, Tile& out) {
    meshSurfaces(city, grid, tile, light, out, nullptr);
}

void meshSurfaces(const City& city, const TileGrid& grid, int tile, const Lighting& light, Tile& out,
                  const SurfaceIndex* index) {
    VISTA_CHECK(tile >= 0 && tile < grid.count());
    VISTA_CHECK(!index || index->tiles == grid.count());
    out.ix = grid.ix(tile);
    out.iy = grid.iy(tile);
    out.origin = grid.origin(tile);
    SurfaceContext ctx(city, grid, tile, light, out, index);
    ctx.groundMesh();
    ctx.parks();
    ctx.roads();
    ctx.sidewalks();
}

}  // namespace vista
