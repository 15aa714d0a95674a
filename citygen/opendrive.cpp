// OpenDRIVE writer: see opendrive.h.
#include "citygen/opendrive.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "citygen/lanes.h"
#include "citygen/terrain.h"
#include "citygen/traffic_signals.h"
#include "foundation/units.h"

#include <nlohmann/json.hpp>

namespace vista {

namespace {

constexpr double kRoadSurfaceLift = 0.02;  // road mesh above ground (surfaces.cpp kRoadLift)
constexpr double kElevationStep = 10.0;    // longest elevation piece
constexpr double kFiniteStep = 0.25;       // finite-difference step of slopes (metres)

std::string num(double v) {
    if (std::abs(v) < 1e-12) v = 0.0;  // no "-0"
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.12g", v);
    return buf;
}

template <class T>
std::string str(T v) {
    return std::to_string(v);
}

// Height, slope (along the edge's a -> b direction) and superelevation of a
// street road at one of its ends.
struct EndProfile {
    double z = kRoadSurfaceLift, slope = 0, superelevation = 0;
};

// Cubic a + b ds + c ds^2 + d ds^3 with the smoothstep from v0 to v1 over L
// (zero slope at both ends).
std::string smoothstepAttrs(double v0, double v1, double L) {
    const double dv = v1 - v0;
    return "a=\"" + num(v0) + "\" b=\"0\" c=\"" + num(3 * dv / (L * L)) + "\" d=\"" + num(-2 * dv / (L * L * L)) + "\"";
}

class Writer {
public:
    Writer(const StreetGraph& g, const CityParams& p, const std::vector<Block>* blocks)
        : g(g), P(p), M(buildLaneModel(g, p, blocks)) {}
    Result<std::string> run(OpenDriveCounts* counts);

private:
    bool flat() const { return !(P.hills_amplitude_m > 0); }
    double surface(const glm::dvec2& p) const { return terrainHeight(P, p) + kRoadSurfaceLift; }
    double crossSlope(const glm::dvec2& p, const glm::dvec2& dir) const;
    glm::dvec2 world(const glm::dvec2& p) const { return p + glm::dvec2(P.origin_x, P.origin_y); }
    EndProfile endProfile(uint32_t e, bool atB) const;
    void elevation(const glm::dvec2& a, const glm::dvec2& dir, double len);
    void laneSide(uint32_t e, bool left);
    void road(uint32_t e);
    void linkRoad(size_t k);
    void junction(size_t j);
    void signals(uint32_t e);
    void placeCrosswalks();
    void objects(size_t k);
    std::string roadMarkCentre(RoadClass c) const;
    std::string roadType(double speedKmh) const;
    size_t linkRoadId(size_t k) const { return g.edges.size() + M.junctions.size() + k; }
    size_t junctionId(size_t j) const { return g.edges.size() + j; }
    // Lane of the transition at the edge's end (atB) or start that links lane `id` of edge e (0: none).
    int transitionLane(uint32_t e, bool atB, int id) const;

    const StreetGraph& g;
    const CityParams& P;
    LaneModel M;
    std::string o;
    OpenDriveCounts n;
    size_t nextObject = 0, nextPlacement = 0;
    // A zebra crossing on a connecting road: object at s, outline u0..u1
    // along the road's heading there, +-halfWidth across.
    struct Crosswalk {
        double s = 0, u0 = 0, u1 = 0, halfWidth = 0;
    };
    std::vector<std::vector<Crosswalk>> hosted;  // per link road
    // A signalised junction's approach group: one <controller> (id = index).
    struct Controller {
        size_t junction;
        int group;
        std::vector<size_t> signals;
    };
    std::vector<Controller> controllers;
};

std::string Writer::roadMarkCentre(RoadClass c) const {
    const char* type = c == RoadClass::Highway ? "solid solid" : c == RoadClass::Arterial ? "solid" : "broken";
    return std::string("<roadMark sOffset=\"0\" type=\"") + type +
           "\" weight=\"standard\" color=\"standard\" width=\"0.15\" laneChange=\"none\"/>";
}

std::string Writer::roadType(double speedKmh) const {
    return "    <type s=\"0\" type=\"town\">\n      <speed max=\"" + num(speedKmh) +
           "\" unit=\"km/h\"/>\n    </type>\n";
}

double Writer::crossSlope(const glm::dvec2& p, const glm::dvec2& dir) const {
    const glm::dvec2 nrm(-dir.y, dir.x);
    const double h = kFiniteStep;
    // Left side higher by tan(angle) per metre; OpenDRIVE: positive falls to the right.
    return std::atan((terrainHeight(P, p + nrm * h) - terrainHeight(P, p - nrm * h)) / (2 * h));
}

EndProfile Writer::endProfile(uint32_t e, bool atB) const {
    EndProfile r;
    if (flat()) return r;
    const EdgeLanes& L = M.edges[e];
    const glm::dvec2 p = atB ? L.end : L.start;
    const double h = kFiniteStep;
    r.z = surface(p);
    r.slope = (surface(p + L.dir * h) - surface(p - L.dir * h)) / (2 * h);
    r.superelevation = crossSlope(p, L.dir);
    return r;
}

// Cubic Hermite pieces through the road surface height, and the terrain's
// cross slope as superelevation (linear pieces). The end values are those of
// endProfile, which the link roads continue.
void Writer::elevation(const glm::dvec2& a, const glm::dvec2& dir, double len) {
    const int pieces = std::max(1, int(std::ceil(len / kElevationStep)));
    const double h = kFiniteStep;
    auto zAt = [&](double s) { return surface(a + dir * s); };
    auto slope = [&](double s) { return (zAt(s + h) - zAt(s - h)) / (2 * h); };
    o += "    <elevationProfile>\n";
    if (flat()) {
        o += "      <elevation s=\"0\" a=\"" + num(kRoadSurfaceLift) + "\" b=\"0\" c=\"0\" d=\"0\"/>\n";
    } else {
        for (int k = 0; k < pieces; ++k) {
            double s0 = len * k / pieces, s1 = len * (k + 1) / pieces, ds = s1 - s0;
            double z0 = zAt(s0), z1 = zAt(s1), m0 = slope(s0), m1 = slope(s1);
            double c = (3 * (z1 - z0) / ds - 2 * m0 - m1) / ds;
            double d = (m0 + m1 - 2 * (z1 - z0) / ds) / (ds * ds);
            o += "      <elevation s=\"" + num(s0) + "\" a=\"" + num(z0) + "\" b=\"" + num(m0) + "\" c=\"" + num(c) +
                 "\" d=\"" + num(d) + "\"/>\n";
        }
    }
    o += "    </elevationProfile>\n    <lateralProfile>\n";
    if (flat()) {
        o += "      <superelevation s=\"0\" a=\"0\" b=\"0\" c=\"0\" d=\"0\"/>\n";
    } else {
        for (int k = 0; k < pieces; ++k) {
            double s0 = len * k / pieces, s1 = len * (k + 1) / pieces;
            double r0 = crossSlope(a + dir * s0, dir), r1 = crossSlope(a + dir * s1, dir);
            o += "      <superelevation s=\"" + num(s0) + "\" a=\"" + num(r0) + "\" b=\"" + num((r1 - r0) / (s1 - s0)) +
                 "\" c=\"0\" d=\"0\"/>\n";
        }
    }
    o += "    </lateralProfile>\n";
}

int Writer::transitionLane(uint32_t e, bool atB, int id) const {
    const int k = atB ? M.edges[e].linkB : M.edges[e].linkA;
    if (k < 0) return 0;
    const LinkRoad& r = M.links[size_t(k)];
    const bool isIn = r.in == e && (g.edges[e].b == r.node) == r.inEnd;
    for (int side = 0; side < 2; ++side) {
        const auto& lanes = side ? r.left : r.right;
        for (size_t i = 0; i < lanes.size(); ++i)
            if ((isIn ? lanes[i].from : lanes[i].to) == id) return side ? int(i) + 1 : -int(i) - 1;
    }
    return 0;
}

void Writer::laneSide(uint32_t e, bool left) {
    const EdgeLanes& L = M.edges[e];
    const StreetEdge& E = g.edges[e];
    const int count = left ? L.left : L.right;
    const int sgn = left ? 1 : -1;
    auto laneXml = [&](int k, bool sidewalk) {
        const int id = sgn * k;
        o += "          <lane id=\"" + str(id) + "\" type=\"" + (sidewalk ? "sidewalk" : "driving") +
             "\" level=\"false\">\n";
        const int pre = transitionLane(e, false, id), suc = transitionLane(e, true, id);
        if (pre || suc) {
            o += "            <link>";
            if (pre) o += "<predecessor id=\"" + str(pre) + "\"/>";
            if (suc) o += "<successor id=\"" + str(suc) + "\"/>";
            o += "</link>\n";
        }
        o += "            <width sOffset=\"0\" a=\"" + num(sidewalk ? L.sidewalk : L.laneWidth) +
             "\" b=\"0\" c=\"0\" d=\"0\"/>\n";
        if (!sidewalk && k < count)
            o += "            <roadMark sOffset=\"0\" type=\"broken\" weight=\"standard\" color=\"standard\" "
                 "width=\"0.15\" laneChange=\"both\"/>\n";
        else o += "            <roadMark sOffset=\"0\" type=\"none\" color=\"standard\"/>\n";
        if (!sidewalk) {
            o += "            <speed sOffset=\"0\" max=\"" + num(L.speedKmh) + "\" unit=\"km/h\"/>\n";
            ++n.drivingLanes;
        } else {
            ++n.sidewalks;
        }
        o += "          </lane>\n";
    };
    const bool walk = L.hasWalk(sgn);
    if (count == 0 && !walk) return;
    o += left ? "        <left>\n" : "        <right>\n";
    if (left) {
        if (walk) laneXml(count + 1, true);
        for (int k = count; k >= 1; --k) laneXml(k, false);
    } else {
        for (int k = 1; k <= count; ++k) laneXml(k, false);
        if (walk) laneXml(count + 1, true);
    }
    o += left ? "        </left>\n" : "        </right>\n";
    (void)E;
}

// The lane model's signals on a street road (SignalPlacement); signal id =
// placement index. Traffic lights are the generic OpenDRIVE code (country
// "OpenDRIVE", type 1000001: a light with three lamps), stop and yield signs
// the German codes 206 and 205. The validity names the lanes it controls
// from the lowest id to the highest.
void Writer::signals(uint32_t e) {
    std::string xml;
    for (; nextPlacement < M.signals.size() && M.signals[nextPlacement].edge == e; ++nextPlacement) {
        const SignalPlacement& sp = M.signals[nextPlacement];
        const size_t id = nextPlacement;
        const bool light = sp.kind == SignalPlacement::Kind::TrafficLight;
        const char* country = light ? "OpenDRIVE" : "DE";
        const char* type = light ? "1000001" : sp.kind == SignalPlacement::Kind::Stop ? "206" : "205";
        const char* name = light ? "traffic light" : sp.kind == SignalPlacement::Kind::Stop ? "stop" : "yield";
        const int a = sp.atB ? -1 : 1, b = sp.atB ? -sp.lanes : sp.lanes;
        xml += "      <signal s=\"" + num(sp.s) + "\" t=\"" + num(sp.t) + "\" id=\"" + str(id) + "\" name=\"" + name +
               "\" dynamic=\"" + (light ? "yes" : "no") + "\" orientation=\"" + (sp.atB ? "+" : "-") + "\" zOffset=\"" +
               num(light ? kTrafficLightBottom : kSignBottom) + "\" country=\"" + country + "\" type=\"" + type +
               "\" subtype=\"-1\" height=\"" + num(light ? kTrafficLightHeight : kSignSize) + "\" width=\"" +
               num(light ? kTrafficLightWidth : kSignSize) + "\">\n";
        xml += "        <validity fromLane=\"" + str(std::min(a, b)) + "\" toLane=\"" + str(std::max(a, b)) +
               "\"/>\n      </signal>\n";
        ++(light ? n.trafficLights : n.signs);
    }
    if (!xml.empty()) o += "    <signals>\n" + xml + "    </signals>\n";
}

// Zebra crossings where the road meshes draw them (crossingBand): in the
// junction, on one of its connecting roads that starts or ends where the
// crossing's street road meets it (the straightest that is long enough for
// the band, else the longest, the band then cut to its length). Both roads'
// reference lines meet there with the same heading or opposite ones, so the
// band keeps its place: outlined in the connecting road's frame at that end.
void Writer::placeCrosswalks() {
    hosted.assign(M.links.size(), {});
    for (uint32_t e = 0; e < M.edges.size(); ++e) {
        const EdgeLanes& L = M.edges[e];
        for (int atB = 0; atB < 2; ++atB) {
            double s0 = 0, s1 = 0;
            if (!crossingBand(L, atB != 0, s0, s1)) continue;
            const uint32_t v = atB ? g.edges[e].b : g.edges[e].a;
            const double anchor = atB ? L.length : 0.0;
            const double u0 = s0 - anchor, u1 = s1 - anchor, need = std::max(std::abs(u0), std::abs(u1));
            size_t best = M.links.size();
            double bestKey = 1e300;
            for (uint32_t k : M.nodeLinks[v]) {
                const LinkRoad& r = M.links[k];
                if (r.junction < 0 || (r.in != e && r.out != e)) continue;
                const double key = r.length() >= need ? std::abs(r.angle) : 10.0 + 1.0 / (1.0 + r.length());
                if (key < bestKey) bestKey = key, best = k;
            }
            if (best == M.links.size()) continue;
            const LinkRoad& r = M.links[best];
            const bool atStart = r.in == e;  // the band lies at the connecting road's start (else its end)
            const bool flip = atStart ? !r.inEnd : !r.outStart;
            Crosswalk c;
            c.s = atStart ? 0.0 : r.length();
            c.u0 = flip ? -u1 : u0;
            c.u1 = flip ? -u0 : u1;
            // Cut to the road's s-range.
            if (atStart) c.u1 = std::min(c.u1, r.length());
            else c.u0 = std::max(c.u0, -r.length());
            c.halfWidth = L.halfWidth();
            if (c.u1 - c.u0 > 0.1) hosted[best].push_back(c);
        }
    }
}

void Writer::objects(size_t k) {
    std::string xml;
    for (const Crosswalk& c : hosted[k]) {
        const double hw = c.halfWidth;
        xml += "      <object type=\"crosswalk\" name=\"zebra crossing\" id=\"" + str(nextObject++) + "\" s=\"" +
               num(c.s) + "\" t=\"0\" zOffset=\"0\" hdg=\"0\" pitch=\"0\" roll=\"0\" orientation=\"none\" length=\"" +
               num(c.u1 - c.u0) + "\" width=\"" + num(2 * hw) +
               "\" height=\"0\">\n        <outlines>\n          <outline id=\"0\" "
               "outer=\"true\" closed=\"true\" laneType=\"driving\">\n";
        for (auto [u, v] : {std::pair{c.u0, -hw}, {c.u1, -hw}, {c.u1, hw}, {c.u0, hw}})
            xml += "            <cornerLocal u=\"" + num(u) + "\" v=\"" + num(v) + "\" z=\"0\" height=\"0\"/>\n";
        xml += "          </outline>\n        </outlines>\n      </object>\n";
        ++n.crosswalks;
    }
    if (!xml.empty()) o += "    <objects>\n" + xml + "    </objects>\n";
}

void Writer::road(uint32_t e) {
    const EdgeLanes& L = M.edges[e];
    const StreetEdge& E = g.edges[e];
    const glm::dvec2 w = world(L.start);
    const double hdg = std::atan2(L.dir.y, L.dir.x);
    o += "  <road name=\"" + std::string(roadClassName(E.cls)) + " " + str(e) + "\" length=\"" + num(L.length) +
         "\" id=\"" + str(e) + "\" junction=\"-1\" rule=\"RHT\">\n";
    o += "    <link>\n";
    auto endLink = [&](bool atB) {
        const char* tag = atB ? "successor" : "predecessor";
        const int j = atB ? L.junctionB : L.junctionA;
        const int k = atB ? L.linkB : L.linkA;
        if (j >= 0 && !M.junctions[size_t(j)].links.empty()) {
            o += std::string("      <") + tag + " elementType=\"junction\" elementId=\"" + str(junctionId(size_t(j))) +
                 "\"/>\n";
        } else if (k >= 0) {
            const LinkRoad& r = M.links[size_t(k)];
            const bool isIn = r.in == e && (E.b == r.node) == r.inEnd;
            o += std::string("      <") + tag + " elementType=\"road\" elementId=\"" + str(linkRoadId(size_t(k))) +
                 "\" contactPoint=\"" + (isIn ? "start" : "end") + "\"/>\n";
        }
    };
    endLink(false);
    endLink(true);
    o += "    </link>\n";
    o += roadType(L.speedKmh);
    o += "    <planView>\n      <geometry s=\"0\" x=\"" + num(w.x) + "\" y=\"" + num(w.y) + "\" hdg=\"" + num(hdg) +
         "\" length=\"" + num(L.length) + "\">\n        <line/>\n      </geometry>\n    </planView>\n";
    elevation(L.start, L.dir, L.length);
    o += "    <lanes>\n      <laneOffset s=\"0\" a=\"" + num(L.offset) + "\" b=\"0\" c=\"0\" d=\"0\"/>\n";
    o += "      <laneSection s=\"0\">\n";
    laneSide(e, true);
    o += "        <center>\n          <lane id=\"0\" type=\"none\" level=\"false\">\n            " +
         roadMarkCentre(E.cls) + "\n          </lane>\n        </center>\n";
    laneSide(e, false);
    o += "      </laneSection>\n    </lanes>\n";
    signals(e);
    o += "  </road>\n";
    (void)E;
    ++n.roads;
}

// A junction's connecting road or a degree-2 transition (lanes.h LinkRoad).
void Writer::linkRoad(size_t k) {
    const LinkRoad& r = M.links[k];
    const double len = r.length();
    const bool inJunction = r.junction >= 0;
    const EdgeLanes &Li = M.edges[r.in], &Lo = M.edges[r.out];
    o += "  <road name=\"" +
         std::string(inJunction ? "junction " + str(junctionId(size_t(r.junction))) : "transition") + " " +
         str(size_t(r.in)) + " to " + str(size_t(r.out)) + "\" length=\"" + num(len) + "\" id=\"" + str(linkRoadId(k)) +
         "\" junction=\"" + (inJunction ? str(junctionId(size_t(r.junction))) : std::string("-1")) +
         "\" rule=\"RHT\">\n";
    o += "    <link>\n      <predecessor elementType=\"road\" elementId=\"" + str(size_t(r.in)) + "\" contactPoint=\"" +
         (r.inEnd ? "end" : "start") + "\"/>\n      <successor elementType=\"road\" elementId=\"" + str(size_t(r.out)) +
         "\" contactPoint=\"" + (r.outStart ? "start" : "end") + "\"/>\n    </link>\n";
    o += roadType(std::min(Li.speedKmh, Lo.speedKmh));
    // Line, arc, line.
    o += "    <planView>\n";
    double s = 0;
    auto piece = [&](double length, const std::string& shape) {
        if (!(length > 1e-9)) return;
        const glm::dvec2 w = world(r.point(s));
        o += "      <geometry s=\"" + num(s) + "\" x=\"" + num(w.x) + "\" y=\"" + num(w.y) + "\" hdg=\"" +
             num(r.heading(s)) + "\" length=\"" + num(length) + "\">\n        " + shape + "\n      </geometry>\n";
        s += length;
    };
    piece(r.line0, "<line/>");
    piece(r.arcLength, "<arc curvature=\"" + num(r.curvature) + "\"/>");
    piece(r.line1, "<line/>");
    o += "    </planView>\n";
    // Height: a cubic Hermite from the incoming road's end to the outgoing
    // road's start (values and slopes), superelevation linear between theirs
    // (both flip sign where a road runs against this road's s).
    const EndProfile a = endProfile(r.in, r.inEnd), b = endProfile(r.out, !r.outStart);
    const double z0 = a.z, z1 = b.z, m0 = r.inEnd ? a.slope : -a.slope, m1 = r.outStart ? b.slope : -b.slope;
    const double c = (3 * (z1 - z0) / len - 2 * m0 - m1) / len, d = (m0 + m1 - 2 * (z1 - z0) / len) / (len * len);
    o += "    <elevationProfile>\n      <elevation s=\"0\" a=\"" + num(z0) + "\" b=\"" + num(m0) + "\" c=\"" + num(c) +
         "\" d=\"" + num(d) + "\"/>\n    </elevationProfile>\n";
    const double r0 = r.inEnd ? a.superelevation : -a.superelevation;
    const double r1 = r.outStart ? b.superelevation : -b.superelevation;
    o += "    <lateralProfile>\n      <superelevation s=\"0\" a=\"" + num(r0) + "\" b=\"" + num((r1 - r0) / len) +
         "\" c=\"0\" d=\"0\"/>\n    </lateralProfile>\n";
    o += "    <lanes>\n      <laneOffset s=\"0\" " + smoothstepAttrs(r.offset0, r.offset1, len) + "/>\n";
    o += "      <laneSection s=\"0\">\n";
    const double speed = std::min(Li.speedKmh, Lo.speedKmh);
    auto lanesXml = [&](const std::vector<LinkRoad::Lane>& lanes, int sgn) {
        for (size_t i = 0; i < lanes.size(); ++i) {
            const size_t idx = sgn > 0 ? lanes.size() - 1 - i : i;  // left lanes outermost first
            const LinkRoad::Lane& l = lanes[idx];
            const int id = sgn * int(idx + 1);
            o += "          <lane id=\"" + str(id) + "\" type=\"" + (l.sidewalk ? "sidewalk" : "driving") +
                 "\" level=\"false\">\n";
            if (l.from || l.to) {
                o += "            <link>";
                if (l.from) o += "<predecessor id=\"" + str(l.from) + "\"/>";
                if (l.to) o += "<successor id=\"" + str(l.to) + "\"/>";
                o += "</link>\n";
            }
            o += "            <width sOffset=\"0\" " + smoothstepAttrs(l.w0, l.w1, len) + "/>\n";
            o += "            <roadMark sOffset=\"0\" type=\"none\" color=\"standard\"/>\n";
            if (!l.sidewalk) o += "            <speed sOffset=\"0\" max=\"" + num(speed) + "\" unit=\"km/h\"/>\n";
            n.taperedLanes += !l.sidewalk && (l.w0 == 0 || l.w1 == 0);
            o += "          </lane>\n";
        }
    };
    if (!r.left.empty()) {
        o += "        <left>\n";
        lanesXml(r.left, 1);
        o += "        </left>\n";
    }
    o += "        <center>\n          <lane id=\"0\" type=\"none\" level=\"false\">\n            <roadMark "
         "sOffset=\"0\" "
         "type=\"none\" color=\"standard\"/>\n          </lane>\n        </center>\n";
    if (!r.right.empty()) {
        o += "        <right>\n";
        lanesXml(r.right, -1);
        o += "        </right>\n";
    }
    o += "      </laneSection>\n    </lanes>\n";
    objects(k);
    o += "  </road>\n";
    if (inJunction) ++n.connectingRoads;
    else ++n.transitions;
}

void Writer::junction(size_t j) {
    const Junction& J = M.junctions[j];
    if (J.links.empty()) return;
    o += "  <junction id=\"" + str(junctionId(j)) + "\" name=\"node " + str(size_t(J.node)) + "\">\n";
    int connection = 0;
    for (uint32_t k : J.links) {
        const LinkRoad& r = M.links[k];
        o += "    <connection id=\"" + str(connection++) + "\" incomingRoad=\"" + str(size_t(r.in)) +
             "\" connectingRoad=\"" + str(linkRoadId(k)) + "\" contactPoint=\"start\">\n";
        for (size_t i = 0; i < r.right.size(); ++i)
            if (r.right[i].from)
                o += "      <laneLink from=\"" + str(r.right[i].from) + "\" to=\"" + str(-int(i) - 1) + "\"/>\n";
        o += "    </connection>\n";
    }
    for (size_t x = 0; x < controllers.size(); ++x)
        if (controllers[x].junction == j)
            o += "    <controller id=\"" + str(x) + "\" type=\"0\" sequence=\"" + str(controllers[x].group + 1) +
                 "\"/>\n";
    o += "  </junction>\n";
    ++n.junctions;
}

Result<std::string> Writer::run(OpenDriveCounts* counts) {
    glm::dvec2 lo(1e300), hi(-1e300);
    size_t valid = 0;
    for (uint32_t e = 0; e < g.edges.size(); ++e) {
        if (!M.edges[e].valid) continue;
        ++valid;
        for (const glm::dvec2& q : {g.nodes[g.edges[e].a], g.nodes[g.edges[e].b]}) {
            lo = glm::min(lo, world(q));
            hi = glm::max(hi, world(q));
        }
    }
    if (valid == 0) return Status::error("OpenDRIVE export: the street graph has no streets (no valid edge)");
    // One controller per approach group of a signalised junction (SignalPlacement::group).
    for (size_t j = 0; j < M.junctions.size(); ++j)
        for (int grp = 0;; ++grp) {
            Controller c{j, grp, {}};
            for (size_t i = 0; i < M.signals.size(); ++i)
                if (M.signals[i].junction == int(j) && M.signals[i].group == grp) c.signals.push_back(i);
            if (c.signals.empty()) break;
            controllers.push_back(std::move(c));
        }
    placeCrosswalks();
    o.reserve(valid * 6144);
    o += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<OpenDRIVE>\n";
    o += "  <header revMajor=\"1\" revMinor=\"6\" name=\"vista city seed " + std::to_string(P.seed) +
         "\" version=\"1\" north=\"" + num(hi.y) + "\" south=\"" + num(lo.y) + "\" east=\"" + num(hi.x) + "\" west=\"" +
         num(lo.x) + "\" vendor=\"vista\">\n";
    o += "    <geoReference><![CDATA[" + openDriveGeoReference(P) + "]]></geoReference>\n  </header>\n";
    for (uint32_t e = 0; e < g.edges.size(); ++e)
        if (M.edges[e].valid) road(e);
    for (size_t k = 0; k < M.links.size(); ++k) linkRoad(k);
    for (size_t x = 0; x < controllers.size(); ++x) {
        o += "  <controller id=\"" + str(x) + "\" name=\"junction " + str(junctionId(controllers[x].junction)) +
             " approach group " + str(controllers[x].group) + "\">\n";
        for (size_t s : controllers[x].signals) o += "    <control signalId=\"" + str(s) + "\" type=\"0\"/>\n";
        o += "  </controller>\n";
    }
    for (size_t j = 0; j < M.junctions.size(); ++j) junction(j);
    o += "</OpenDRIVE>\n";
    n.sharpCorners = M.sharpCorners;
    n.droppedTurns = M.droppedTurns;
    n.tightTurns = M.tightTurns;
    n.overlappingArms = M.overlappingArms;
    n.crossingTurns = M.crossingTurns;
    n.tightTurnsKept = M.tightTurnsKept;
    n.crossingTurnsKept = M.crossingTurnsKept;
    n.joinedEdges = M.joinedEdges;
    n.unlinkedLanes = M.unlinkedLanes;
    n.unfedLanes = M.unfedLanes;
    n.minTurnRadius = M.minTurnRadius;
    if (counts) *counts = n;
    return std::move(o);
}

}  // namespace

std::string openDriveCountsJson(const OpenDriveCounts& n) {
    nlohmann::ordered_json j;
    j["roads"] = n.roads;
    j["transitions"] = n.transitions;
    j["junctions"] = n.junctions;
    j["connecting_roads"] = n.connectingRoads;
    j["driving_lanes"] = n.drivingLanes;
    j["sidewalks"] = n.sidewalks;
    j["traffic_lights"] = n.trafficLights;
    j["signs"] = n.signs;
    j["crosswalks"] = n.crosswalks;
    j["sharp_corners"] = n.sharpCorners;
    j["dropped_turns"] = n.droppedTurns;
    j["tight_turns"] = n.tightTurns;
    j["overlapping_arms"] = n.overlappingArms;
    j["crossing_turns"] = n.crossingTurns;
    j["tight_turns_kept"] = n.tightTurnsKept;
    j["crossing_turns_kept"] = n.crossingTurnsKept;
    j["joined_edges"] = n.joinedEdges;
    j["unlinked_lanes"] = n.unlinkedLanes;
    j["unfed_lanes"] = n.unfedLanes;
    j["tapered_lanes"] = n.taperedLanes;
    j["min_turn_radius_m"] = n.minTurnRadius;
    return j.dump();
}

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
