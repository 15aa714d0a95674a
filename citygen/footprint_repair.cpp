// Exact-predicate ring repair, nesting checks and constrained triangulation of
// polygons with holes (CGAL only here). Contracts in footprint_repair.h.
#include "citygen/footprint_repair.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <exception>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/intersections.h>

#include "citygen/polygon.h"

namespace vista {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_2;
using Segment = K::Segment_2;

constexpr int kMaxSplits = 64;

bool finite(const Polygon2& r) {
    for (const auto& p : r)
        if (!std::isfinite(p.x) || !std::isfinite(p.y)) return false;
    return true;
}

Point pt(const glm::dvec2& p) { return Point(p.x, p.y); }

struct Box {
    glm::dvec2 lo, hi;
    bool overlaps(const Box& o) const { return lo.x <= o.hi.x && o.lo.x <= hi.x && lo.y <= o.hi.y && o.lo.y <= hi.y; }
};
Box edgeBox(const glm::dvec2& a, const glm::dvec2& b) { return {glm::min(a, b), glm::max(a, b)}; }

// Removes exactly repeated consecutive points (and the closing repeat) and zero-width spikes
// (a vertex whose neighbours lie on a line through it, folding back), with exact orientation.
Polygon2 dedupeAndDespike(Polygon2 r) {
    bool changed = true;
    while (changed && r.size() >= 2) {
        changed = false;
        Polygon2 out;
        for (const auto& p : r)
            if (out.empty() || p != out.back()) out.push_back(p);
        while (out.size() > 1 && out.front() == out.back()) out.pop_back();
        changed = out.size() != r.size();
        r = std::move(out);
        for (size_t i = 0; r.size() >= 3 && i < r.size(); ++i) {
            const size_t n = r.size();
            const glm::dvec2 &a = r[(i + n - 1) % n], &b = r[i], &c = r[(i + 1) % n];
            if (CGAL::orientation(pt(a), pt(b), pt(c)) == CGAL::COLLINEAR && glm::dot(b - a, c - b) <= 0) {
                r.erase(r.begin() + long(i));
                changed = true;
                break;
            }
        }
    }
    return r;
}

bool simple(const Polygon2& r) {
    if (r.size() < 3) return false;
    std::vector<Point> pts;
    pts.reserve(r.size());
    for (const auto& p : r) pts.push_back(pt(p));
    return CGAL::is_simple_2(pts.begin(), pts.end(), K());
}

// First pair (i < j) of non-adjacent edges that touch or cross; false if none.
bool firstConflict(const Polygon2& r, size_t& ei, size_t& ej) {
    const size_t n = r.size();
    std::vector<Box> boxes(n);
    for (size_t i = 0; i < n; ++i) boxes[i] = edgeBox(r[i], r[(i + 1) % n]);
    for (size_t i = 0; i < n; ++i)
        for (size_t j = i + 2; j < n; ++j) {
            if (i == 0 && j == n - 1) continue;  // adjacent through the closing vertex
            if (!boxes[i].overlaps(boxes[j])) continue;
            if (CGAL::do_intersect(Segment(pt(r[i]), pt(r[(i + 1) % n])), Segment(pt(r[j]), pt(r[(j + 1) % n])))) {
                ei = i;
                ej = j;
                return true;
            }
        }
    return false;
}

bool segmentsConflict(const Polygon2& a, const Polygon2& b) {
    const size_t na = a.size(), nb = b.size();
    std::vector<Box> bb(nb);
    for (size_t j = 0; j < nb; ++j) bb[j] = edgeBox(b[j], b[(j + 1) % nb]);
    for (size_t i = 0; i < na; ++i) {
        const Box ba = edgeBox(a[i], a[(i + 1) % na]);
        const Segment sa(pt(a[i]), pt(a[(i + 1) % na]));
        for (size_t j = 0; j < nb; ++j)
            if (ba.overlaps(bb[j]) && CGAL::do_intersect(sa, Segment(pt(b[j]), pt(b[(j + 1) % nb])))) return true;
    }
    return false;
}

bool strictlyInsidePoint(const glm::dvec2& p, const Polygon2& ring) {
    std::vector<Point> pts;
    pts.reserve(ring.size());
    for (const auto& q : ring) pts.push_back(pt(q));
    return CGAL::bounded_side_2(pts.begin(), pts.end(), pt(p), K()) == CGAL::ON_BOUNDED_SIDE;
}

}  // namespace

bool isSimpleRingExact(const Polygon2& ring) {
    if (!finite(ring)) return false;
    try {
        return simple(ring);
    } catch (...) { return false; }
}

Polygon2 makeSimpleRing(const Polygon2& ring, bool& split) {
    split = false;
    if (!finite(ring)) return {};
    try {
        std::vector<Polygon2> work{ring}, done;
        int splits = 0;
        while (!work.empty()) {
            Polygon2 r = dedupeAndDespike(std::move(work.back()));
            work.pop_back();
            if (r.size() < 3) continue;
            if (simple(r)) {
                done.push_back(std::move(r));
                continue;
            }
            if (r.size() > kMaxRepairRingNodes || splits >= kMaxSplits) continue;
            size_t i = 0, j = 0;
            if (!firstConflict(r, i, j)) continue;  // not simple for a reason splitting cannot fix
            const size_t n = r.size();
            const Segment si(pt(r[i]), pt(r[(i + 1) % n])), sj(pt(r[j]), pt(r[(j + 1) % n]));
            glm::dvec2 x;
            const auto hit = CGAL::intersection(si, sj);
            if (!hit) continue;
            if (const Point* p = boost::get<Point>(&*hit)) x = {CGAL::to_double(p->x()), CGAL::to_double(p->y())};
            else if (const Segment* s = boost::get<Segment>(&*hit))
                x = {CGAL::to_double(s->source().x()), CGAL::to_double(s->source().y())};
            else continue;
            if (!std::isfinite(x.x) || !std::isfinite(x.y)) continue;
            // Loop A: x, r[i+1] .. r[j]; loop B: x, r[j+1] .. r[i] (cyclic).
            Polygon2 a{x}, b{x};
            for (size_t k = i + 1; k <= j; ++k) a.push_back(r[k]);
            for (size_t k = j + 1; k != i + 1 + n; ++k) b.push_back(r[k % n]);
            ++splits;
            split = true;
            work.push_back(std::move(b));
            work.push_back(std::move(a));
        }
        size_t best = done.size();
        double bestArea = 0;
        for (size_t k = 0; k < done.size(); ++k) {
            const double a = std::abs(signedArea(done[k]));
            if (a > bestArea) {
                bestArea = a;
                best = k;
            }
        }
        if (best == done.size()) return {};
        Polygon2 out = std::move(done[best]);
        if (signedArea(out) < 0) std::reverse(out.begin(), out.end());
        return out;
    } catch (...) { return {}; }
}

bool ringStrictlyInside(const Polygon2& inner, const Polygon2& outer) {
    if (inner.size() < 3 || outer.size() < 3 || !finite(inner) || !finite(outer)) return false;
    try {
        return !segmentsConflict(inner, outer) && strictlyInsidePoint(inner[0], outer);
    } catch (...) { return false; }
}

bool ringsDisjoint(const Polygon2& a, const Polygon2& b) {
    if (a.size() < 3 || b.size() < 3 || !finite(a) || !finite(b)) return false;
    try {
        return !segmentsConflict(a, b) && !strictlyInsidePoint(a[0], b) && !strictlyInsidePoint(b[0], a);
    } catch (...) { return false; }
}

std::vector<std::array<glm::dvec2, 3>> triangulateWithHoles(const Polygon2& outer, const std::vector<Polygon2>& holes) {
    using Vb = CGAL::Triangulation_vertex_base_2<K>;
    using Fbb = CGAL::Triangulation_face_base_with_info_2<int, K>;
    using Fb = CGAL::Constrained_triangulation_face_base_2<K, Fbb>;
    using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
    using Cdt = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;
    std::vector<std::array<glm::dvec2, 3>> out;
    if (outer.size() < 3 || !finite(outer)) return out;
    for (const auto& h : holes)
        if (h.size() < 3 || !finite(h)) return out;
    try {
        Cdt cdt;
        auto addRing = [&](const Polygon2& r) {
            std::vector<Cdt::Vertex_handle> v;
            v.reserve(r.size());
            for (const auto& p : r) v.push_back(cdt.insert(pt(p)));
            for (size_t k = 0; k < v.size(); ++k)
                if (v[k] != v[(k + 1) % v.size()]) cdt.insert_constraint(v[k], v[(k + 1) % v.size()]);
        };
        addRing(outer);
        for (const auto& h : holes) addRing(h);
        // Nesting level per face: 0 for faces reached from the infinite face without crossing a
        // constraint, one more for every constraint crossed (odd = inside the polygon with holes).
        for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) f->info() = -1;
        std::deque<std::pair<Cdt::Face_handle, int>> crossings{{cdt.infinite_face(), 0}};
        while (!crossings.empty()) {
            auto [start, level] = crossings.front();
            crossings.pop_front();
            if (start->info() != -1) continue;
            std::deque<Cdt::Face_handle> flood{start};
            start->info() = level;
            while (!flood.empty()) {
                auto f = flood.front();
                flood.pop_front();
                for (int k = 0; k < 3; ++k) {
                    auto g = f->neighbor(k);
                    if (g->info() != -1) continue;
                    if (cdt.is_constrained(std::make_pair(f, k))) {
                        crossings.push_back({g, level + 1});
                    } else {
                        g->info() = level;
                        flood.push_back(g);
                    }
                }
            }
        }
        for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
            if (f->info() % 2 != 1) continue;
            std::array<glm::dvec2, 3> t;
            for (int k = 0; k < 3; ++k)
                t[size_t(k)] = {CGAL::to_double(f->vertex(k)->point().x()), CGAL::to_double(f->vertex(k)->point().y())};
            out.push_back(t);
        }
    } catch (...) { out.clear(); }
    return out;
}

}  // namespace vista
