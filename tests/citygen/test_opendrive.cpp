// OpenDRIVE export (citygen/opendrive.h) and the lane model (citygen/lanes.h):
// - SUMO netconvert (a real consumer) reads the .xodr of a generated city and
//   of OSM imports (hard_cases.osm, town.osm) with 0 errors; its junctions and per-edge lane counts
//   match the street graph (skipped when netconvert is not installed);
// - points on the lane centres, evaluated here from the XML (reference line +
//   lane widths + elevation + superelevation), lie on the road mesh of the
//   city tiles within 5 cm vertically;
// - the CLI: gen --xodr and export write the same bytes; bad input exit 2,
//   no file.
#include <gtest/gtest.h>

#include <expat.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "citygen/generate.h"
#include "citygen/lanes.h"
#include "citygen/opendrive.h"
#include "citygen/streets.h"
#include "foundation/units.h"
#include "tests/common/run_vista.h"
#include "tests/common/temp_dir.h"
#include "tests/citygen/opendrive_fixtures.h"

namespace fs = std::filesystem;
using namespace vista;
using vista::test::readBytes;
using vista::test::runVista;
using vista::test::TempDir;
namespace {
// ---- lane centres on the road mesh ------------------------------------------
double poly(const Element* e, double ds) {
    return e->num("a") + ds * (e->num("b") + ds * (e->num("c") + ds * e->num("d")));
}
// The record of `tag` in effect at s (the last whose s <= s).
double profileAt(const Element* parent, const std::string& tag, double s) {
    const Element* best = nullptr;
    for (const Element* e : parent->all(tag))
        if (e->num("s") <= s + 1e-9) best = e;
    return best ? poly(best, s - best->num("s")) : 0.0;
}

struct RoadTriangles {
    std::vector<glm::dvec3> v;  // 3 per triangle, city frame
    double cell = 20;
    std::map<std::pair<int, int>, std::vector<size_t>> grid;
    explicit RoadTriangles(const City& c, Material mat = Material::Road) {
        for (const Tile& t : c.tiles) {
            const Mesh& m = t.meshes[size_t(mat)];
            for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
                size_t id = v.size() / 3;
                glm::dvec2 lo(1e300), hi(-1e300);
                for (int k = 0; k < 3; ++k) {
                    glm::dvec3 p = glm::dvec3(m.positions[m.indices[i + k]]) + t.origin;
                    v.push_back(p);
                    lo = glm::min(lo, glm::dvec2(p));
                    hi = glm::max(hi, glm::dvec2(p));
                }
                for (int y = int(std::floor(lo.y / cell)); y <= int(std::floor(hi.y / cell)); ++y)
                    for (int x = int(std::floor(lo.x / cell)); x <= int(std::floor(hi.x / cell)); ++x)
                        grid[{x, y}].push_back(id);
            }
        }
    }
    bool covers(const glm::dvec2& p) const { return !std::isnan(heightError({p, 0.0})); }
    // Smallest |z - mesh z| over the road triangles containing p (xy, 1e-4
    // barycentric slack); NaN if none.
    double heightError(const glm::dvec3& p) const {
        auto it = grid.find({int(std::floor(p.x / cell)), int(std::floor(p.y / cell))});
        double best = std::nan("");
        if (it == grid.end()) return best;
        for (size_t id : it->second) {
            const glm::dvec3 &a = v[3 * id], &b = v[3 * id + 1], &c = v[3 * id + 2];
            double den = (b.y - c.y) * (a.x - c.x) + (c.x - b.x) * (a.y - c.y);
            if (std::abs(den) < 1e-12) continue;
            double l0 = ((b.y - c.y) * (p.x - c.x) + (c.x - b.x) * (p.y - c.y)) / den;
            double l1 = ((c.y - a.y) * (p.x - c.x) + (a.x - c.x) * (p.y - c.y)) / den;
            double l2 = 1 - l0 - l1;
            // 1e-4 of a triangle (~1 mm): points on a seam between two tiles'
            // float meshes (a crack of float rounding) count as covered.
            if (l0 < -1e-4 || l1 < -1e-4 || l2 < -1e-4) continue;
            double z = l0 * a.z + l1 * b.z + l2 * c.z, err = std::abs(z - p.z);
            if (!(err >= best)) best = err;
        }
        return best;
    }
};

}  // namespace

static void checkLaneCentres(const City& city, const std::string& label) {
    {
        auto xodr = openDriveXml(city.streets, city.params, &city.blocks);
        ASSERT_TRUE(xodr.isOk());
        std::string err;
        auto doc = parseXml(*xodr, &err);
        ASSERT_TRUE(doc) << err;
        const RoadTriangles mesh(city), walks(city, Material::Sidewalk);
        const glm::dvec2 origin(city.params.origin_x, city.params.origin_y);
        size_t samples = 0, missing = 0, walkSamples = 0, walkCovered = 0;
        double worst = 0;
        for (const Element* road : doc->all("road")) {
            // Street roads (straight lines); transitions are checked by xodr_check.py.
            if (road->str("junction") != "-1" || road->str("name").rfind("transition", 0) == 0) continue;
            const Element* g = road->first("planView")->first("geometry");
            ASSERT_TRUE(g->first("line"));
            const double len = g->num("length"), hdg = g->num("hdg");
            const glm::dvec2 p0 = glm::dvec2(g->num("x"), g->num("y")) - origin, d(std::cos(hdg), std::sin(hdg)),
                             nrm(-d.y, d.x);
            const Element* section = road->first("lanes")->first("laneSection");
            for (const char* sideName : {"left", "right"}) {
                const Element* side = section->first(sideName);
                if (!side) continue;
                // Lane centre offsets: accumulate widths outwards from the centre lane.
                std::map<int, double> width;
                std::map<int, std::string> type;
                for (const Element* lane : side->all("lane")) {
                    int id = std::stoi(lane->str("id"));
                    width[std::abs(id)] = lane->first("width")->num("a");
                    type[std::abs(id)] = lane->str("type");
                }
                const double sgn = std::string(sideName) == "left" ? 1.0 : -1.0;
                const Element* laneOffset = road->first("lanes")->first("laneOffset");
                ASSERT_TRUE(laneOffset);
                const double offset = laneOffset->num("a");  // constant on street roads
                EXPECT_EQ(laneOffset->num("b"), 0.0);
                double inner = 0;
                for (auto& [k, w] : width) {
                    const double t = offset + sgn * (inner + 0.5 * w);
                    inner += w;
                    if (type[k] == "sidewalk") {
                        // The sidewalk lane lies on the sidewalk mesh (except
                        // where a crossing street's sidewalk corner is cut).
                        for (double f : {0.25, 0.5, 0.75}) {
                            ++walkSamples;
                            walkCovered += walks.covers(p0 + d * (f * len) + nrm * t);
                        }
                    }
                    if (type[k] != "driving") continue;
                    for (double f : {0.1, 0.5, 0.9}) {
                        const double s = f * len;
                        const double z = profileAt(road->first("elevationProfile"), "elevation", s) +
                                         t * std::tan(profileAt(road->first("lateralProfile"), "superelevation", s));
                        const glm::dvec2 q = p0 + d * s + nrm * t;
                        const double e = mesh.heightError({q, z});
                        ++samples;
                        if (std::isnan(e)) {
                            ++missing;
                            ADD_FAILURE()
                                << label << ": no road triangle under lane " << k << " of road " << road->str("id")
                                << " at s " << s << " (city frame " << q.x << ", " << q.y << ")";
                            continue;
                        }
                        worst = std::max(worst, e);
                        EXPECT_LT(e, 0.05) << "road " << road->str("id") << " lane " << sgn * k << " s " << s;
                    }
                }
            }
        }
        EXPECT_GT(samples, 20u);
        if (!city.blocks.empty()) {  // (an OSM fixture may enclose no block)
            EXPECT_GT(walkSamples, 10u) << label;
        }
        EXPECT_GE(double(walkCovered), 0.95 * double(walkSamples)) << label;
        EXPECT_EQ(missing, 0u);
        std::printf(
            "[ %s ] %zu lane-centre samples, worst vertical distance to the road mesh %.4f m; sidewalk lanes on "
            "the sidewalk mesh %zu of %zu\n",
            label.c_str(), samples, worst, walkCovered, walkSamples);
    }
}

TEST(OpenDrive, LaneCentresLieOnTheRoadMesh) {
    checkLaneCentres(generated(smallParams(7, 500, 0)), "generated, flat");
    checkLaneCentres(generated(smallParams(7, 500, 25)), "generated, hills 25 m / 500 m");
    checkLaneCentres(osmCity("hard_cases.osm"), "osm hard_cases.osm");
    checkLaneCentres(osmCity("town.osm"), "osm town.osm");
    checkLaneCentres(oddLanes(smallParams(5, 400, 10)), "generated, odd lane counts, hills 10 m");
}

TEST(OpenDrive, DeterministicAndWellFormed) {
    const City city = generated(smallParams(3, 400, 10));
    auto a = openDriveXml(city.streets, city.params, &city.blocks),
         b = openDriveXml(city.streets, city.params, &city.blocks);
    ASSERT_TRUE(a.isOk());
    EXPECT_EQ(*a, *b);
    std::string err;
    auto doc = parseXml(*a, &err);
    ASSERT_TRUE(doc) << err;
    EXPECT_EQ(doc->name, "OpenDRIVE");
    const Element* header = doc->first("header");
    ASSERT_TRUE(header);
    EXPECT_EQ(header->str("revMajor"), "1");
    EXPECT_EQ(header->str("revMinor"), "6");
    EXPECT_TRUE(header->first("geoReference"));
    // Every connection names a connecting road inside its junction and lane links that exist.
    std::map<std::string, const Element*> roads;
    for (const Element* r : doc->all("road")) roads[r->str("id")] = r;
    size_t connections = 0;
    for (const Element* j : doc->all("junction")) {
        for (const Element* c : j->all("connection")) {
            ++connections;
            ASSERT_TRUE(roads.count(c->str("connectingRoad")));
            ASSERT_TRUE(roads.count(c->str("incomingRoad")));
            EXPECT_EQ(roads[c->str("connectingRoad")]->str("junction"), j->str("id"));
            EXPECT_FALSE(c->all("laneLink").empty());
        }
    }
    EXPECT_GT(connections, 0u);
    StreetGraph empty;
    EXPECT_FALSE(openDriveXml(empty, city.params, nullptr).isOk());
}

TEST(OpenDrive, GeoReferenceOfAnOsmImportIsItsProjection) {
    CityParams p;
    p.geo = GeoReference{48.1, 11.5};
    p.origin_x = 10;
    const std::string s = openDriveGeoReference(p);
    EXPECT_NE(s.find("+proj=tmerc"), std::string::npos) << s;
    EXPECT_NE(s.find("+lat_0=48.1 "), std::string::npos) << s;
    EXPECT_NE(s.find("+lon_0=11.5 "), std::string::npos) << s;
    EXPECT_NE(s.find("+x_0=10 "), std::string::npos) << s;
    EXPECT_NE(s.find("+ellps=WGS84"), std::string::npos) << s;
}

// The rendered markings follow the same lane model as the .xodr: stop lines
// across the incoming lanes before every junction, centre lines (solid on
// arterials and highways, dashed on local streets), dashed dividers between
// lanes of one direction, zebra crossings inside the junction boundary; the
// lane centres themselves stay clear.
TEST(OpenDrive, MarkingsFollowTheLaneModel) {
    const City city = generated(smallParams(3, 600, 0));
    const LaneModel M = buildLaneModel(city.streets, city.params, &city.blocks);
    const RoadTriangles marks(city, Material::Marking);
    size_t stops = 0, centres = 0, dividers = 0, crossings = 0, clear = 0;
    size_t markingTriangles = 0, roadTriangles = 0;
    for (const Tile& t : city.tiles) {
        markingTriangles += t.meshes[size_t(Material::Marking)].triangleCount();
        roadTriangles += t.meshes[size_t(Material::Road)].triangleCount();
    }
    for (size_t e = 0; e < M.edges.size(); ++e) {
        const EdgeLanes& L = M.edges[e];
        if (!L.valid || L.length < 8) continue;
        auto at = [&](double s, double t) { return L.start + L.dir * s + L.normal() * t; };
        const double lw = L.laneWidth, off = L.offset;
        // Stop lines and crossings at every junction end but a through junction's (lanes.h).
        if (stopLine(L, true)) {
            EXPECT_TRUE(marks.covers(at(L.length - 0.7, L.laneCentre(-1)))) << "stop line, edge " << e;
            ++stops;
            if (L.trimB > 2.5) {
                const double s = L.length + 0.5 * (0.3 + std::min(L.trimB - 0.5, L.sidewalk));
                int hit = 0, n = 0;
                for (double t = -L.halfWidth() + 0.05; t < L.halfWidth(); t += 0.1, ++n) hit += marks.covers(at(s, t));
                EXPECT_GT(hit, n / 4) << "crossing, edge " << e;
                EXPECT_LT(hit, 3 * n / 4) << "crossing stripes, edge " << e;
                ++crossings;
            }
        }
        if (stopLine(L, false)) {
            EXPECT_TRUE(marks.covers(at(0.7, L.laneCentre(1)))) << "stop line, edge " << e;
            ++stops;
        }
        const RoadClass cls = city.streets.edges[e].cls;
        const double s = 2.0;  // inside the first dash (dashes [0, 3] of every 9 m)
        if (L.length > 6 && M.degree[city.streets.edges[e].a] != 1) {
            if (cls == RoadClass::Highway) {
                EXPECT_TRUE(marks.covers(at(s, off + 0.15)) && marks.covers(at(s, off - 0.15)))
                    << "double centre line " << e;
                EXPECT_FALSE(marks.covers(at(s, off))) << "gap of the double line " << e;
            } else {
                EXPECT_TRUE(marks.covers(at(s, off))) << "centre line, edge " << e;
            }
            ++centres;
            if (cls != RoadClass::Arterial && cls != RoadClass::Highway) {
                EXPECT_FALSE(marks.covers(at(s + 4.5, off))) << "dash gap, edge " << e;
            }
            if (L.right >= 2) {
                EXPECT_TRUE(marks.covers(at(s, off - lw))) << "divider, edge " << e;
                EXPECT_FALSE(marks.covers(at(s + 4.5, off - lw))) << "divider gap, edge " << e;
                ++dividers;
            }
        }
        for (int id = -L.right; id <= L.left; ++id) {
            if (id == 0) continue;
            EXPECT_FALSE(marks.covers(at(0.5 * L.length, L.laneCentre(id)))) << "lane " << id << " of edge " << e;
            ++clear;
        }
    }
    EXPECT_GT(stops, 50u);
    EXPECT_GT(crossings, 20u);
    EXPECT_GT(centres, 50u);
    EXPECT_GT(dividers, 5u);
    // Modest: markings stay a small share of the road surface triangles' order of magnitude.
    EXPECT_LT(markingTriangles, 20 * roadTriangles);
    std::printf(
        "[ markings ] %zu stop lines, %zu crossings, %zu centre lines, %zu dividers checked, %zu clear lane centres; "
        "%zu marking triangles (road: %zu)\n",
        stops, crossings, centres, dividers, clear, markingTriangles, roadTriangles);
}

// The road meshes follow the lane model through junctions and bends too:
// the centres of the driving lanes of every link road (junction turns,
// degree-2 transitions) lie on the road surface.
TEST(OpenDrive, LinkRoadLanesLieOnTheRoadMesh) {
    for (const City& city : {generated(smallParams(7, 500, 0)), osmCity("town.osm"), osmCity("hard_cases.osm")}) {
        const LaneModel M = buildLaneModel(city.streets, city.params, &city.blocks);
        const RoadTriangles mesh(city);
        size_t samples = 0, missing = 0;
        for (const LinkRoad& r : M.links) {
            for (double f : {0.1, 0.5, 0.9}) {
                const double s = f * r.length(), h = r.heading(s);
                const glm::dvec2 n(-std::sin(h), std::cos(h));
                for (int side : {-1, 1}) {
                    double t = r.laneOffset(s);
                    for (const LinkRoad::Lane& l : side < 0 ? r.right : r.left) {
                        const double w = r.width(l, s);
                        if (!l.sidewalk && w > 0.5) {
                            ++samples;
                            const glm::dvec2 q = r.point(s) + n * (t + side * 0.5 * w);
                            if (!mesh.covers(q)) {
                                ++missing;
                                ADD_FAILURE() << "no road under link road " << r.in << "->" << r.out << " at s " << s;
                            }
                        }
                        t += side * w;
                    }
                }
            }
        }
        EXPECT_GT(samples, 100u);
        EXPECT_EQ(missing, 0u);
    }
}

// OSM road tags reach the simulator: every street road of lanes.osm carries
// its edge's lanes per direction and speed limit (maxspeed where tagged, the
// class default otherwise) on its <type> and on each driving lane.
TEST(OpenDrive, OsmLaneAndSpeedTagsReachTheFile) {
    const City city = osmCity("lanes.osm");
    auto xodr = openDriveXml(city.streets, city.params, &city.blocks);
    ASSERT_TRUE(xodr.isOk());
    std::string err;
    auto doc = parseXml(*xodr, &err);
    ASSERT_TRUE(doc) << err;
    size_t tagged = 0, oneWay = 0, checked = 0;
    for (const Element* road : doc->all("road")) {
        if (road->str("junction") != "-1" || road->str("name").rfind("transition", 0) == 0) continue;
        const size_t e = std::stoul(road->str("id"));
        ASSERT_LT(e, city.streets.edges.size());
        const StreetEdge& E = city.streets.edges[e];
        const double speed = E.maxspeedKmh > 0 ? double(E.maxspeedKmh) : classSpeedKmh(E.cls);
        tagged += E.maxspeedKmh > 0;
        EXPECT_NEAR(road->first("type")->first("speed")->num("max"), speed, 1e-6) << "road " << e;
        int right = 0, left = 0;
        const Element* section = road->first("lanes")->first("laneSection");
        for (const char* side : {"left", "right"}) {
            if (!section->first(side)) continue;
            for (const Element* lane : section->first(side)->all("lane")) {
                if (lane->str("type") != "driving") continue;
                (std::string(side) == "left" ? left : right)++;
                EXPECT_NEAR(lane->first("speed")->num("max"), speed, 1e-6) << "road " << e;
            }
        }
        if (E.lanesForward >= 0) { EXPECT_EQ(right, E.lanesForward) << "road " << e; }
        if (E.lanesBackward >= 0) { EXPECT_EQ(left, E.lanesBackward) << "road " << e; }
        oneWay += right == 0 || left == 0;
        ++checked;
    }
    EXPECT_GT(checked, 10u);
    EXPECT_GT(tagged, 5u);
    EXPECT_GT(oneWay, 3u);
}

// Signals a simulator reads, on a junction of four arterials whose arms leave
// at 7, 33, 74 and 215 degrees: traffic lights are the generic OpenDRIVE code,
// every validity runs from the lower lane id to the higher, each controller
// holds one approach or two whose arms are opposite within kOppositeArms
// (here 33 and 215 degrees; 7 and 74 each alone: three controllers), all
// computed from the arm angles given here; crosswalk outlines lie within the
// s-range of the road that carries them.
TEST(OpenDrive, SignalsAreReadableBySimulators) {
    const double armDeg[4] = {7, 33, 74, 215};
    StreetGraph g;
    g.nodes.push_back({0, 0});
    for (double a : armDeg) {
        g.nodes.push_back(120.0 * glm::dvec2(std::cos(a * kPi / 180), std::sin(a * kPi / 180)));
        g.edges.push_back({0, uint32_t(g.nodes.size() - 1), RoadClass::Arterial, 7.0f, 2});
    }
    CityParams p;
    p.sidewalk_m = 2.5;
    auto xml = openDriveXml(g, p, nullptr);
    ASSERT_TRUE(xml.isOk());
    std::string err;
    auto doc = parseXml(*xml, &err);
    ASSERT_TRUE(doc) << err;
    std::map<std::string, std::string> signalRoad;  // signal id -> road id
    size_t lights = 0;
    std::map<std::string, const Element*> roads;
    for (const Element* r : doc->all("road")) {
        roads[r->str("id")] = r;
        const Element* sigs = r->first("signals");
        if (!sigs) continue;
        for (const Element* s : sigs->all("signal")) {
            signalRoad[s->str("id")] = r->str("id");
            ASSERT_EQ(s->str("dynamic"), "yes");
            EXPECT_EQ(s->str("country"), "OpenDRIVE");
            EXPECT_EQ(s->str("type"), "1000001");
            const Element* v = s->first("validity");
            ASSERT_TRUE(v);
            EXPECT_LE(std::stoi(v->str("fromLane")), std::stoi(v->str("toLane")));
            ++lights;
        }
    }
    EXPECT_EQ(lights, 4u);
    // Road id = edge index; arm e points at armDeg[e] from the junction.
    auto opposite = [&](const std::string& a, const std::string& b) {
        double d = std::fmod(std::abs(armDeg[std::stoi(a)] - armDeg[std::stoi(b)]), 360.0);
        return std::abs(180.0 - d) <= 30.0;
    };
    const auto controllers = doc->all("controller");
    EXPECT_EQ(controllers.size(), 3u);
    std::set<std::string> controlled;
    for (const Element* c : controllers) {
        const auto controls = c->all("control");
        ASSERT_GE(controls.size(), 1u);
        for (size_t x = 0; x < controls.size(); ++x) {
            EXPECT_TRUE(controlled.insert(controls[x]->str("signalId")).second);
            for (size_t y = x + 1; y < controls.size(); ++y)
                EXPECT_TRUE(
                    opposite(signalRoad[controls[x]->str("signalId")], signalRoad[controls[y]->str("signalId")]))
                    << "controller " << c->str("id");
        }
    }
    EXPECT_EQ(controlled.size(), lights);
    size_t crosswalks = 0;
    for (const auto& [id, r] : roads) {
        const Element* objs = r->first("objects");
        if (!objs) continue;
        const double length = r->num("length");
        for (const Element* o : objs->all("object")) {
            if (o->str("type") != "crosswalk") continue;
            ++crosswalks;
            EXPECT_NE(r->str("junction"), "-1") << "crosswalk " << o->str("id") << " lies in the junction";
            EXPECT_EQ(o->num("hdg"), 0.0);
            for (const Element* corner : o->first("outlines")->first("outline")->all("cornerLocal")) {
                const double s = o->num("s") + corner->num("u");
                EXPECT_GE(s, -1e-9) << "road " << id << " crosswalk " << o->str("id");
                EXPECT_LE(s, length + 1e-9) << "road " << id << " crosswalk " << o->str("id");
            }
        }
    }
    EXPECT_EQ(crosswalks, 4u);
}

// A dual carriageway mapped as two one-way ways 10 m apart
// (tests/data/osm/dual_carriageway.osm): read back from the XML, every road
// along either carriageway and along the one-way side street has driving
// lanes on its right side only, as many as its way's lanes tag, and its
// reference line runs along the way's traffic (oneway=-1: against the way's
// drawing); no road there is written two-way.
TEST(OpenDrive, OsmOneWayWaysAreOneWayRoads) {
    const City city = osmCity("dual_carriageway.osm");
    auto xodr = openDriveXml(city.streets, city.params, &city.blocks);
    ASSERT_TRUE(xodr.isOk());
    std::string err;
    auto doc = parseXml(*xodr, &err);
    ASSERT_TRUE(doc) << err;
    int north = 0, south = 0, side = 0, twoWay = 0;
    for (const Element* road : doc->all("road")) {
        if (road->str("junction") != "-1" || road->str("name").rfind("transition", 0) == 0) continue;
        const Element* geometry = road->first("planView")->first("geometry");
        ASSERT_TRUE(geometry->first("line")) << "road " << road->str("id");
        const double hdg = geometry->num("hdg"), half = 0.5 * road->num("length");
        const double x = geometry->num("x") + half * std::cos(hdg) - city.params.origin_x;
        const double y = geometry->num("y") + half * std::sin(hdg) - city.params.origin_y;
        int right = 0, left = 0;
        const Element* section = road->first("lanes")->first("laneSection");
        for (const char* s : {"left", "right"}) {
            if (!section->first(s)) continue;
            for (const Element* lane : section->first(s)->all("lane"))
                if (lane->str("type") == "driving") (std::string(s) == "left" ? left : right)++;
        }
        SCOPED_TRACE("road " + road->str("id") + " at (" + std::to_string(x) + ", " + std::to_string(y) + ")");
        if (std::abs(x) < 300 && std::abs(y) > 0.5 && std::abs(y) < 6 && std::abs(std::sin(hdg)) < 0.2) {
            const bool northern = y > 0;  // lanes=2 driven east; the south: lanes=3, oneway=-1, driven west
            (northern ? north : south)++;
            EXPECT_EQ(right, northern ? 2 : 3);
            EXPECT_EQ(left, 0);
            EXPECT_GT(northern ? std::cos(hdg) : -std::cos(hdg), 0.9);
            twoWay += right > 0 && left > 0;
        } else if (std::abs(x) < 0.5 && y > 5) {  // oneway=-1 drawn north: driven south
            ++side;
            EXPECT_EQ(right, 1);
            EXPECT_EQ(left, 0);
            EXPECT_LT(std::sin(hdg), -0.9);
            twoWay += right > 0 && left > 0;
        }
    }
    EXPECT_EQ(north, 6);
    EXPECT_EQ(south, 6);
    EXPECT_GE(side, 1);
    EXPECT_EQ(twoWay, 0);
}
