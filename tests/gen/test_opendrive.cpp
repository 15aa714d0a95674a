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
#include "tests/common/run_vista.h"
#include "tests/common/temp_dir.h"

namespace fs = std::filesystem;
using namespace vista;
using vista::test::readBytes;
using vista::test::runVista;
using vista::test::TempDir;

namespace {

// ---- a minimal DOM over expat ----------------------------------------------
struct Element {
    std::string name;
    std::map<std::string, std::string> attr;
    std::vector<std::unique_ptr<Element>> children;
    Element* parent = nullptr;
    std::vector<const Element*> all(const std::string& n) const {
        std::vector<const Element*> r;
        for (const auto& c : children)
            if (c->name == n) r.push_back(c.get());
        return r;
    }
    const Element* first(const std::string& n) const {
        for (const auto& c : children)
            if (c->name == n) return c.get();
        return nullptr;
    }
    double num(const std::string& k) const {
        auto it = attr.find(k);
        return it == attr.end() ? 0.0 : std::stod(it->second);
    }
    std::string str(const std::string& k) const {
        auto it = attr.find(k);
        return it == attr.end() ? std::string() : it->second;
    }
};

std::unique_ptr<Element> parseXml(const std::string& text, std::string* error) {
    struct State {
        std::unique_ptr<Element> root;
        Element* cur = nullptr;
    } st;
    XML_Parser p = XML_ParserCreate(nullptr);
    XML_SetUserData(p, &st);
    XML_SetElementHandler(
        p,
        [](void* ud, const XML_Char* name, const XML_Char** atts) {
            auto* s = static_cast<State*>(ud);
            auto e = std::make_unique<Element>();
            e->name = name;
            for (int i = 0; atts[i]; i += 2) e->attr[atts[i]] = atts[i + 1];
            Element* raw = e.get();
            if (!s->cur) {
                s->root = std::move(e);
            } else {
                e->parent = s->cur;
                s->cur->children.push_back(std::move(e));
            }
            s->cur = raw;
        },
        [](void* ud, const XML_Char*) {
            auto* s = static_cast<State*>(ud);
            s->cur = s->cur->parent;
        });
    bool ok = XML_Parse(p, text.data(), int(text.size()), 1) == XML_STATUS_OK;
    if (!ok && error) *error = XML_ErrorString(XML_GetErrorCode(p));
    XML_ParserFree(p);
    return ok ? std::move(st.root) : nullptr;
}

// ---- test cities -------------------------------------------------------------
CityParams smallParams(uint64_t seed, double size, double hills) {
    CityParams p;
    p.seed = seed;
    p.size_m = size;
    p.detail = 0;
    p.hills_amplitude_m = hills;
    p.hills_wavelength_m = 500;
    p.origin_x = 1000.5;
    p.origin_y = -2000.25;
    return p;
}

City generated(const CityParams& p) {
    auto c = generateCity(p);
    EXPECT_TRUE(c.isOk()) << c.status().message();
    return std::move(*c);
}

City osmCity(const std::string& file) {
    CityParams p;
    p.detail = 0;
    auto g = importOsm(std::string(VISTA_TEST_DATA) + "/osm/" + file, p);
    EXPECT_TRUE(g.isOk()) << g.status().message();
    p.geo = g->geo;
    GenerateOptions o;
    o.streets = std::move(g->streets);
    auto c = generateCity(p, o);
    EXPECT_TRUE(c.isOk()) << c.status().message();
    return std::move(*c);
}

// A generated city's streets with every third edge given an odd lane count
// (3 or 5: asymmetric lanes about the centre line, OpenDRIVE laneOffset).
City oddLanes(const CityParams& p) {
    City c = generated(p);
    StreetGraph g = c.streets;
    for (size_t e = 0; e < g.edges.size(); e += 3) g.edges[e].lanes = uint8_t(g.edges[e].lanes >= 4 ? 5 : 3);
    GenerateOptions o;
    o.streets = std::move(g);
    auto r = generateCity(p, o);
    EXPECT_TRUE(r.isOk()) << r.status().message();
    return std::move(*r);
}

// ---- netconvert --------------------------------------------------------------
std::string shellOut(const std::string& cmd) {
    std::string out;
    FILE* f = ::popen(cmd.c_str(), "r");
    if (!f) return out;
    char buf[512];
    while (std::fgets(buf, sizeof buf, f)) out += buf;
    ::pclose(f);
    while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
    return out;
}

// The netconvert on PATH, or "" (then the caller skips). netconvert needs
// SUMO_HOME for its built-in type maps: set it from the install prefix (the
// data are in Debian's sumo-tools, which .ci/setup.sh installs).
std::string findNetconvert() {
    std::string path = shellOut("command -v netconvert 2>/dev/null");
    if (path.empty()) return path;
    if (!std::getenv("SUMO_HOME")) {
        std::error_code ec;
        fs::path real = fs::canonical(path, ec);
        fs::path home = (ec ? fs::path(path) : real).parent_path().parent_path() / "share" / "sumo";
        if (fs::exists(home / "data")) ::setenv("SUMO_HOME", home.c_str(), 1);
    }
    return path;
}

struct NetCheck {
    int exitCode = -1;
    int errors = 0;
    std::string log;
    std::unique_ptr<Element> net;
};

NetCheck runNetconvert(const std::string& netconvert, const std::string& xodr, const std::string& dir) {
    NetCheck r;
    const std::string net = dir + "/city.net.xml", log = dir + "/netconvert.log";
    const int st = std::system((netconvert + " --opendrive-files " + xodr + " -o " + net + " >" + log + " 2>&1").c_str());
    r.exitCode = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    r.log = readBytes(log);
    for (size_t pos = 0; (pos = r.log.find("Error", pos)) != std::string::npos; ++pos)
        if (pos == 0 || r.log[pos - 1] == '\n') ++r.errors;
    std::string err;
    r.net = parseXml(readBytes(net), &err);
    EXPECT_TRUE(r.net) << "net.xml does not parse: " << err;
    return r;
}

bool allDigits(const std::string& s) {
    if (s.empty()) return false;
    for (char c : s)
        if (c < '0' || c > '9') return false;
    return true;
}

// netconvert's net against the graph: one junction (id = the OpenDRIVE
// junction id, digits only) per node of degree >= 3; road ends without a
// link become "<road>.begin"/"<road>.end" nodes, each transition road two
// "<road>.<road>" nodes; one traffic-light program per signalised junction;
// "internal" junctions are netconvert's own (inside junctions). Every road
// becomes edge "-<id>" (right lanes) and "<id>" (left lanes) with the
// lane model's driving lane counts (sidewalks are not imported by default).
void checkNet(const City& city, const std::string& label) {
    const std::string netconvert = findNetconvert();
    if (netconvert.empty()) GTEST_SKIP() << "netconvert (SUMO) is not on PATH: install the Debian package 'sumo'";
    TempDir dir("vista_xodr");
    OpenDriveCounts n;
    auto xodr = openDriveXml(city.streets, city.params, &city.blocks, &n);
    ASSERT_TRUE(xodr.isOk()) << xodr.status().message();
    {
        std::ofstream f(dir.file("city.xodr"), std::ios::binary);
        f << *xodr;
    }
    NetCheck r = runNetconvert(netconvert, dir.file("city.xodr"), dir.path());
    EXPECT_EQ(r.exitCode, 0) << label << "\n" << r.log;
    EXPECT_EQ(r.errors, 0) << label << "\n" << r.log;
    ASSERT_TRUE(r.net);

    const LaneModel M = buildLaneModel(city.streets, city.params, &city.blocks);
    size_t graphJunctions = 0;
    for (int d : M.degree) graphJunctions += d >= 3;
    // Road ends without a link: dead ends, and both roads at a corner too
    // sharp for a transition (LaneModel::sharpCorners).
    size_t openEnds = 0;
    for (size_t e = 0; e < M.edges.size(); ++e) {
        const EdgeLanes& L = M.edges[e];
        if (!L.valid) continue;
        for (uint32_t v : {city.streets.edges[e].a, city.streets.edges[e].b}) {
            const int link = v == city.streets.edges[e].a ? L.linkA : L.linkB;
            openEnds += M.degree[size_t(v)] == 1 || (M.degree[size_t(v)] == 2 && link < 0);
        }
    }
    EXPECT_EQ(graphJunctions, M.junctions.size());
    EXPECT_EQ(n.junctions, M.junctions.size());
    size_t transitions = 0;
    for (const LinkRoad& r : M.links) transitions += r.junction < 0;
    EXPECT_EQ(n.transitions, transitions);
    size_t netJunctions = 0, netEnds = 0, netLinks = 0;
    for (const Element* j : r.net->all("junction")) {
        const std::string id = j->str("id"), type = j->str("type");
        if (type == "internal" || id.empty() || id[0] == ':') continue;
        // "<road>#<k>": netconvert splits a road where its lane count
        // changes (a lane tapering in or out inside a transition).
        if (id.find('#') != std::string::npos) continue;
        if (allDigits(id)) {
            const size_t jid = std::stoul(id);
            EXPECT_GE(jid, city.streets.edges.size()) << id;
            EXPECT_LT(jid, city.streets.edges.size() + M.junctions.size()) << id;
            ++netJunctions;
        } else if ((id.size() > 6 && id.compare(id.size() - 6, 6, ".begin") == 0) ||
                   (id.size() > 4 && id.compare(id.size() - 4, 4, ".end") == 0)) {
            ++netEnds;
        } else {
            ++netLinks;
        }
    }
    // Traffic lights: netconvert builds one traffic-light program per
    // junction whose approaches carry dynamic signals.
    std::set<int> lit;
    for (const SignalPlacement& sp : M.signals)
        if (sp.kind == SignalPlacement::Kind::TrafficLight) lit.insert(sp.junction);
    EXPECT_EQ(r.net->all("tlLogic").size(), lit.size()) << label;
    EXPECT_EQ(netJunctions, graphJunctions) << label;
    EXPECT_EQ(netEnds, openEnds) << label;
    // A transition road between two street roads: two road-to-road nodes.
    EXPECT_EQ(netLinks, 2 * transitions) << label;

    std::map<std::string, int> netLanes;
    for (const Element* e : r.net->all("edge")) {
        if (e->str("function") == "internal") continue;
        netLanes[e->str("id")] = int(e->all("lane").size());
    }
    size_t roads = 0, lanes = 0;
    for (size_t e = 0; e < M.edges.size(); ++e) {
        const EdgeLanes& L = M.edges[e];
        if (!L.valid) continue;
        ++roads;
        const StreetEdge& E = city.streets.edges[e];
        if (E.lanesForward < 0 && E.lanesBackward < 0) EXPECT_EQ(L.right + L.left, std::max<int>(E.lanes, 2)) << "edge " << e;
        EXPECT_NEAR(L.laneWidth * (L.right + L.left), carriagewayWidth(city.streets.edges[e]), 1e-9);
        const std::string rid = std::to_string(e);
        if (L.right > 0) {
            ASSERT_TRUE(netLanes.count("-" + rid)) << label << ": no net edge for road " << rid;
            EXPECT_EQ(netLanes["-" + rid], L.right) << label << " road " << rid;
        }
        if (L.left > 0) {
            ASSERT_TRUE(netLanes.count(rid)) << label << ": no net edge for road " << rid;
            EXPECT_EQ(netLanes[rid], L.left) << label << " road " << rid;
        }
        lanes += size_t(L.right + L.left);
    }
    EXPECT_EQ(n.roads, roads);
    EXPECT_EQ(n.drivingLanes, lanes);
    std::printf("[ %s ] roads %zu, transitions %zu, junctions %zu (netconvert %zu), connecting roads %zu, driving lanes %zu, "
                "traffic lights %zu at %zu junctions (netconvert programs %zu), signs %zu, crosswalks %zu, "
                "netconvert errors %d\n",
                label.c_str(), n.roads, n.transitions, n.junctions, netJunctions, n.connectingRoads, n.drivingLanes,
                n.trafficLights, lit.size(), r.net->all("tlLogic").size(), n.signs, n.crosswalks, r.errors);
}

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

TEST(OpenDrive, NetconvertReadsGeneratedCity) { checkNet(generated(smallParams(3, 600, 0)), "generated 600 m seed 3"); }

TEST(OpenDrive, NetconvertReadsHillyCity) { checkNet(generated(smallParams(7, 500, 25)), "generated 500 m seed 7, hills 25 m"); }

TEST(OpenDrive, NetconvertReadsOddLaneCounts) { checkNet(oddLanes(smallParams(5, 400, 0)), "generated 400 m seed 5, odd lane counts"); }

TEST(OpenDrive, NetconvertReadsOsmImport) { checkNet(osmCity("hard_cases.osm"), "osm hard_cases.osm"); }

// The synthetic town (tests/data/osm/town.osm: a 7 x 7 street grid with
// building footprints): many junctions, blocks with sidewalks on both sides.
TEST(OpenDrive, NetconvertReadsOsmTown) { checkNet(osmCity("town.osm"), "osm town.osm"); }

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
            const glm::dvec2 p0 = glm::dvec2(g->num("x"), g->num("y")) - origin, d(std::cos(hdg), std::sin(hdg)), nrm(-d.y, d.x);
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
                            ADD_FAILURE() << label << ": no road triangle under lane " << k << " of road " << road->str("id") << " at s " << s
                                          << " (city frame " << q.x << ", " << q.y << ")";
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
        std::printf("[ %s ] %zu lane-centre samples, worst vertical distance to the road mesh %.4f m; sidewalk lanes on "
                    "the sidewalk mesh %zu of %zu\n", label.c_str(), samples, worst, walkCovered, walkSamples);
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
    auto a = openDriveXml(city.streets, city.params, &city.blocks), b = openDriveXml(city.streets, city.params, &city.blocks);
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

TEST(OpenDrive, GenAndExportWriteTheSameBytes) {
    TempDir dir("vista_xodr_cli");
    const std::string city = dir.file("c.osgb"), a = dir.file("a.xodr"), b = dir.file("b.xodr");
    auto r = runVista("gen --size 300 --seed 4 --detail 0 -q -o " + city + " --xodr " + a);
    ASSERT_EQ(r.code, 0) << r.err;
    r = runVista("export " + city + " --xodr " + b + " -q");
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string x = readBytes(a);
    EXPECT_GT(x.size(), 1000u);
    EXPECT_EQ(x, readBytes(b));
}

TEST(OpenDrive, ExportBadInputIsExit2WithoutFile) {
    TempDir dir("vista_xodr_bad");
    const std::string out = dir.file("x.xodr");
    auto r = runVista("export " + dir.file("missing.osgb") + " --xodr " + out);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("missing.osgb"), std::string::npos) << r.err;
    r = runVista("export " + dir.file("missing.osgb") + " --xodr " + dir.file("x.txt"));
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find(".xodr"), std::string::npos) << r.err;
    r = runVista("export " + dir.file("missing.osgb") + " --xodr " + dir.file("no/such/dir/x.xodr"));
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--xodr"), std::string::npos) << r.err;
    r = runVista("export " + dir.file("missing.osgb"));
    EXPECT_EQ(r.code, 2);
    r = runVista("gen --size 300 -q -o " + dir.file("c.osgb") + " --xodr " + dir.file("c.txt"));
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--xodr"), std::string::npos) << r.err;
    EXPECT_TRUE(vista::test::listTree(dir.path()).empty());
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
        if (L.junctionB >= 0) {
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
        if (L.junctionA >= 0) {
            EXPECT_TRUE(marks.covers(at(0.7, L.laneCentre(1)))) << "stop line, edge " << e;
            ++stops;
        }
        const RoadClass cls = city.streets.edges[e].cls;
        const double s = 2.0;  // inside the first dash (dashes [0, 3] of every 9 m)
        if (L.length > 6 && M.degree[city.streets.edges[e].a] != 1) {
            if (cls == RoadClass::Highway) {
                EXPECT_TRUE(marks.covers(at(s, off + 0.15)) && marks.covers(at(s, off - 0.15))) << "double centre line " << e;
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
    std::printf("[ markings ] %zu stop lines, %zu crossings, %zu centre lines, %zu dividers checked, %zu clear lane centres; "
                "%zu marking triangles (road: %zu)\n", stops, crossings, centres, dividers, clear, markingTriangles, roadTriangles);
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
        if (E.lanesForward >= 0) EXPECT_EQ(right, E.lanesForward) << "road " << e;
        if (E.lanesBackward >= 0) EXPECT_EQ(left, E.lanesBackward) << "road " << e;
        oneWay += right == 0 || left == 0;
        ++checked;
    }
    EXPECT_GT(checked, 10u);
    EXPECT_GT(tagged, 5u);
    EXPECT_GT(oneWay, 3u);
}
