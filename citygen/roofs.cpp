// CGAL straight-skeleton based helpers: polygon inset fallback and hipped roofs.
// See building_geometry.h for the contracts.
#include <cmath>
#include <exception>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2.h>
#include <CGAL/create_offset_polygons_2.h>
#include <CGAL/create_straight_skeleton_2.h>

#include "citygen/building_geometry.h"
#include "citygen/polygon.h"

namespace vista {

namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalPolygon = CGAL::Polygon_2<K>;

bool toCgal(const Polygon2& p, CgalPolygon& out) {
    if (p.size() < 3) return false;
    for (const auto& q : p) {
        if (!std::isfinite(q.x) || !std::isfinite(q.y)) return false;
        out.push_back(K::Point_2(q.x, q.y));
    }
    return out.is_simple() && out.is_counterclockwise_oriented();
}
}  // namespace

std::vector<Polygon2> insetPolygonSkeleton(const Polygon2& ccw, double d) {
    std::vector<Polygon2> out;
    if (!(d > 0) || !std::isfinite(d)) return out;
    try {
        CgalPolygon poly;
        if (!toCgal(ccw, poly)) return out;
        auto res = CGAL::create_interior_skeleton_and_offset_polygons_2(d, poly);
        for (const auto& pp : res) {
            if (!pp) continue;
            Polygon2 q;
            for (auto it = pp->vertices_begin(); it != pp->vertices_end(); ++it)
                q.emplace_back(CGAL::to_double(it->x()), CGAL::to_double(it->y()));
            bool ok = q.size() >= 3;
            for (const auto& v : q) ok = ok && std::isfinite(v.x) && std::isfinite(v.y);
            if (ok) out.push_back(makeCounterClockwise(std::move(q)));
        }
    } catch (const std::exception&) { out.clear(); } catch (...) {
        out.clear();
    }
    return out;
}

bool hippedRoofFaces(const Polygon2& ccw, std::vector<std::vector<glm::dvec3>>& faces, double& maxTime) {
    faces.clear();
    maxTime = 0;
    try {
        CgalPolygon poly;
        if (!toCgal(ccw, poly)) return false;
        auto ss = CGAL::create_interior_straight_skeleton_2(poly.vertices_begin(), poly.vertices_end(), K());
        if (!ss) return false;
        for (auto f = ss->faces_begin(); f != ss->faces_end(); ++f) {
            std::vector<glm::dvec3> face;
            auto h0 = f->halfedge();
            auto h = h0;
            size_t guard = 0;
            do {
                const auto& v = h->vertex();
                glm::dvec3 q(CGAL::to_double(v->point().x()), CGAL::to_double(v->point().y()),
                             CGAL::to_double(v->time()));
                if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z)) return false;
                face.push_back(q);
                maxTime = std::max(maxTime, q.z);
                h = h->next();
            } while (h != h0 && ++guard < 10000);
            if (face.size() < 3) continue;
            // Orient counter-clockwise seen from above (Newell normal z > 0).
            double nz = 0;
            for (size_t i = 0; i < face.size(); ++i) {
                const auto& a = face[i];
                const auto& b = face[(i + 1) % face.size()];
                nz += (a.x - b.x) * (a.y + b.y);
            }
            if (nz < 0) std::reverse(face.begin(), face.end());
            faces.push_back(std::move(face));
        }
        if (faces.size() < ccw.size() || !(maxTime > 0)) {
            faces.clear();
            return false;
        }
        return true;
    } catch (const std::exception&) {
    } catch (...) {}
    faces.clear();
    return false;
}

}  // namespace vista
