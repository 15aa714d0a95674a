// Signals in the scene (citygen/traffic_signals.h) of a generated city with
// traffic lights, stop and yield signs (tests/common/signal_city.h): every
// signal of the lane model stands in exactly one tile (the tile of its pole)
// with its instance id and material, its pole rises at its position from the
// terrain, its head is in front of the pole and its front faces (wound
// counter-clockwise toward the traffic) face SignalPlacement::facing; the
// counts per kind equal the lane model's; the meshes are deterministic.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "citygen/generate.h"
#include "citygen/labels.h"
#include "citygen/lanes.h"
#include "citygen/mesh_builder.h"
#include "citygen/terrain.h"
#include "citygen/traffic_signals.h"
#include "foundation/units.h"
#include "tests/common/signal_city.h"

using namespace vista;

namespace {

struct Tri {
    glm::dvec3 p[3];
    glm::dvec3 centroid() const { return (p[0] + p[1] + p[2]) / 3.0; }
    glm::dvec3 cross() const { return glm::cross(p[1] - p[0], p[2] - p[0]); }  // winding normal, length = 2 area
};

// The triangles of instance `id` in `mesh` (every vertex of a triangle carries the id), city frame.
std::vector<Tri> trianglesOf(const Mesh& mesh, const glm::dvec3& origin, uint32_t id) {
    std::vector<Tri> out;
    if (mesh.ids.size() != mesh.positions.size()) return out;
    for (size_t k = 0; k + 2 < mesh.indices.size(); k += 3) {
        const uint32_t a = mesh.indices[k], b = mesh.indices[k + 1], c = mesh.indices[k + 2];
        if (mesh.ids[a] != id) continue;
        EXPECT_EQ(mesh.ids[b], id);
        EXPECT_EQ(mesh.ids[c], id);
        out.push_back({{origin + glm::dvec3(mesh.positions[a]), origin + glm::dvec3(mesh.positions[b]),
                        origin + glm::dvec3(mesh.positions[c])}});
    }
    return out;
}

const City& signalCity() {
    static const City city = [] {
        GenerateOptions o;
        o.streets = test::signalStreets();
        auto r = generateCity(test::signalCityParams(), o);
        EXPECT_TRUE(r.isOk()) << r.status().message();
        return r.isOk() ? std::move(*r) : City();
    }();
    return city;
}

}  // namespace

TEST(TrafficSignals, EverySignalStandsInOneTileFacingItsTraffic) {
    const City& city = signalCity();
    ASSERT_FALSE(city.tiles.empty());
    const LaneModel lanes = buildLaneModel(city.streets, city.params, &city.blocks);
    std::map<SignalPlacement::Kind, size_t> kinds;
    for (const auto& s : lanes.signals) ++kinds[s.kind];
    // The graph is made to have all three kinds: lights at the crossing of
    // four arterials, stop signs on the two locals of the 4-arm junction,
    // yield signs on the two locals of the tee.
    EXPECT_EQ(kinds[SignalPlacement::Kind::TrafficLight], 4u);
    EXPECT_EQ(kinds[SignalPlacement::Kind::Stop], 2u);
    EXPECT_EQ(kinds[SignalPlacement::Kind::Yield], 2u);

    // Every signal id present in the tiles, in which tile and with which material.
    std::map<uint32_t, std::vector<std::pair<size_t, Material>>> seen;
    for (size_t t = 0; t < city.tiles.size(); ++t)
        for (int m = 0; m < kMaterialCount; ++m) {
            const Mesh& mesh = city.tiles[t].meshes[size_t(m)];
            for (uint32_t id : mesh.ids) {
                const InstanceKind k = instanceKind(id);
                if (k != InstanceKind::TrafficLight && k != InstanceKind::TrafficSign) continue;
                auto& v = seen[id];
                if (v.empty() || v.back() != std::make_pair(t, Material(m))) v.emplace_back(t, Material(m));
            }
        }
    EXPECT_EQ(seen.size(), lanes.signals.size()) << "one instance per signal, no other signal instances";

    const TileGrid grid(city.params);
    for (size_t i = 0; i < lanes.signals.size(); ++i) {
        const SignalPlacement& s = lanes.signals[i];
        const bool light = s.kind == SignalPlacement::Kind::TrafficLight;
        const uint32_t id = makeInstanceId(light ? InstanceKind::TrafficLight : InstanceKind::TrafficSign, i);
        const Material mat = light ? Material::TrafficLight : Material::TrafficSign;
        ASSERT_EQ(seen[id].size(), 1u) << "signal " << i << ": exactly one tile and material";
        const auto [t, m] = seen[id][0];
        EXPECT_EQ(m, mat) << i;
        const Tile& tile = city.tiles[t];
        EXPECT_EQ(tile.iy * grid.countX() + tile.ix, grid.tileOf(s.position))
            << "signal " << i << ": the tile of its pole";
        const std::vector<Tri> tris = trianglesOf(tile.meshes[size_t(mat)], tile.origin, id);
        ASSERT_FALSE(tris.empty()) << i;

        // The pole: below the head every vertex is within the pole's half
        // diagonal of the position, the lowest on the terrain.
        const double ground = terrainHeight(city.params, s.position);
        const double headBottom = light ? kTrafficLightBottom : kSignBottom;
        double lowest = 1e300, highest = -1e300;
        int below = 0;
        for (const Tri& tr : tris)
            for (const auto& p : tr.p) {
                lowest = std::min(lowest, p.z);
                highest = std::max(highest, p.z);
                if (p.z < ground + headBottom - 0.01) {
                    ++below;
                    EXPECT_LT(glm::length(glm::dvec2(p) - s.position), 0.5 * kSignalPoleWidth * std::sqrt(2.0) + 1e-3)
                        << i;
                }
            }
        EXPECT_GT(below, 4) << "signal " << i << " has a pole";
        EXPECT_NEAR(lowest, ground, 1e-3) << i;
        EXPECT_GT(highest - ground, light ? 3.3 : 2.4) << i;
        EXPECT_LT(highest - ground, 3.6) << i;

        // The head: in front of the pole (toward the traffic); its frontmost
        // triangles (the lamp or sign faces) are wound toward the traffic.
        const glm::dvec3 f(s.facing, 0.0);
        const glm::dvec3 base(s.position, ground);
        double front = -1e300, headArea = 0;
        glm::dvec3 headCentre(0.0);
        for (const Tri& tr : tris) {
            const glm::dvec3 c = tr.centroid();
            if (c.z < ground + headBottom - 0.01) continue;
            front = std::max(front, glm::dot(c - base, f));
            const double a = 0.5 * glm::length(tr.cross());
            headArea += a;
            headCentre += a * c;
        }
        ASSERT_GT(headArea, 0) << i;
        headCentre /= headArea;
        EXPECT_GT(glm::dot(headCentre - base, f), 0.5 * kSignalPoleWidth)
            << "signal " << i << ": head in front of the pole";
        double frontArea = 0;
        for (const Tri& tr : tris) {
            const glm::dvec3 c = tr.centroid();
            if (c.z < ground + headBottom - 0.01 || glm::dot(c - base, f) < front - 1e-4) continue;
            const glm::dvec3 n = glm::normalize(tr.cross());
            EXPECT_GT(glm::dot(n, f), 0.9) << "signal " << i << ": front face turned away from the traffic";
            frontArea += 0.5 * glm::length(tr.cross());
        }
        // Lamps: three octagons of 0.2 m across the flats; stop sign: the red
        // octagon; yield: the white triangle (a good part of the plate).
        const double octagon = 8.0 * 0.1 * 0.1 * std::tan(kPi / 8);
        const double expect = light ? 3 * octagon : s.kind == SignalPlacement::Kind::Stop ? 0.3 : 0.05;
        EXPECT_GT(frontArea, 0.95 * expect) << "signal " << i;
        // The facing (plate or housing) area turned toward the traffic is at least the face's.
        double facingArea = 0;
        for (const Tri& tr : tris)
            if (tr.centroid().z >= ground + headBottom - 0.01 && glm::dot(glm::normalize(tr.cross()), f) > 0.9)
                facingArea += 0.5 * glm::length(tr.cross());
        const double plate = light                                   ? kTrafficLightWidth * kTrafficLightHeight
                             : s.kind == SignalPlacement::Kind::Stop ? 2 * kSignSize * kSignSize * std::tan(kPi / 8)
                                                                     : std::sqrt(3.0) / 4 * kSignSize * kSignSize;
        EXPECT_GT(facingArea, 0.99 * plate) << "signal " << i;
    }
}

TEST(TrafficSignals, MeshesAreDeterministicAndPrelit) {
    const City& city = signalCity();
    const LaneModel lanes = buildLaneModel(city.streets, city.params, &city.blocks);
    ASSERT_FALSE(lanes.signals.empty());
    const Lighting light(city.params);
    for (size_t i = 0; i < lanes.signals.size(); ++i) {
        Mesh a, b;
        const uint32_t id = makeInstanceId(signalInstanceKind(lanes.signals[i].kind), i);
        meshSignal(lanes.signals[i], city.params, glm::dvec3(10, 20, 0), light, a, id);
        meshSignal(lanes.signals[i], city.params, glm::dvec3(10, 20, 0), light, b, id);
        ASSERT_FALSE(a.empty());
        EXPECT_EQ(a.positions, b.positions);
        EXPECT_EQ(a.colors, b.colors);
        EXPECT_EQ(a.indices, b.indices);
        EXPECT_EQ(a.ids.size(), a.positions.size());
        EXPECT_EQ(a.normals.size(), a.positions.size());
        for (uint32_t v : a.ids) EXPECT_EQ(v, id);
        for (uint32_t k : a.indices) EXPECT_LT(k, a.positions.size());
        for (const auto& c : a.colors) EXPECT_EQ(c.w, 255);
    }
    // A placement without a direction adds nothing.
    SignalPlacement bad = lanes.signals[0];
    bad.facing = glm::dvec2(0.0);
    Mesh none;
    meshSignal(bad, city.params, glm::dvec3(0.0), light, none, 1);
    EXPECT_TRUE(none.empty());
}

TEST(TrafficSignals, LabelsOfTheSignalKinds) {
    EXPECT_EQ(semanticClass(Material::TrafficLight), SemanticClass::TrafficLight);
    EXPECT_EQ(semanticClass(Material::TrafficSign), SemanticClass::TrafficSign);
    EXPECT_STREQ(semanticClassName(SemanticClass::TrafficLight), "traffic_light");
    EXPECT_STREQ(semanticClassName(SemanticClass::TrafficSign), "traffic_sign");
    EXPECT_STREQ(instanceKindName(InstanceKind::TrafficLight), "traffic_light");
    EXPECT_STREQ(instanceKindName(InstanceKind::TrafficSign), "traffic_sign");
    EXPECT_STREQ(instanceKindName(InstanceKind::Count), "unknown");
    EXPECT_EQ(materialFromName("traffic_light"), Material::TrafficLight);
    EXPECT_EQ(materialFromName("traffic_sign"), Material::TrafficSign);
    EXPECT_EQ(signalMaterial(SignalPlacement::Kind::Yield), Material::TrafficSign);
    EXPECT_EQ(signalInstanceKind(SignalPlacement::Kind::Stop), InstanceKind::TrafficSign);
    EXPECT_EQ(signalInstanceKind(SignalPlacement::Kind::TrafficLight), InstanceKind::TrafficLight);
}
