// OSM buildings: tags, footprint repair, the fixture import, heights and roofs, courtyards,
// overlap with procedural buildings, PBF against XML; the generator with OSM input.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>

#include <nlohmann/json.hpp>

#include "citygen/footprint_repair.h"
#include "citygen/generate.h"
#include "citygen/geodesy.h"
#include "citygen/osm_buildings.h"
#include "citygen/polygon.h"
#include "citygen/streets.h"
#include "tests/common/temp_dir.h"
#include "tests/citygen/osm_fixtures.h"

using namespace vista;

// ---- vista gen --osm ----------------------------------------------------------------

TEST(OsmGen, GeoReferenceReachesSceneAndGeoJsonAndDropsAreReported) {
    test::TempDir dir("vista_osm_gen");
    OsmWriter w;
    const GeoPoint c{-16.8, 179.999};  // 107 m west of the antimeridian
    w.grid(c, 400, 3);
    w.way({w.node(destination(c, 0, 150)), w.rawNode(R"(lat="-16.8" lon="1e300")"), w.node(destination(c, 10, 180))});
    const std::string osm = w.write(dir, "fiji.osm");
    auto run = [&](const std::string& args) {
        const std::string cmd =
            std::string(VISTA_BINARY) + " gen " + args + " 2>" + dir.file("err.txt") + " >/dev/null";
        const int st = std::system(cmd.c_str());
        return std::make_pair(WIFEXITED(st) ? WEXITSTATUS(st) : -1, test::readBytes(dir.file("err.txt")));
    };
    auto [code, err] = run("--osm " + osm + " --size 500 --detail 0 -q -o " + dir.file("c.osgb") + " --geojson " +
                           dir.file("s.geojson"));
    ASSERT_EQ(code, 0) << err;
    EXPECT_NE(err.find("osm: dropped 1 node (1 with invalid coordinates)"), std::string::npos) << err;
    // The scene stores the geo reference with the parameters.
    const std::string scene = test::readBytes(dir.file("c.osgb"));
    EXPECT_NE(scene.find("\"projection\": \"tmerc\""), std::string::npos);
    // GeoJSON in lon/lat near the data, cut at the antimeridian where an edge crosses it.
    auto j = nlohmann::json::parse(test::readBytes(dir.file("s.geojson")));
    ASSERT_GT(j["features"].size(), 0u);
    size_t cut = 0;
    for (const auto& f : j["features"]) {
        const bool multi = f["geometry"]["type"] == "MultiLineString";
        cut += multi;
        for (const auto& line :
             multi ? f["geometry"]["coordinates"] : nlohmann::json::array({f["geometry"]["coordinates"]}))
            for (const auto& p : line) {
                EXPECT_NEAR(p[1].get<double>(), -16.8, 0.01);
                EXPECT_GT(std::abs(p[0].get<double>()), 179.99);
                EXPECT_LE(std::abs(p[0].get<double>()), 180.0);
            }
    }
    EXPECT_GT(cut, 0u);
    // Implausible extent: exit 2 with the message.
    OsmWriter wide;
    wide.grid(c, 1.5 * maxCitySize(), 2);
    std::tie(code, err) = run("--osm " + wide.write(dir, "wide.osm") + " -q -o " + dir.file("w.osgb"));
    EXPECT_EQ(code, 2);
    EXPECT_NE(err.find("the roads span"), std::string::npos) << err;
}
namespace {
// ---- buildings from OSM -------------------------------------------------------------

// The fixture's city: streets and buildings imported, then the whole pipeline.
struct OsmCity {
    OsmImport import;
    City city;
};
OsmCity osmCity(bool buildings = true) {
    CityParams p;
    p.size_m = 800;
    p.detail = 2;
    p.threads = 1;
    auto imp = importOsm(fixture("buildings.osm"), p, buildings);
    EXPECT_TRUE(imp.isOk()) << imp.status().message();
    p.geo = imp->geo;
    GenerateOptions o;
    o.streets = imp->streets;
    if (buildings) {
        o.osmBuildings = imp->buildings;
        o.osmStats = imp->buildingStats;
    }
    auto c = generateCity(p, o);
    EXPECT_TRUE(c.isOk()) << c.status().message();
    return {std::move(*imp), std::move(*c)};
}

const Building* byOsmId(const City& c, int64_t id) {
    for (const auto& b : c.buildings)
        if (b.source != BuildingSource::Procedural && b.osm_id == id) return &b;
    return nullptr;
}

}  // namespace

TEST(OsmBuildingTags, LengthsLevelsAndRoofShapes) {
    EXPECT_DOUBLE_EQ(parseOsmLength("12"), 12.0);
    EXPECT_DOUBLE_EQ(parseOsmLength("12 m"), 12.0);
    EXPECT_DOUBLE_EQ(parseOsmLength("12.5m"), 12.5);
    EXPECT_DOUBLE_EQ(parseOsmLength(" 7,5 "), 7.5);
    EXPECT_NEAR(parseOsmLength("40'"), 40 * 0.3048, 1e-12);
    EXPECT_NEAR(parseOsmLength("40 ft"), 40 * 0.3048, 1e-12);
    EXPECT_NEAR(parseOsmLength("12'6\""), 12.5 * 0.3048, 1e-12);
    for (const char* bad : {"", "tall", "-3", "1e300", "12 km", "12'13\"", "5000", "nan", "12..5"})
        EXPECT_TRUE(std::isnan(parseOsmLength(bad))) << bad;
    EXPECT_DOUBLE_EQ(parseOsmLevels("4"), 4.0);
    EXPECT_DOUBLE_EQ(parseOsmLevels("2.5"), 2.5);
    for (const char* bad : {"", "four", "-1", "3 floors", "1000"}) EXPECT_TRUE(std::isnan(parseOsmLevels(bad))) << bad;
    EXPECT_EQ(parseOsmRoofShape("gabled"), OsmRoofShape::Gabled);
    EXPECT_EQ(parseOsmRoofShape("gambrel"), OsmRoofShape::Gabled);
    EXPECT_EQ(parseOsmRoofShape("hipped"), OsmRoofShape::Hipped);
    EXPECT_EQ(parseOsmRoofShape("pyramidal"), OsmRoofShape::Hipped);
    EXPECT_EQ(parseOsmRoofShape("flat"), OsmRoofShape::Flat);
    EXPECT_EQ(parseOsmRoofShape("skillion"), OsmRoofShape::Flat);
    EXPECT_EQ(parseOsmRoofShape("banana"), OsmRoofShape::Flat);
    EXPECT_EQ(parseOsmRoofShape(""), OsmRoofShape::Absent);
}

TEST(FootprintRepair, BowTieSplitsIntoItsLargerHalfAndHolesTriangulate) {
    bool split = false;
    // Bow-tie whose left lobe (area 10 * 4 / 2 ... ) is larger: crossing at (4, 2).
    const Polygon2 bow{{0, 0}, {10, 5}, {10, 0}, {0, 4}};
    const Polygon2 r = makeSimpleRing(bow, split);
    EXPECT_TRUE(split);
    ASSERT_GE(r.size(), 3u);
    EXPECT_TRUE(isSimpleRingExact(r));
    EXPECT_GT(signedArea(r), 0.0);
    // Independent: the crossing of (0,0)-(10,5) and (10,0)-(0,4) is at x = 40/9; lobes are triangles.
    const double xc = 40.0 / 9.0, left = 0.5 * 4.0 * xc, right = 0.5 * 5.0 * (10.0 - xc);
    EXPECT_NEAR(signedArea(r), std::max(left, right), 1e-9);
    // A simple ring comes back unchanged (counter-clockwise), a degenerate one empty.
    const Polygon2 sq{{0, 0}, {0, 10}, {10, 10}, {10, 0}};
    const Polygon2 s2 = makeSimpleRing(sq, split);
    EXPECT_FALSE(split);
    EXPECT_NEAR(signedArea(s2), 100.0, 1e-12);
    EXPECT_TRUE(makeSimpleRing({{0, 0}, {1, 1}, {2, 2}}, split).empty());
    EXPECT_TRUE(makeSimpleRing({{0, 0}, {1, std::nan("")}, {2, 0}}, split).empty());
    // Nesting: strictly inside, touching, outside.
    const Polygon2 big{{0, 0}, {20, 0}, {20, 20}, {0, 20}};
    const Polygon2 hole{{5, 5}, {5, 15}, {15, 15}, {15, 5}};  // clockwise
    EXPECT_TRUE(ringStrictlyInside(hole, big));
    EXPECT_FALSE(ringStrictlyInside(Polygon2{{0, 5}, {5, 15}, {15, 5}}, big));
    EXPECT_FALSE(ringStrictlyInside(Polygon2{{25, 5}, {25, 15}, {30, 5}}, big));
    EXPECT_TRUE(ringsDisjoint(hole, Polygon2{{16, 16}, {16, 19}, {19, 16}}));
    EXPECT_FALSE(ringsDisjoint(hole, Polygon2{{6, 6}, {6, 9}, {9, 6}}));
    // Triangulation: area 400 - 100, no triangle covers the hole's centre.
    const auto tris = triangulateWithHoles(big, {hole});
    ASSERT_FALSE(tris.empty());
    double area = 0;
    for (const auto& t : tris) {
        const double a = signedArea({t[0], t[1], t[2]});
        EXPECT_GT(a, 0.0);
        area += a;
        EXPECT_FALSE(pointInPolygon({t[0], t[1], t[2]}, {10, 10}));
    }
    EXPECT_NEAR(area, 300.0, 1e-9);
}

TEST(OsmBuildings, FixtureImportsRepairsAndSkipsPerReason) {
    CityParams p;
    p.size_m = 800;
    auto r = importOsm(fixture("buildings.osm"), p, true);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    const OsmBuildingStats& s = r->buildingStats;
    EXPECT_TRUE(s.enabled);
    EXPECT_EQ(s.ways, 11u);
    EXPECT_EQ(s.relations, 2u);
    EXPECT_EQ(s.candidates, 13u);
    EXPECT_EQ(s.imported, 10u);
    EXPECT_EQ(r->buildings.size(), 10u);
    // Repaired (and imported).
    EXPECT_EQ(s.duplicateNodes, 1u);     // way 205
    EXPECT_EQ(s.unclosedRings, 1u);      // way 204
    EXPECT_EQ(s.selfIntersections, 1u);  // way 203 (bow-tie)
    EXPECT_EQ(s.innerRingsDropped, 1u);  // relation 301
    // Skipped, by reason.
    EXPECT_EQ(s.missingNodes, 1u);  // way 206
    EXPECT_EQ(s.tooSmall, 1u);      // way 207
    EXPECT_EQ(s.tooFewNodes, 1u);   // way 208
    EXPECT_EQ(s.selfIntersecting, 0u);
    EXPECT_EQ(s.outsideCity, 0u);
    EXPECT_EQ(s.noOuterRing, 0u);
    EXPECT_EQ(s.candidates, s.imported + s.missingNodes + s.tooSmall + s.tooFewNodes + s.selfIntersecting +
                                s.outsideCity + s.noOuterRing);
    // Every footprint simple and counter-clockwise; holes clockwise, strictly inside.
    size_t withHoles = 0;
    for (const auto& f : r->buildings) {
        EXPECT_TRUE(isSimpleRingExact(f.outer)) << f.osm_id;
        EXPECT_GT(signedArea(f.outer), kOsmMinFootprintArea_m2) << f.osm_id;
        for (const auto& h : f.holes) {
            EXPECT_LT(signedArea(h), 0.0);
            EXPECT_TRUE(ringStrictlyInside(h, f.outer));
        }
        withHoles += f.holes.empty() ? 0 : 1;
        if (f.osm_id == 205) { EXPECT_EQ(f.outer.size(), 4u); }
        if (f.osm_id == 204) { EXPECT_EQ(f.outer.size(), 4u); }
        if (f.osm_id == 203) { EXPECT_EQ(f.outer.size(), 3u); }  // one lobe of the bow-tie
    }
    EXPECT_EQ(withHoles, 1u);
    // The same streets with buildings off, and no buildings read.
    auto off = importOsm(fixture("buildings.osm"), p, false);
    ASSERT_TRUE(off.isOk());
    EXPECT_TRUE(off->buildings.empty());
    EXPECT_FALSE(off->buildingStats.enabled);
    EXPECT_EQ(off->streets.edges.size(), r->streets.edges.size());
    // A city too small for the buildings: they are skipped as outside the city, never an error
    // (the city still holds roads: they are clipped to its square).
    p.size_m = 200;
    auto tiny = importOsm(fixture("buildings.osm"), p, true);
    ASSERT_TRUE(tiny.isOk()) << tiny.status().message();
    EXPECT_GT(tiny->buildingStats.outsideCity, 0u);
    for (const auto& f : tiny->buildings)
        for (const auto& q : f.outer) EXPECT_LE(std::max(std::abs(q.x), std::abs(q.y)), 100.0);
}

TEST(OsmBuildings, HeightsAndRoofsFollowTheTags) {
    const OsmCity oc = osmCity();
    const City& c = oc.city;
    const double storey = c.params.floor_height_m;
    auto top = [](const Building& b) { return b.height + b.roof_height; };
    struct Want {
        int64_t id;
        double top;
    };
    // Total heights from `height` (metres, "m" suffix, feet): independent of the parser.
    for (const Want& w :
         {Want{200, 12.0}, Want{203, 12.5}, Want{205, 40 * 0.3048}, Want{214, 6.0}, Want{300, 15.0}, Want{202, 9.0}}) {
        const Building* b = byOsmId(c, w.id);
        ASSERT_NE(b, nullptr) << w.id;
        EXPECT_NEAR(top(*b), w.top, 1e-9) << w.id;
        EXPECT_EQ(b->lot, kNoLot);
    }
    // building:levels x storey height.
    EXPECT_NEAR(byOsmId(c, 201)->height, 4 * storey, 1e-9);
    EXPECT_EQ(byOsmId(c, 201)->floors, 4);
    EXPECT_NEAR(byOsmId(c, 204)->height, 3 * storey, 1e-9);
    // Gabled with roof:height 3 on height 9: eaves at 6.
    const Building* g = byOsmId(c, 202);
    EXPECT_EQ(g->roof, RoofType::Gabled);
    EXPECT_NEAR(g->roof_height, 3.0, 1e-9);
    EXPECT_NEAR(g->height, 6.0, 1e-9);
    EXPECT_EQ(g->floors, 2);
    // Hipped on a simple footprint (its stray inner ring was dropped).
    const Building* h = byOsmId(c, 301);
    EXPECT_EQ(h->roof, RoofType::Hipped);
    EXPECT_TRUE(h->holes.empty());
    EXPECT_NEAR(h->height, 2 * storey, 1e-9);
    EXPECT_GT(h->roof_height, 0.0);
    // The courtyard building is flat; the untagged one procedural but positive.
    EXPECT_EQ(byOsmId(c, 300)->roof, RoofType::Flat);
    EXPECT_EQ(byOsmId(c, 300)->holes.size(), 1u);
    EXPECT_GT(byOsmId(c, 209)->height, 0.0);
    EXPECT_EQ(c.osmBuildings.heightFromTag, 6u);     // 200 202 203 205 214 300
    EXPECT_EQ(c.osmBuildings.heightFromLevels, 3u);  // 201 204 301
    EXPECT_EQ(c.osmBuildings.heightProcedural, 1u);  // 209
    EXPECT_EQ(c.osmBuildings.roofFromTag, 2u);       // 202 301
    EXPECT_EQ(c.osmBuildings.roofFallbackFlat, 0u);
}

TEST(OsmBuildings, CourtyardStaysOpen) {
    const OsmCity oc = osmCity();
    const City& c = oc.city;
    const Building* b = byOsmId(c, 300);
    ASSERT_NE(b, nullptr);
    ASSERT_EQ(b->holes.size(), 1u);
    const glm::dvec2 yard = centroid(b->holes[0]);
    ASSERT_TRUE(pointInPolygon(b->footprint, yard));
    // No building's solid (outer ring minus its holes) holds the courtyard point.
    for (const auto& o : c.buildings) {
        bool inHole = false;
        for (const auto& h : o.holes) inHole = inHole || pointInPolygon(h, yard);
        EXPECT_FALSE(pointInPolygon(o.footprint, yard) && !inHole) << o.osm_id;
    }
    // No roof triangle covers it; some roof triangles lie around it (the roof exists).
    size_t roofTris = 0, near = 0;
    for (const auto& t : c.tiles) {
        const Mesh& m = t.meshes[size_t(Material::Roof)];
        for (size_t k = 0; k + 2 < m.indices.size(); k += 3) {
            Polygon2 tri;
            for (int v = 0; v < 3; ++v)
                tri.push_back(glm::dvec2(t.origin) + glm::dvec2(m.positions[m.indices[k + size_t(v)]]));
            ++roofTris;
            if (std::abs(signedArea(tri)) < 1e-9) continue;
            EXPECT_FALSE(pointInPolygon(tri, yard));
            near += glm::length(centroid(tri) - yard) < 40.0 ? 1 : 0;
        }
    }
    EXPECT_GT(roofTris, 0u);
    EXPECT_GE(near, 4u);
    // Walls stand around the courtyard: wall vertices on the inner ring.
    // Faces of those walls (normal across the ring edge) face into the courtyard (the yard is convex).
    size_t onHole = 0, facingIn = 0;
    const Polygon2& ring = b->holes[0];
    for (const auto& t : c.tiles) {
        const Mesh& m = t.meshes[size_t(Material::Wall)];
        for (size_t v = 0; v < m.positions.size(); ++v) {
            const glm::dvec2 p = glm::dvec2(t.origin) + glm::dvec2(m.positions[v]);
            for (size_t k = 0; k < ring.size(); ++k) {
                const glm::dvec2 a = ring[k], e = ring[(k + 1) % ring.size()];
                if (pointSegmentDistance(p, a, e) >= 1e-3) continue;
                ++onHole;
                const glm::dvec2 n(m.normals[v].x, m.normals[v].y), dir = glm::normalize(e - a);
                if (glm::length(n) > 0.9 && std::abs(glm::dot(n, dir)) < 0.1) {
                    EXPECT_GT(glm::dot(n, yard - p), 0.0) << "a courtyard wall faces away from the courtyard";
                    ++facingIn;
                }
                break;
            }
        }
    }
    EXPECT_GT(onHole, 16u);
    EXPECT_GT(facingIn, 8u);
}

TEST(OsmBuildings, NoProceduralBuildingOverlapsAnImportedOne) {
    const OsmCity oc = osmCity();
    const City& c = oc.city;
    std::vector<const Building*> imported, procedural;
    for (const auto& b : c.buildings) (b.source == BuildingSource::Procedural ? procedural : imported).push_back(&b);
    EXPECT_EQ(imported.size(), 10u);
    EXPECT_GT(c.osmBuildings.lotsDropped, 0u);
    EXPECT_GE(c.osmBuildings.onCarriageway, 1u);  // way 214 stands on South Street
    for (const auto* p : procedural)
        for (const auto* i : imported) EXPECT_FALSE(polygonsOverlap(p->footprint, i->footprint, 1e-6)) << i->osm_id;
    // Without OSM buildings the same streets carry more procedural buildings and no imported one.
    const OsmCity off = osmCity(false);
    EXPECT_FALSE(off.city.osmBuildings.enabled);
    for (const auto& b : off.city.buildings) EXPECT_EQ(b.source, BuildingSource::Procedural);
    EXPECT_GT(off.city.buildings.size(), procedural.size());
    EXPECT_GE(off.city.lots.size(), c.lots.size() + c.osmBuildings.lotsDropped);
}

TEST(OsmGen, BuildingsAreDeterministicCountedAndCanBeTurnedOff) {
    test::TempDir dir("vista_osm_buildings");
    auto run = [&](const std::string& args) {
        const std::string cmd = std::string(VISTA_BINARY) + " gen --osm " + fixture("buildings.osm") + " --size 800 " +
                                args + " 2>" + dir.file("err.txt") + " >/dev/null";
        const int st = std::system(cmd.c_str());
        return std::make_pair(WIFEXITED(st) ? WEXITSTATUS(st) : -1, test::readBytes(dir.file("err.txt")));
    };
    auto [code, err] = run("-q -o " + dir.file("a.osgb") + " --stats " + dir.file("a.json"));
    ASSERT_EQ(code, 0) << err;
    EXPECT_NE(err.find("osm: skipped 3 of 13 building footprints"), std::string::npos) << err;
    std::tie(code, err) = run("-q --threads 2 -o " + dir.file("b.osgb"));
    ASSERT_EQ(code, 0) << err;
    const std::string a = test::readBytes(dir.file("a.osgb")), b = test::readBytes(dir.file("b.osgb"));
    ASSERT_FALSE(a.empty());
    EXPECT_TRUE(a == b) << "the same input gave different bytes";
    const auto j = nlohmann::json::parse(test::readBytes(dir.file("a.json")));
    ASSERT_TRUE(j.contains("osm_buildings"));
    const auto& o = j["osm_buildings"];
    EXPECT_EQ(o["imported"], 10);
    EXPECT_EQ(o["candidates"], 13);
    EXPECT_EQ(o["skipped"]["missing_nodes"], 1);
    EXPECT_EQ(o["skipped"]["too_small"], 1);
    EXPECT_EQ(o["skipped"]["too_few_nodes"], 1);
    EXPECT_EQ(o["repaired"]["self_intersections"], 1);
    EXPECT_EQ(o["repaired"]["unclosed_rings"], 1);
    EXPECT_EQ(o["repaired"]["duplicate_nodes"], 1);
    EXPECT_EQ(o["repaired"]["inner_rings_dropped"], 1);
    EXPECT_GE(j["buildings"].get<int>(), 10);
    // Off: no import, no stats object, different city.
    std::tie(code, err) = run("-q --osm-buildings off -o " + dir.file("c.osgb") + " --stats " + dir.file("c.json"));
    ASSERT_EQ(code, 0) << err;
    EXPECT_FALSE(nlohmann::json::parse(test::readBytes(dir.file("c.json"))).contains("osm_buildings"));
    EXPECT_FALSE(test::readBytes(dir.file("c.osgb")) == a);
    // A bad value: exit 2 naming the option.
    std::tie(code, err) = run("-q --osm-buildings maybe -o " + dir.file("d.osgb"));
    EXPECT_EQ(code, 2);
    EXPECT_NE(err.find("--osm-buildings"), std::string::npos) << err;
}

TEST(FootprintRepair, RandomRingsGiveSimpleCounterClockwiseRingsOrNothing) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-20.0, 20.0);
    std::uniform_int_distribution<int> count(3, 24);
    size_t repaired = 0, kept = 0;
    for (int k = 0; k < 400; ++k) {
        Polygon2 ring;
        const int n = count(rng);
        for (int i = 0; i < n; ++i) {
            // Snap some vertices to a coarse grid, so touching and collinear cases occur.
            glm::dvec2 p(u(rng), u(rng));
            if (i % 3 == 0) p = glm::round(p / 10.0) * 10.0;
            ring.push_back(p);
        }
        if (k % 5 == 0) ring.push_back(ring[size_t(n / 2)]);  // a repeated vertex further on
        bool split = false;
        const Polygon2 r = makeSimpleRing(ring, split);
        if (r.empty()) continue;
        ++kept;
        repaired += split ? 1 : 0;
        EXPECT_TRUE(isSimpleRingExact(r)) << k;
        EXPECT_GT(signedArea(r), 0.0) << k;
        // Every vertex of the result is an input vertex or lies on an input edge (a split point).
        for (const auto& q : r) {
            double best = 1e300;
            for (size_t i = 0; i < ring.size(); ++i)
                best = std::min(best, pointSegmentDistance(q, ring[i], ring[(i + 1) % ring.size()]));
            EXPECT_LT(best, 1e-9) << k;
        }
    }
    EXPECT_GT(kept, 300u);
    EXPECT_GT(repaired, 200u);
}

TEST(OsmBuildings, PbfGivesTheSameFootprintsAsXml) {
    // buildings.osm.pbf: buildings.osm converted to PBF by libosmium's writer.
    CityParams p;
    p.size_m = 800;
    auto x = importOsm(fixture("buildings.osm"), p, true), b = importOsm(fixture("buildings.osm.pbf"), p, true);
    ASSERT_TRUE(x.isOk() && b.isOk());
    ASSERT_EQ(x->buildings.size(), b->buildings.size());
    for (size_t i = 0; i < x->buildings.size(); ++i) {
        EXPECT_EQ(x->buildings[i].osm_id, b->buildings[i].osm_id);
        EXPECT_EQ(x->buildings[i].outer, b->buildings[i].outer);
        EXPECT_EQ(x->buildings[i].holes, b->buildings[i].holes);
    }
    EXPECT_EQ(x->buildingStats.missingNodes, b->buildingStats.missingNodes);
    EXPECT_EQ(x->buildingStats.innerRingsDropped, b->buildingStats.innerRingsDropped);
}
