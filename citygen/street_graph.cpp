#include "citygen/street_graph.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <unordered_set>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <nlohmann/json.hpp>

#include "citygen/osm_road_tags.h"
#include "citygen/street_geometry.h"
#include "foundation/number_text.h"

namespace vista {

const char* roadClassName(RoadClass c) {
    switch (c) {
        case RoadClass::Highway: return "highway";
        case RoadClass::Arterial: return "arterial";
        case RoadClass::Local: return "local";
    }
    return "local";
}

double roadWidth(RoadClass c) {
    switch (c) {
        case RoadClass::Highway: return 20.0;
        case RoadClass::Arterial: return 13.0;
        case RoadClass::Local: return 7.5;
    }
    return 7.5;
}

int roadLanes(RoadClass c) {
    switch (c) {
        case RoadClass::Highway: return 6;
        case RoadClass::Arterial: return 4;
        case RoadClass::Local: return 2;
    }
    return 2;
}

std::vector<int> StreetGraph::degrees() const {
    std::vector<int> d(nodes.size(), 0);
    for (const auto& e : edges) {
        if (e.a < d.size()) d[e.a]++;
        if (e.b < d.size()) d[e.b]++;
    }
    return d;
}

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using KPoint = K::Point_2;
using KSegment = K::Segment_2;

std::string fmtPoint(const glm::dvec2& p) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "(%.6f, %.6f)", p.x, p.y);
    return buf;
}

// True when edges e and f (valid, non-degenerate) violate planarity.
bool conflicts(const StreetGraph& g, const StreetEdge& e, const StreetEdge& f) {
    const uint32_t ea = e.a, eb = e.b, fa = f.a, fb = f.b;
    int shared = int(ea == fa) + int(ea == fb) + int(eb == fa) + int(eb == fb);
    KPoint p0(g.nodes[ea].x, g.nodes[ea].y), p1(g.nodes[eb].x, g.nodes[eb].y);
    KPoint q0(g.nodes[fa].x, g.nodes[fa].y), q1(g.nodes[fb].x, g.nodes[fb].y);
    if (shared >= 2) return true;  // duplicate edge
    if (shared == 1) {
        KPoint s, a, b;
        if (ea == fa) {
            s = p0;
            a = p1;
            b = q1;
        } else if (ea == fb) {
            s = p0;
            a = p1;
            b = q0;
        } else if (eb == fa) {
            s = p1;
            a = p0;
            b = q1;
        } else {
            s = p1;
            a = p0;
            b = q0;
        }
        if (!CGAL::collinear(s, a, b)) return false;
        // Collinear: fine only when s lies strictly between a and b (opposite rays).
        return !CGAL::collinear_are_strictly_ordered_along_line(a, s, b);
    }
    return CGAL::do_intersect(KSegment(p0, p1), KSegment(q0, q1));
}

}  // namespace

std::vector<std::pair<uint32_t, uint32_t>> findConflictingEdges(const StreetGraph& g, size_t maxPairs) {
    std::vector<std::pair<uint32_t, uint32_t>> out;
    const size_t n = g.edges.size();
    if (n < 2 || maxPairs == 0) return out;
    struct Box {
        double x0, y0, x1, y1;
    };
    std::vector<Box> boxes(n);
    double minX = 1e300, minY = 1e300, maxX = -1e300, maxY = -1e300, sumLen = 0;
    for (size_t i = 0; i < n; ++i) {
        const auto& a = g.nodes[g.edges[i].a];
        const auto& b = g.nodes[g.edges[i].b];
        boxes[i] = {std::min(a.x, b.x), std::min(a.y, b.y), std::max(a.x, b.x), std::max(a.y, b.y)};
        minX = std::min(minX, boxes[i].x0);
        minY = std::min(minY, boxes[i].y0);
        maxX = std::max(maxX, boxes[i].x1);
        maxY = std::max(maxY, boxes[i].y1);
        sumLen += glm::length(b - a);
    }
    double w = std::max(maxX - minX, 1e-9), h = std::max(maxY - minY, 1e-9);
    double cell = std::max({sumLen / double(n), std::sqrt(w * h / double(2 * n)), 1e-6});
    const int kMaxDim = 2048;
    int nx = std::clamp(int(std::ceil(w / cell)), 1, kMaxDim);
    int ny = std::clamp(int(std::ceil(h / cell)), 1, kMaxDim);
    double cx = w / nx, cy = h / ny;
    auto ix = [&](double x) { return std::clamp(int((x - minX) / cx), 0, nx - 1); };
    auto iy = [&](double y) { return std::clamp(int((y - minY) / cy), 0, ny - 1); };

    // Counting sort of (cell, edge) entries.
    std::vector<uint32_t> count(size_t(nx) * ny + 1, 0);
    for (size_t i = 0; i < n; ++i)
        for (int y = iy(boxes[i].y0); y <= iy(boxes[i].y1); ++y)
            for (int x = ix(boxes[i].x0); x <= ix(boxes[i].x1); ++x) count[size_t(y) * nx + x + 1]++;
    for (size_t c = 1; c < count.size(); ++c) count[c] += count[c - 1];
    std::vector<uint32_t> items(count.back());
    std::vector<uint32_t> fill(count.begin(), count.end() - 1);
    for (size_t i = 0; i < n; ++i)
        for (int y = iy(boxes[i].y0); y <= iy(boxes[i].y1); ++y)
            for (int x = ix(boxes[i].x0); x <= ix(boxes[i].x1); ++x) items[fill[size_t(y) * nx + x]++] = uint32_t(i);

    for (int y = 0; y < ny; ++y) {
        for (int x = 0; x < nx; ++x) {
            size_t c = size_t(y) * nx + x;
            for (uint32_t s = count[c]; s < count[c + 1]; ++s) {
                uint32_t i = items[s];
                const Box& bi = boxes[i];
                for (uint32_t t = s + 1; t < count[c + 1]; ++t) {
                    uint32_t j = items[t];
                    const Box& bj = boxes[j];
                    if (bi.x1 < bj.x0 || bj.x1 < bi.x0 || bi.y1 < bj.y0 || bj.y1 < bi.y0) continue;
                    // Test each pair once: in the cell holding the overlap's min corner.
                    if (ix(std::max(bi.x0, bj.x0)) != x || iy(std::max(bi.y0, bj.y0)) != y) continue;
                    if (conflicts(g, g.edges[i], g.edges[j])) {
                        out.emplace_back(std::min(i, j), std::max(i, j));
                        if (out.size() >= maxPairs) return out;
                    }
                }
            }
        }
    }
    std::sort(out.begin(), out.end());
    return out;
}

Status checkPlanarGraph(const StreetGraph& g, double minSegment) {
    const size_t nn = g.nodes.size();
    for (size_t i = 0; i < nn; ++i)
        if (!std::isfinite(g.nodes[i].x) || !std::isfinite(g.nodes[i].y))
            return Status::error("street graph: node " + std::to_string(i) + " has a non-finite coordinate");
    std::unordered_set<uint64_t> seen;
    seen.reserve(g.edges.size() * 2);
    for (size_t e = 0; e < g.edges.size(); ++e) {
        const auto& ed = g.edges[e];
        if (ed.a >= nn || ed.b >= nn)
            return Status::error("street graph: edge " + std::to_string(e) + " references node " +
                                 std::to_string(std::max(ed.a, ed.b)) + ", allowed range [0, " + std::to_string(nn) +
                                 ")");
        if (ed.a == ed.b)
            return Status::error("street graph: edge " + std::to_string(e) + " is a self loop at node " +
                                 std::to_string(ed.a));
        if (uint8_t(ed.cls) > 2)
            return Status::error("street graph: edge " + std::to_string(e) + " has road class " +
                                 std::to_string(int(ed.cls)) + ", allowed range [0, 2]");
        if (!std::isfinite(ed.width) || ed.width <= 0)
            return Status::error("street graph: edge " + std::to_string(e) + " has invalid width " +
                                 shortNumber(ed.width));
        uint64_t key = (uint64_t(std::min(ed.a, ed.b)) << 32) | std::max(ed.a, ed.b);
        if (!seen.insert(key).second)
            return Status::error("street graph: edge " + std::to_string(e) + " duplicates another edge between nodes " +
                                 std::to_string(ed.a) + " and " + std::to_string(ed.b));
        double len = g.edgeLength(e);
        if (!(len >= minSegment))
            return Status::error("street graph: edge " + std::to_string(e) + " has length " + std::to_string(len) +
                                 " m, shorter than the minimum " + std::to_string(minSegment) + " m (at " +
                                 fmtPoint(g.nodes[ed.a]) + ")");
    }
    // Coincident nodes.
    std::vector<uint32_t> order(nn);
    for (size_t i = 0; i < nn; ++i) order[i] = uint32_t(i);
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        return g.nodes[a].x < g.nodes[b].x || (g.nodes[a].x == g.nodes[b].x && g.nodes[a].y < g.nodes[b].y);
    });
    for (size_t i = 1; i < nn; ++i)
        if (g.nodes[order[i]] == g.nodes[order[i - 1]])
            return Status::error("street graph: nodes " + std::to_string(order[i - 1]) + " and " +
                                 std::to_string(order[i]) + " coincide at " + fmtPoint(g.nodes[order[i]]));
    auto bad = findConflictingEdges(g, 1);
    if (!bad.empty()) {
        auto [e, f] = bad.front();
        return Status::error("street graph: edges " + std::to_string(e) + " " + fmtPoint(g.nodes[g.edges[e].a]) + "-" +
                             fmtPoint(g.nodes[g.edges[e].b]) + " and " + std::to_string(f) + " " +
                             fmtPoint(g.nodes[g.edges[f].a]) + "-" + fmtPoint(g.nodes[g.edges[f].b]) +
                             " intersect away from a shared node");
    }
    return Status::ok();
}

std::string streetGraphToJson(const StreetGraph& g) {
    nlohmann::json nodes = nlohmann::json::array();
    for (const auto& p : g.nodes) nodes.push_back({p.x, p.y});
    nlohmann::json edges = nlohmann::json::array();
    for (const auto& e : g.edges) {
        nlohmann::json row = {e.a, e.b, int(e.cls), double(e.width), int(e.lanes)};
        // The lane directions, speed limit and turn lanes only when they differ from the defaults.
        nlohmann::json extra = nlohmann::json::object();
        if (e.lanesForward != -1) extra["forward"] = int(e.lanesForward);
        if (e.lanesBackward != -1) extra["backward"] = int(e.lanesBackward);
        if (e.maxspeedKmh != 0.0f) extra["maxspeed"] = double(e.maxspeedKmh);
        if (!e.turnForward.empty()) extra["turn_forward"] = e.turnForward;
        if (!e.turnBackward.empty()) extra["turn_backward"] = e.turnBackward;
        if (!extra.empty()) row.push_back(std::move(extra));
        edges.push_back(std::move(row));
    }
    nlohmann::json j;
    j["nodes"] = std::move(nodes);
    j["edges"] = std::move(edges);
    return j.dump();
}

namespace {

// Lanes of one direction: the explicit count, else the split derived from `lanes`.
int directionLanes(const StreetEdge& e, bool forward) {
    const int explicitCount = forward ? e.lanesForward : e.lanesBackward;
    if (explicitCount >= 0) return explicitCount;
    const int n = std::max(int(e.lanes), 2);
    return forward ? (n + 1) / 2 : n / 2;
}

// The sixth element of an edge row: the fields that differ from the defaults.
Status readEdgeExtras(const nlohmann::json& x, const std::string& where, StreetEdge& se) {
    if (!x.is_object())
        return Status::error(where +
                             " must be an object with forward, backward, maxspeed, turn_forward, turn_backward");
    for (const auto& [key, value] : x.items()) {
        const std::string at = where + "." + key;
        if (key == "forward" || key == "backward") {
            if (!value.is_number_integer()) return Status::error(at + " must be an integer");
            const int64_t n = value.get<int64_t>();
            if (n < 0 || n > kMaxLanesPerDirection)
                return Status::error(at + " = " + std::to_string(n) + " is out of range [0, " +
                                     std::to_string(kMaxLanesPerDirection) + "]");
            (key == "forward" ? se.lanesForward : se.lanesBackward) = int8_t(n);
        } else if (key == "maxspeed") {
            if (!value.is_number()) return Status::error(at + " is not a number");
            const double v = value.get<double>();
            if (!(v >= kMinMaxspeedKmh && v <= kMaxMaxspeedKmh))
                return Status::error(at + " = " + shortNumber(v) + " is out of range [" +
                                     std::to_string(int(kMinMaxspeedKmh)) + ", " +
                                     std::to_string(int(kMaxMaxspeedKmh)) + "] km/h");
            se.maxspeedKmh = float(v);
        } else if (key == "turn_forward" || key == "turn_backward") {
            if (!value.is_string()) return Status::error(at + " must be a string");
            const std::string v = value.get<std::string>();
            const auto turns = parseOsmTurnLanes(v);
            if (v.empty() || !turns || turns->value != v)
                return Status::error(at + " = '" + v.substr(0, 64) +
                                     "' is not a turn:lanes value (lanes separated by '|', each "
                                     "empty or ';'-separated turn values, at most " +
                                     std::to_string(kMaxLanesPerDirection) + " lanes)");
            (key == "turn_forward" ? se.turnForward : se.turnBackward) = v;
        } else {
            return Status::error(where + " has unknown key '" + key.substr(0, 64) +
                                 "' (allowed: forward, backward, maxspeed, turn_forward, turn_backward)");
        }
    }
    if (se.lanesForward == 0 && se.lanesBackward == 0)
        return Status::error(where + " has no driving lane (forward = backward = 0)");
    for (bool forward : {true, false}) {
        const std::string& turn = forward ? se.turnForward : se.turnBackward;
        if (turn.empty()) continue;
        const int lanes = directionLanes(se, forward);
        const int listed = parseOsmTurnLanes(turn)->lanes;
        if (listed != lanes)
            return Status::error(where + (forward ? ".turn_forward" : ".turn_backward") + " lists " +
                                 std::to_string(listed) + " lanes, the direction has " + std::to_string(lanes));
    }
    return Status::ok();
}

}  // namespace

Result<StreetGraph> streetGraphFromJson(const std::string& text) {
    try {
        nlohmann::json j;
        try {
            j = nlohmann::json::parse(text);
        } catch (const nlohmann::json::parse_error& e) {
            return Status::error(std::string("street graph JSON is malformed: ") + e.what());
        }
        if (!j.is_object())
            return Status::error("street graph JSON: top level must be an object with 'nodes' and 'edges'");
        if (!j.contains("nodes") || !j["nodes"].is_array())
            return Status::error("street graph JSON: field 'nodes' is missing or not an array");
        if (!j.contains("edges") || !j["edges"].is_array())
            return Status::error("street graph JSON: field 'edges' is missing or not an array");
        StreetGraph g;
        const auto& nodes = j["nodes"];
        g.nodes.reserve(nodes.size());
        for (size_t i = 0; i < nodes.size(); ++i) {
            const auto& n = nodes[i];
            if (!n.is_array() || n.size() != 2 || !n[0].is_number() || !n[1].is_number())
                return Status::error("street graph JSON: nodes[" + std::to_string(i) + "] must be [x, y] numbers");
            double x = n[0].get<double>(), y = n[1].get<double>();
            if (!std::isfinite(x) || !std::isfinite(y) || std::abs(x) > 1e9 || std::abs(y) > 1e9)
                return Status::error("street graph JSON: nodes[" + std::to_string(i) + "] = [" + shortNumber(x) + ", " +
                                     shortNumber(y) + "] is out of range [-1e9, 1e9] metres");
            g.nodes.emplace_back(x, y);
        }
        const auto& edges = j["edges"];
        g.edges.reserve(edges.size());
        for (size_t i = 0; i < edges.size(); ++i) {
            const auto& e = edges[i];
            std::string where = "street graph JSON: edges[" + std::to_string(i) + "]";
            if (!e.is_array() || (e.size() != 5 && e.size() != 6))
                return Status::error(where +
                                     " must be [a, b, class, width, lanes] or [a, b, class, width, lanes, {...}]");
            for (int k = 0; k < 5; ++k)
                if (!e[k].is_number()) return Status::error(where + "[" + std::to_string(k) + "] is not a number");
            for (int k : {0, 1, 2, 4})
                if (!e[k].is_number_integer())
                    return Status::error(where + "[" + std::to_string(k) + "] must be an integer");
            int64_t a = e[0].get<int64_t>(), b = e[1].get<int64_t>(), cls = e[2].get<int64_t>(),
                    lanes = e[4].get<int64_t>();
            double width = e[3].get<double>();
            int64_t nn = int64_t(g.nodes.size());
            if (a < 0 || a >= nn || b < 0 || b >= nn)
                return Status::error(where + " node index " + std::to_string(a < 0 || a >= nn ? a : b) +
                                     " is out of range [0, " + std::to_string(nn) + ")");
            if (a == b) return Status::error(where + " is a self loop at node " + std::to_string(a));
            if (cls < 0 || cls > 2)
                return Status::error(where + " road class " + std::to_string(cls) + " is out of range [0, 2]");
            if (!std::isfinite(width) || width <= 0 || width > 200)
                return Status::error(where + " width " + std::to_string(width) + " is out of range (0, 200] metres");
            if (lanes < 1 || lanes > 32)
                return Status::error(where + " lanes " + std::to_string(lanes) + " is out of range [1, 32]");
            StreetEdge se;
            se.a = uint32_t(a);
            se.b = uint32_t(b);
            se.cls = RoadClass(uint8_t(cls));
            se.width = float(width);
            se.lanes = uint8_t(lanes);
            if (e.size() == 6) VISTA_RETURN_IF_ERROR(readEdgeExtras(e[5], where + "[5]", se));
            g.edges.push_back(std::move(se));
        }
        return g;
    } catch (const std::exception& ex) {
        return Status::error(std::string("street graph JSON could not be read: ") + ex.what());
    }
}

namespace {

// WGS84 geometry of edge a-b: a LineString, or a MultiLineString cut where it crosses +-180 degrees.
nlohmann::json geoEdge(const GeoReference& ref, const glm::dvec2& a, const glm::dvec2& b) {
    const GeoPoint ga = localToGeo(ref, a), gb = localToGeo(ref, b);
    const double dl = std::remainder(gb.lon_deg - ga.lon_deg, 360.0);
    const double end = ga.lon_deg + dl;  // b's longitude unwrapped next to a's
    if (std::abs(end) <= 180.0)
        return {{"type", "LineString"}, {"coordinates", {{ga.lon_deg, ga.lat_deg}, {gb.lon_deg, gb.lat_deg}}}};
    // Bisection for the crossing on the straight city-frame edge.
    const double cut = end > 0 ? 180.0 : -180.0;
    double t0 = 0, t1 = 1;
    for (int i = 0; i < 60; ++i) {
        const double t = 0.5 * (t0 + t1);
        const double lon = localToGeo(ref, a + t * (b - a)).lon_deg;
        const double unwrapped = ga.lon_deg + std::remainder(lon - ga.lon_deg, 360.0);
        ((unwrapped - cut) * (ga.lon_deg - cut) > 0 ? t0 : t1) = t;
    }
    const double lat = localToGeo(ref, a + 0.5 * (t0 + t1) * (b - a)).lat_deg;
    return {{"type", "MultiLineString"},
            {"coordinates", {{{ga.lon_deg, ga.lat_deg}, {cut, lat}}, {{-cut, lat}, {gb.lon_deg, gb.lat_deg}}}}};
}

}  // namespace

std::string streetGraphToGeoJson(const StreetGraph& g, double originX, double originY,
                                 const std::optional<GeoReference>& geo) {
    nlohmann::json features = nlohmann::json::array();
    for (size_t i = 0; i < g.edges.size(); ++i) {
        const auto& e = g.edges[i];
        const auto& a = g.nodes[e.a];
        const auto& b = g.nodes[e.b];
        nlohmann::json f;
        f["type"] = "Feature";
        if (geo) f["geometry"] = geoEdge(*geo, a, b);
        else
            f["geometry"] = {{"type", "LineString"},
                             {"coordinates", {{a.x + originX, a.y + originY}, {b.x + originX, b.y + originY}}}};
        f["properties"] = {
            {"id", i}, {"class", roadClassName(e.cls)}, {"width", double(e.width)}, {"lanes", int(e.lanes)}};
        features.push_back(std::move(f));
    }
    nlohmann::json j;
    j["type"] = "FeatureCollection";
    j["features"] = std::move(features);
    return j.dump();
}

}  // namespace vista
