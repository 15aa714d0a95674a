// Parked cars (citygen/parked_cars.h) of a generated hilly city: the same
// seed gives the same cars, another seed other cars, a share of 0 none; no
// car overlaps a driving lane, a junction, a building, a tree's crown or
// another car, every car lies in the city square on the ground, and every
// car is meshed once, in the tile of its centre, with its own instance id.
// The overlap checks here are independent of the placement code: they sample
// each car's rectangle (built here from its model's size, position and yaw)
// densely and test the samples against the lane, footprint and crown
// geometry with their own point tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "citygen/generate.h"
#include "citygen/labels.h"
#include "citygen/lanes.h"
#include "citygen/mesh_builder.h"
#include "citygen/parked_cars.h"
#include "citygen/terrain.h"

using namespace vista;

namespace {

CityParams carParams(uint64_t seed = 11) {
    CityParams p;
    p.seed = seed;
    p.size_m = 700.0;
    p.tile_size_m = 175.0;
    p.hills_amplitude_m = 8.0;
    p.hills_wavelength_m = 500.0;
    p.parked_car_share = 0.5;
    p.threads = 2;
    return p;
}

City generate(const CityParams& p) {
    auto r = generateCity(p);
    EXPECT_TRUE(r.isOk()) << r.status().message();
    return r.isOk() ? std::move(*r) : City();
}

const City& carCity() {
    static const City city = generate(carParams());
    return city;
}

// A car's rectangle in the test's own terms: centre, unit heading, half extents.
struct Box {
    glm::dvec2 c, f, l;
    double hl, hw;
};
Box boxOf(const ParkedCar& car) {
    const CarModel& m = carModels()[car.model];
    const glm::dvec2 f(std::cos(car.yaw), std::sin(car.yaw));
    return {glm::dvec2(car.position), f, glm::dvec2(-f.y, f.x), 0.5 * m.length, 0.5 * m.width};
}

// Points on the rectangle's boundary every 0.1 m and on an interior grid.
std::vector<glm::dvec2> samples(const Box& b) {
    std::vector<glm::dvec2> out;
    const int nl = int(std::ceil(2 * b.hl / 0.1)), nw = int(std::ceil(2 * b.hw / 0.1));
    for (int i = 0; i <= nl; ++i)
        for (int j = 0; j <= nw; ++j) {
            if (i != 0 && i != nl && j != 0 && j != nw && (i % 5 != 0 || j % 5 != 0)) continue;
            const double x = -b.hl + 2 * b.hl * i / nl, y = -b.hw + 2 * b.hw * j / nw;
            out.push_back(b.c + b.f * x + b.l * y);
        }
    return out;
}

// Strictly inside the rectangle, `margin` metres in from its sides.
bool insideBox(const Box& b, const glm::dvec2& p, double margin = 0.0) {
    const glm::dvec2 d = p - b.c;
    return std::abs(glm::dot(d, b.f)) < b.hl - margin && std::abs(glm::dot(d, b.l)) < b.hw - margin;
}

// Crossing-number point-in-polygon (either orientation).
bool insidePolygon(const std::vector<glm::dvec2>& poly, const glm::dvec2& p) {
    bool in = false;
    for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
        const glm::dvec2 a = poly[i], b = poly[j];
        if ((a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x) in = !in;
    }
    return in;
}

// Strictly inside a convex quad given in either orientation, shrunk by `eps`.
bool insideQuad(const glm::dvec2 q[4], const glm::dvec2& p, double eps = 1e-3) {
    double sgn = 0;
    for (int k = 0; k < 4; ++k) {
        const glm::dvec2 a = q[k], b = q[(k + 1) % 4];
        const double len = glm::length(b - a);
        if (!(len > 1e-9)) continue;
        const double c = ((b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)) / len;
        if (std::abs(c) < eps) return false;
        if (sgn == 0) sgn = c;
        else if ((c > 0) != (sgn > 0)) return false;
    }
    return true;
}

// The driving area of the lane model as convex quads: every street road's
// carriageway along its trimmed reference line, and every link road's lanes
// between their outer borders in short steps.
std::vector<std::array<glm::dvec2, 4>> drivingQuads(const LaneModel& lm) {
    std::vector<std::array<glm::dvec2, 4>> out;
    for (const EdgeLanes& L : lm.edges) {
        if (!L.valid) continue;
        const glm::dvec2 n = L.normal() * L.halfWidth();
        out.push_back({L.start - n, L.end - n, L.end + n, L.start + n});
    }
    for (const LinkRoad& r : lm.links) {
        const int steps = std::max(1, int(std::ceil(r.length() / 0.5)));
        for (int k = 0; k < steps; ++k) {
            const double s0 = r.length() * k / steps, s1 = r.length() * (k + 1) / steps;
            auto side = [&](double s, double off) {
                const double h = r.heading(s);
                return r.point(s) + glm::dvec2(-std::sin(h), std::cos(h)) * off;
            };
            out.push_back({side(s0, r.rightBorder(s0)), side(s1, r.rightBorder(s1)), side(s1, r.leftBorder(s1)),
                           side(s0, r.leftBorder(s0))});
        }
    }
    return out;
}

double crownRadius(const City& city, const TreeInstance& t) {
    double r = 0;
    for (const auto& q : city.treePrototypes.at(t.prototype).mesh.positions)
        r = std::max(r, std::hypot(double(q.x), double(q.y)));
    return r * double(t.scale);
}

size_t carTriangles(const City& city) {
    size_t n = 0;
    for (const Tile& t : city.tiles) n += t.meshes[size_t(Material::Car)].triangleCount();
    return n;
}

}  // namespace

TEST(ParkedCars, SameSeedSameCarsOtherSeedOtherCars) {
    const City& a = carCity();
    ASSERT_GT(a.cars.size(), 20u);
    CityParams p = carParams();
    p.threads = 1;
    const City b = generate(p);
    ASSERT_EQ(a.cars.size(), b.cars.size());
    for (size_t i = 0; i < a.cars.size(); ++i) {
        EXPECT_EQ(a.cars[i].position, b.cars[i].position) << "car " << i;
        EXPECT_EQ(a.cars[i].yaw, b.cars[i].yaw) << "car " << i;
        EXPECT_EQ(a.cars[i].model, b.cars[i].model) << "car " << i;
        EXPECT_EQ(a.cars[i].colour, b.cars[i].colour) << "car " << i;
    }
    ASSERT_EQ(a.tiles.size(), b.tiles.size());
    for (size_t t = 0; t < a.tiles.size(); ++t) {
        const Mesh &ma = a.tiles[t].meshes[size_t(Material::Car)], &mb = b.tiles[t].meshes[size_t(Material::Car)];
        EXPECT_EQ(ma.positions, mb.positions) << "tile " << t;
        EXPECT_EQ(ma.colors, mb.colors) << "tile " << t;
        EXPECT_EQ(ma.ids, mb.ids) << "tile " << t;
    }
    const City c = generate(carParams(12));
    ASSERT_GT(c.cars.size(), 20u);
    std::vector<glm::dvec3> pa, pc;
    for (const auto& car : a.cars) pa.push_back(car.position);
    for (const auto& car : c.cars) pc.push_back(car.position);
    EXPECT_NE(pa, pc);
}

TEST(ParkedCars, ShareZeroGivesNoCars) {
    CityParams p = carParams();
    p.parked_car_share = 0;
    const City c = generate(p);
    EXPECT_TRUE(c.cars.empty());
    EXPECT_EQ(carTriangles(c), 0u);
    // And a larger share gives more cars than a smaller one.
    p.parked_car_share = 0.15;
    const City few = generate(p);
    EXPECT_GT(few.cars.size(), 0u);
    EXPECT_LT(few.cars.size(), carCity().cars.size());
}

TEST(ParkedCars, AlongCurbsAndInLots) {
    size_t curb = 0, lot = 0;
    for (const auto& car : carCity().cars) (car.curb ? curb : lot)++;
    EXPECT_GT(curb, 5u);
    EXPECT_GT(lot, 5u);
}

TEST(ParkedCars, NoCarOnADrivingLaneOrInAJunction) {
    const City& city = carCity();
    const LaneModel lm = buildLaneModel(city.streets, city.params, &city.blocks);
    const auto quads = drivingQuads(lm);
    ASSERT_FALSE(quads.empty());
    size_t bad = 0;
    for (size_t i = 0; i < city.cars.size(); ++i) {
        const Box b = boxOf(city.cars[i]);
        const auto pts = samples(b);
        for (const auto& q : quads) {
            glm::dvec2 lo = glm::min(glm::min(q[0], q[1]), glm::min(q[2], q[3]));
            glm::dvec2 hi = glm::max(glm::max(q[0], q[1]), glm::max(q[2], q[3]));
            if (hi.x < b.c.x - 6 || lo.x > b.c.x + 6 || hi.y < b.c.y - 6 || lo.y > b.c.y + 6) continue;
            bool hit = false;
            for (const auto& p : pts) hit = hit || insideQuad(q.data(), p);
            // A lane corner inside the car (a car across a quad's corner).
            for (const auto& c : q) hit = hit || insideBox(b, c, 1e-3);
            if (hit && ++bad < 5) ADD_FAILURE() << "car " << i << " at " << b.c.x << ", " << b.c.y << " on a lane";
        }
        for (const Junction& j : lm.junctions) {
            const glm::dvec2 n = city.streets.nodes[j.node];
            for (const auto& p : pts)
                if (glm::length(p - n) < j.radius) {
                    if (++bad < 5) ADD_FAILURE() << "car " << i << " in the junction at node " << j.node;
                    break;
                }
        }
    }
    EXPECT_EQ(bad, 0u);
}

TEST(ParkedCars, NoCarOverlapsABuildingATreeOrAnotherCar) {
    const City& city = carCity();
    size_t bad = 0;
    std::vector<Box> boxes;
    for (const auto& car : city.cars) boxes.push_back(boxOf(car));
    for (size_t i = 0; i < boxes.size(); ++i) {
        const Box& b = boxes[i];
        const auto pts = samples(b);
        for (size_t k = 0; k < city.buildings.size(); ++k) {
            const auto& fp = city.buildings[k].footprint;
            glm::dvec2 lo(1e300), hi(-1e300);
            for (const auto& q : fp) lo = glm::min(lo, q), hi = glm::max(hi, q);
            if (hi.x < b.c.x - 5 || lo.x > b.c.x + 5 || hi.y < b.c.y - 5 || lo.y > b.c.y + 5) continue;
            bool hit = false;
            for (const auto& p : pts) hit = hit || insidePolygon(fp, p);
            for (const auto& q : fp) hit = hit || insideBox(b, q);
            if (hit && ++bad < 5) ADD_FAILURE() << "car " << i << " overlaps building " << k;
        }
        for (size_t k = 0; k < city.trees.size(); ++k) {
            const TreeInstance& t = city.trees[k];
            const glm::dvec2 trunk(t.position);
            if (glm::length(trunk - b.c) > 30) continue;
            // Distance from the trunk to the rectangle, in the car's frame.
            const glm::dvec2 d = trunk - b.c;
            const double du = std::max(0.0, std::abs(glm::dot(d, b.f)) - b.hl);
            const double dv = std::max(0.0, std::abs(glm::dot(d, b.l)) - b.hw);
            if (std::hypot(du, dv) < crownRadius(city, t) - 1e-6 && ++bad < 5)
                ADD_FAILURE() << "car " << i << " under the crown of tree " << k;
        }
        for (size_t j = i + 1; j < boxes.size(); ++j) {
            if (glm::length(boxes[j].c - b.c) > 6) continue;
            bool hit = false;
            for (const auto& p : pts) hit = hit || insideBox(boxes[j], p);
            for (const auto& p : samples(boxes[j])) hit = hit || insideBox(b, p);
            if (hit && ++bad < 5) ADD_FAILURE() << "cars " << i << " and " << j << " overlap";
        }
    }
    EXPECT_EQ(bad, 0u);
}

TEST(ParkedCars, ClearOfStreetLightsAndSignalPoles) {
    CityParams p = carParams();
    p.effects.night = NightEffect{};
    p.effects.night->street_light_spacing_m = 12.0;
    const City city = generate(p);
    ASSERT_GT(city.streetLights.size(), 50u);
    ASSERT_GT(city.cars.size(), 20u);
    const LaneModel lm = buildLaneModel(city.streets, city.params, &city.blocks);
    std::vector<glm::dvec2> poles;
    for (const auto& l : city.streetLights) poles.emplace_back(l);
    for (const auto& s : lm.signals) poles.push_back(s.position);
    ASSERT_GT(poles.size(), city.streetLights.size());
    size_t bad = 0, curb = 0;
    for (size_t i = 0; i < city.cars.size(); ++i) {
        const Box b = boxOf(city.cars[i]);
        curb += city.cars[i].curb;
        for (const auto& q : poles) {
            const glm::dvec2 d = q - b.c;
            const double du = std::max(0.0, std::abs(glm::dot(d, b.f)) - b.hl);
            const double dv = std::max(0.0, std::abs(glm::dot(d, b.l)) - b.hw);
            if (std::hypot(du, dv) < 0.35 && ++bad < 5) ADD_FAILURE() << "car " << i << " at a pole";
        }
    }
    EXPECT_EQ(bad, 0u);
    EXPECT_GT(curb, 0u);
}

TEST(ParkedCars, InTheCityOnTheGround) {
    const City& city = carCity();
    const double half = 0.5 * city.params.size_m;
    bool sloped = false;
    for (const auto& car : city.cars) {
        const Box b = boxOf(car);
        for (const auto& p : samples(b)) {
            EXPECT_LE(std::abs(p.x), half);
            EXPECT_LE(std::abs(p.y), half);
        }
        const double ground = terrainHeight(city.params, b.c);
        sloped = sloped || std::abs(ground) > 0.5;
        // On the ground, or on a sidewalk (12 cm up).
        EXPECT_GE(car.position.z, ground - 1e-6);
        EXPECT_LE(car.position.z, ground + 0.13);
    }
    EXPECT_TRUE(sloped) << "the test city should be hilly";
}

TEST(ParkedCars, ModelsArePlausibleAndEachCarIsMeshedOnceWithItsId) {
    for (const CarModel& m : carModels()) {
        EXPECT_GE(m.length, 4.0);
        EXPECT_LE(m.length, 4.8);
        EXPECT_GE(m.width, 1.7);
        EXPECT_LE(m.width, 1.9);
        EXPECT_GE(m.height, 1.4);
        EXPECT_LE(m.height, 1.6);
    }
    const City& city = carCity();
    const TileGrid grid(city.params);
    std::map<uint32_t, size_t> triangles;
    std::map<uint32_t, int> tileOf;
    for (const Tile& t : city.tiles) {
        const Mesh& m = t.meshes[size_t(Material::Car)];
        ASSERT_EQ(m.ids.size(), m.positions.size());
        for (size_t k = 0; k < m.indices.size(); k += 3) {
            const uint32_t id = m.ids[m.indices[k]];
            ASSERT_EQ(instanceKind(id), InstanceKind::Car);
            ASSERT_LT(instanceIndex(id), city.cars.size());
            ++triangles[id];
            tileOf[id] = t.iy * grid.countX() + t.ix;
            const ParkedCar& car = city.cars[instanceIndex(id)];
            const CarModel& model = carModels()[car.model];
            for (int v = 0; v < 3; ++v) {
                const glm::dvec3 p = t.origin + glm::dvec3(m.positions[m.indices[k + size_t(v)]]);
                EXPECT_LE(glm::length(glm::dvec2(p) - glm::dvec2(car.position)),
                          0.5 * std::hypot(model.length, model.width) + 1e-3);
                EXPECT_GE(p.z, car.position.z - 1e-3);
                EXPECT_LE(p.z, car.position.z + model.height + 1e-3);
            }
        }
    }
    ASSERT_EQ(triangles.size(), city.cars.size());
    for (const auto& [id, n] : triangles) {
        EXPECT_EQ(n, kCarTriangles);
        EXPECT_EQ(tileOf[id], grid.tileOf(glm::dvec2(city.cars[instanceIndex(id)].position)));
    }
    EXPECT_EQ(semanticClass(Material::Car), SemanticClass::Car);
    EXPECT_STREQ(semanticClassName(SemanticClass::Car), "car");
    EXPECT_STREQ(instanceKindName(InstanceKind::Car), "car");
    EXPECT_STREQ(materialName(Material::Car), "car");
}

TEST(ParkedCars, ShareOutOfRangeNamesTheField) {
    for (const char* text : {"{\"parked_car_share\": 1.5}", "{\"parked_car_share\": -0.1}"}) {
        auto r = parseParamsJson(text, "p.json");
        ASSERT_FALSE(r.isOk());
        EXPECT_NE(r.status().message().find("'parked_car_share'"), std::string::npos) << r.status().message();
        EXPECT_NE(r.status().message().find("[0, 1]"), std::string::npos) << r.status().message();
    }
    auto ok = parseParamsJson("{\"parked_car_share\": 0}", "p.json");
    ASSERT_TRUE(ok.isOk());
    EXPECT_EQ(ok->parked_car_share, 0.0);
    EXPECT_EQ(CityParams().parked_car_share, 0.3);
}
