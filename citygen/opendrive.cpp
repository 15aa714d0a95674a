// OpenDRIVE writer: see opendrive.h.
#include "citygen/opendrive.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "citygen/lanes.h"
#include "citygen/terrain.h"

namespace vista {

namespace {

constexpr double kRoadSurfaceLift = 0.02;  // road mesh above ground (surfaces.cpp kRoadLift)
constexpr double kElevationStep = 10.0;    // longest elevation piece

std::string num(double v) {
    if (std::abs(v) < 1e-12) v = 0.0;  // no "-0"
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.12g", v);
    return buf;
}

class Writer {
public:
    Writer(const StreetGraph& g, const CityParams& p, const std::vector<Block>* blocks)
        : g(g), P(p), M(buildLaneModel(g, p, blocks)) {}
    Result<std::string> run(OpenDriveCounts* counts);

private:
    double surface(const glm::dvec2& p) const { return terrainHeight(P, p) + kRoadSurfaceLift; }
    glm::dvec2 world(const glm::dvec2& p) const { return p + glm::dvec2(P.origin_x, P.origin_y); }
    void elevation(const glm::dvec2& a, const glm::dvec2& dir, double len);
    void laneSide(const EdgeLanes& L, const StreetEdge& E, bool left, uint32_t e);
    void road(uint32_t e);
    void junction(size_t j);
    std::string roadMarkCentre(RoadClass c) const;
    // Lane link at node v for lane `id` of edge e (0: none).
    int linkedLane(uint32_t e, uint32_t v, int id) const;
    uint32_t otherEdge(uint32_t e, uint32_t v) const;

    const StreetGraph& g;
    const CityParams& P;
    LaneModel M;
    std::string o;
    std::vector<std::vector<uint32_t>> incident;
    size_t nextRoadId = 0;
    OpenDriveCounts n;
    std::string junctionXml;  // <junction> elements, written after the roads
};

std::string Writer::roadMarkCentre(RoadClass c) const {
    const char* type = c == RoadClass::Highway ? "solid solid" : c == RoadClass::Arterial ? "solid" : "broken";
    return std::string("<roadMark sOffset=\"0\" type=\"") + type +
           "\" weight=\"standard\" color=\"standard\" width=\"0.15\" laneChange=\"none\"/>";
}

// Cubic Hermite pieces through the road surface height, and the terrain's
// cross slope as superelevation (linear pieces).
void Writer::elevation(const glm::dvec2& a, const glm::dvec2& dir, double len) {
    const glm::dvec2 nrm(-dir.y, dir.x);
    const int pieces = std::max(1, int(std::ceil(len / kElevationStep)));
    const double h = 0.25;  // finite-difference step
    auto zAt = [&](double s) { return surface(a + dir * s); };
    auto slope = [&](double s) { return (zAt(s + h) - zAt(s - h)) / (2 * h); };
    auto cross = [&](double s) {
        glm::dvec2 p = a + dir * s;
        return std::atan((terrainHeight(P, p + nrm * h) - terrainHeight(P, p - nrm * h)) / (2 * h));
    };
    const bool flat = !(P.hills_amplitude_m > 0);
    o += "      <elevationProfile>\n";
    if (flat) {
        o += "        <elevation s=\"0\" a=\"" + num(kRoadSurfaceLift) + "\" b=\"0\" c=\"0\" d=\"0\"/>\n";
    } else {
        for (int k = 0; k < pieces; ++k) {
            double s0 = len * k / pieces, s1 = len * (k + 1) / pieces, ds = s1 - s0;
            double z0 = zAt(s0), z1 = zAt(s1), m0 = slope(s0), m1 = slope(s1);
            double c = (3 * (z1 - z0) / ds - 2 * m0 - m1) / ds;
            double d = (m0 + m1 - 2 * (z1 - z0) / ds) / (ds * ds);
            o += "        <elevation s=\"" + num(s0) + "\" a=\"" + num(z0) + "\" b=\"" + num(m0) + "\" c=\"" + num(c) +
                 "\" d=\"" + num(d) + "\"/>\n";
        }
    }
    o += "      </elevationProfile>\n      <lateralProfile>\n";
    if (flat) {
        o += "        <superelevation s=\"0\" a=\"0\" b=\"0\" c=\"0\" d=\"0\"/>\n";
    } else {
        for (int k = 0; k < pieces; ++k) {
            double s0 = len * k / pieces, s1 = len * (k + 1) / pieces;
            // Left side higher by tan(angle) per metre; OpenDRIVE: positive falls to the right.
            double r0 = cross(s0), r1 = cross(s1);
            o += "        <superelevation s=\"" + num(s0) + "\" a=\"" + num(r0) + "\" b=\"" + num((r1 - r0) / (s1 - s0)) +
                 "\" c=\"0\" d=\"0\"/>\n";
        }
    }
    o += "      </lateralProfile>\n";
}

uint32_t Writer::otherEdge(uint32_t e, uint32_t v) const {
    for (uint32_t f : incident[v])
        if (f != e) return f;
    return e;
}

// Lanes across a degree-2 node: driving lane k links to driving lane k of the
// same travel direction when it exists, sidewalk to sidewalk.
int Writer::linkedLane(uint32_t e, uint32_t v, int id) const {
    const uint32_t f = otherEdge(e, v);
    if (f == e) return 0;
    const EdgeLanes &Le = M.edges[e], &Lf = M.edges[f];
    const bool eEndsHere = g.edges[e].b == v, fStartsHere = g.edges[f].a == v;
    // Same s direction through the node: ids keep their sign; else flip.
    const int sign = (eEndsHere == fStartsHere) ? 1 : -1;
    const int side = id > 0 ? 1 : -1;
    const int k = std::abs(id);
    const int ne = side > 0 ? Le.left : Le.right;
    const int nf = (side * sign) > 0 ? Lf.left : Lf.right;
    if (k <= ne) return k <= nf ? side * sign * k : 0;
    if (k == ne + 1 && Le.hasWalk(side) && Lf.hasWalk(side * sign)) return side * sign * (nf + 1);
    return 0;
}

void Writer::laneSide(const EdgeLanes& L, const StreetEdge& E, bool left, uint32_t e) {
    const int count = left ? L.left : L.right;
    const int sgn = left ? 1 : -1;
    const StreetEdge& SE = g.edges[e];
    const bool linkA = M.degree[SE.a] == 2, linkB = M.degree[SE.b] == 2;
    auto laneXml = [&](int k, bool sidewalk) {
        const int id = sgn * k;
        o += "            <lane id=\"" + std::to_string(id) + "\" type=\"" + (sidewalk ? "sidewalk" : "driving") +
             "\" level=\"false\">\n";
        int pre = linkA ? linkedLane(e, SE.a, id) : 0, suc = linkB ? linkedLane(e, SE.b, id) : 0;
        if (pre || suc) {
            o += "              <link>";
            if (pre) o += "<predecessor id=\"" + std::to_string(pre) + "\"/>";
            if (suc) o += "<successor id=\"" + std::to_string(suc) + "\"/>";
            o += "</link>\n";
        }
        o += "              <width sOffset=\"0\" a=\"" + num(sidewalk ? L.sidewalk : L.laneWidth) +
             "\" b=\"0\" c=\"0\" d=\"0\"/>\n";
        const bool divider = !sidewalk && k < count;
        if (divider)
            o += "              <roadMark sOffset=\"0\" type=\"broken\" weight=\"standard\" color=\"standard\" "
                 "width=\"0.15\" laneChange=\"both\"/>\n";
        else
            o += "              <roadMark sOffset=\"0\" type=\"none\"/>\n";
        if (!sidewalk) {
            o += "              <speed sOffset=\"0\" max=\"" +
                 std::string(E.cls == RoadClass::Highway ? "80" : E.cls == RoadClass::Arterial ? "50" : "30") +
                 "\" unit=\"km/h\"/>\n";
            ++n.drivingLanes;
        } else {
            ++n.sidewalks;
        }
        o += "            </lane>\n";
    };
    o += left ? "          <left>\n" : "          <right>\n";
    if (left) {
        if (L.hasWalk(1)) laneXml(count + 1, true);
        for (int k = count; k >= 1; --k) laneXml(k, false);
    } else {
        for (int k = 1; k <= count; ++k) laneXml(k, false);
        if (L.hasWalk(-1)) laneXml(count + 1, true);
    }
    o += left ? "          </left>\n" : "          </right>\n";
}

void Writer::road(uint32_t e) {
    const EdgeLanes& L = M.edges[e];
    const StreetEdge& E = g.edges[e];
    const glm::dvec2 w = world(L.start);
    const double hdg = std::atan2(L.dir.y, L.dir.x);
    o += "  <road name=\"" + std::string(roadClassName(E.cls)) + " " + std::to_string(e) + "\" length=\"" +
         num(L.length) + "\" id=\"" + std::to_string(e) + "\" junction=\"-1\" rule=\"RHT\">\n";
    o += "    <link>\n";
    auto endLink = [&](uint32_t v, bool isSuccessor) {
        const char* tag = isSuccessor ? "successor" : "predecessor";
        if (M.nodeJunction[v] >= 0) {
            o += std::string("      <") + tag + " elementType=\"junction\" elementId=\"" +
                 std::to_string(g.edges.size() + size_t(M.nodeJunction[v])) + "\"/>\n";
        } else if (M.degree[v] == 2) {
            uint32_t f = otherEdge(e, v);
            if (f == e) return;
            o += std::string("      <") + tag + " elementType=\"road\" elementId=\"" + std::to_string(f) +
                 "\" contactPoint=\"" + (g.edges[f].a == v ? "start" : "end") + "\"/>\n";
        }
    };
    endLink(E.a, false);
    endLink(E.b, true);
    o += "    </link>\n";
    o += "    <type s=\"0\" type=\"town\"/>\n";
    o += "    <planView>\n      <geometry s=\"0\" x=\"" + num(w.x) + "\" y=\"" + num(w.y) + "\" hdg=\"" + num(hdg) +
         "\" length=\"" + num(L.length) + "\">\n        <line/>\n      </geometry>\n    </planView>\n";
    elevation(L.start, L.dir, L.length);
    o += "    <lanes>\n      <laneOffset s=\"0\" a=\"" + num(L.offset) + "\" b=\"0\" c=\"0\" d=\"0\"/>\n";
    o += "      <laneSection s=\"0\">\n";
    laneSide(L, E, true, e);
    o += "        <center>\n          <lane id=\"0\" type=\"none\" level=\"false\">\n            " + roadMarkCentre(E.cls) +
         "\n          </lane>\n        </center>\n";
    laneSide(L, E, false, e);
    o += "      </laneSection>\n    </lanes>\n  </road>\n";
    ++n.roads;
}

// Connecting roads of one junction and its <junction> element.
void Writer::junction(size_t j) {
    const Junction& J = M.junctions[j];
    const uint32_t v = J.node;
    const size_t jid = g.edges.size() + j;
    std::string jx = "  <junction id=\"" + std::to_string(jid) + "\" name=\"node " + std::to_string(v) + "\">\n";
    int connection = 0;
    for (uint32_t in : J.arms) {
        const EdgeLanes& Li = M.edges[in];
        const bool inEnd = g.edges[in].b == v;  // incoming road meets the junction with its end
        const int inLanes = inEnd ? Li.right : Li.left;
        const glm::dvec2 p0 = inEnd ? Li.end : Li.start;
        const glm::dvec2 d0 = inEnd ? Li.dir : -Li.dir;  // travel direction into the junction
        for (uint32_t out : J.arms) {
            if (out == in) continue;
            const EdgeLanes& Lo = M.edges[out];
            const bool outStart = g.edges[out].a == v;
            const int outLanes = outStart ? Lo.right : Lo.left;
            const int lanes = std::min(inLanes, outLanes);
            if (lanes < 1) continue;
            const glm::dvec2 p1 = outStart ? Lo.start : Lo.end;
            const glm::dvec2 d1 = outStart ? Lo.dir : -Lo.dir;
            // Cubic Hermite in the local frame of (p0, d0), tangents of length |p1 - p0|.
            const double chord = glm::length(p1 - p0);
            if (!(chord > 1e-6)) continue;
            const glm::dvec2 side(-d0.y, d0.x);
            auto local = [&](const glm::dvec2& q) { return glm::dvec2(glm::dot(q, d0), glm::dot(q, side)); };
            const glm::dvec2 P1 = local(p1 - p0), T0(chord, 0.0), T1 = local(d1) * chord;
            const glm::dvec2 c = 3.0 * P1 - 2.0 * T0 - T1, d = -2.0 * P1 + T0 + T1;
            // Arc length by Simpson's rule on the derivative.
            auto speed = [&](double t) { return glm::length(T0 + 2.0 * c * t + 3.0 * d * t * t); };
            const int K = 64;
            double len = 0;
            for (int k = 0; k < K; ++k) {
                double t0 = double(k) / K, t1 = double(k + 1) / K;
                len += (t1 - t0) / 6 * (speed(t0) + 4 * speed(0.5 * (t0 + t1)) + speed(t1));
            }
            const size_t rid = nextRoadId++;
            const glm::dvec2 w = world(p0);
            const double z0 = surface(p0), z1 = surface(p1);
            const double w0 = Li.laneWidth, w1 = Lo.laneWidth;
            o += "  <road name=\"junction " + std::to_string(jid) + " " + std::to_string(in) + " to " +
                 std::to_string(out) + "\" length=\"" + num(len) + "\" id=\"" + std::to_string(rid) + "\" junction=\"" +
                 std::to_string(jid) + "\" rule=\"RHT\">\n";
            o += "    <link>\n      <predecessor elementType=\"road\" elementId=\"" + std::to_string(in) +
                 "\" contactPoint=\"" + (inEnd ? "end" : "start") + "\"/>\n      <successor elementType=\"road\" elementId=\"" +
                 std::to_string(out) + "\" contactPoint=\"" + (outStart ? "start" : "end") + "\"/>\n    </link>\n";
            o += "    <type s=\"0\" type=\"town\"/>\n";
            o += "    <planView>\n      <geometry s=\"0\" x=\"" + num(w.x) + "\" y=\"" + num(w.y) + "\" hdg=\"" +
                 num(std::atan2(d0.y, d0.x)) + "\" length=\"" + num(len) + "\">\n        <paramPoly3 aU=\"0\" bU=\"" +
                 num(T0.x) + "\" cU=\"" + num(c.x) + "\" dU=\"" + num(d.x) + "\" aV=\"0\" bV=\"" + num(T0.y) + "\" cV=\"" +
                 num(c.y) + "\" dV=\"" + num(d.y) + "\" pRange=\"normalized\"/>\n      </geometry>\n    </planView>\n";
            o += "    <elevationProfile>\n      <elevation s=\"0\" a=\"" + num(z0) + "\" b=\"" + num((z1 - z0) / len) +
                 "\" c=\"0\" d=\"0\"/>\n    </elevationProfile>\n";
            // Centre lane position in this road's frame (reversed roads flip its sign).
            const double off0 = inEnd ? Li.offset : -Li.offset, off1 = outStart ? Lo.offset : -Lo.offset;
            o += "    <lanes>\n      <laneOffset s=\"0\" a=\"" + num(off0) + "\" b=\"" + num((off1 - off0) / len) +
                 "\" c=\"0\" d=\"0\"/>\n      <laneSection s=\"0\">\n        <center>\n          <lane id=\"0\" type=\"none\" "
                 "level=\"false\">\n            <roadMark sOffset=\"0\" type=\"none\"/>\n          </lane>\n        </center>\n"
                 "        <right>\n";
            jx += "    <connection id=\"" + std::to_string(connection++) + "\" incomingRoad=\"" + std::to_string(in) +
                  "\" connectingRoad=\"" + std::to_string(rid) + "\" contactPoint=\"start\">\n";
            for (int k = 1; k <= lanes; ++k) {
                const int fromId = inEnd ? -k : k, toId = outStart ? -k : k;
                o += "          <lane id=\"" + std::to_string(-k) + "\" type=\"driving\" level=\"false\">\n"
                     "            <link><predecessor id=\"" + std::to_string(fromId) + "\"/><successor id=\"" +
                     std::to_string(toId) + "\"/></link>\n            <width sOffset=\"0\" a=\"" + num(w0) + "\" b=\"" +
                     num((w1 - w0) / len) + "\" c=\"0\" d=\"0\"/>\n            <roadMark sOffset=\"0\" type=\"none\"/>\n"
                     "          </lane>\n";
                jx += "      <laneLink from=\"" + std::to_string(fromId) + "\" to=\"" + std::to_string(-k) + "\"/>\n";
            }
            jx += "    </connection>\n";
            o += "        </right>\n      </laneSection>\n    </lanes>\n  </road>\n";
            ++n.connectingRoads;
        }
    }
    jx += "  </junction>\n";
    junctionXml += jx;
    ++n.junctions;
}

Result<std::string> Writer::run(OpenDriveCounts* counts) {
    incident.assign(g.nodes.size(), {});
    glm::dvec2 lo(1e300), hi(-1e300);
    size_t valid = 0;
    for (uint32_t e = 0; e < g.edges.size(); ++e) {
        if (!M.edges[e].valid) continue;
        ++valid;
        incident[g.edges[e].a].push_back(e);
        incident[g.edges[e].b].push_back(e);
        for (const glm::dvec2& q : {g.nodes[g.edges[e].a], g.nodes[g.edges[e].b]}) {
            lo = glm::min(lo, world(q));
            hi = glm::max(hi, world(q));
        }
    }
    if (valid == 0) return Status::error("OpenDRIVE export: the street graph has no streets (no valid edge)");
    o.reserve(valid * 4096);
    o += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<OpenDRIVE>\n";
    o += "  <header revMajor=\"1\" revMinor=\"6\" name=\"vista city seed " + std::to_string(P.seed) +
         "\" version=\"1\" north=\"" + num(hi.y) + "\" south=\"" + num(lo.y) + "\" east=\"" + num(hi.x) + "\" west=\"" +
         num(lo.x) + "\" vendor=\"vista\">\n";
    o += "    <geoReference><![CDATA[" + openDriveGeoReference(P) + "]]></geoReference>\n  </header>\n";
    for (uint32_t e = 0; e < g.edges.size(); ++e)
        if (M.edges[e].valid) road(e);
    nextRoadId = g.edges.size() + M.junctions.size();
    for (size_t j = 0; j < M.junctions.size(); ++j) junction(j);
    o += junctionXml;
    o += "</OpenDRIVE>\n";
    if (counts) *counts = n;
    return std::move(o);
}

}  // namespace

std::string openDriveGeoReference(const CityParams& p) {
    const double lat0 = p.geo ? p.geo->lat0_deg : 0.0, lon0 = p.geo ? p.geo->lon0_deg : 0.0;
    return "+proj=tmerc +lat_0=" + num(lat0) + " +lon_0=" + num(lon0) + " +k_0=1 +x_0=" + num(p.origin_x) +
           " +y_0=" + num(p.origin_y) + " +ellps=WGS84 +units=m +no_defs";
}

Result<std::string> openDriveXml(const StreetGraph& g, const CityParams& params, const std::vector<Block>* blocks,
                                 OpenDriveCounts* counts) {
    Writer w(g, params, blocks);
    return w.run(counts);
}

}  // namespace vista
