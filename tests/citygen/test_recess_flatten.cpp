// Window recesses flattened (citygen/recess_flatten.h): on the facades
// meshBuilding() makes, every recessed window is recognised, its glass moves
// out by the recess depth and its jambs go; the flat mesh stays within the
// stated distance of the original surface (checked by brute-force
// point-to-triangle distances).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "citygen/buildings.h"
#include "citygen/recess_flatten.h"

using namespace vista;

namespace {

struct Merged {
    std::vector<glm::vec3> positions;
    std::vector<uint32_t> indices;
    std::vector<Material> material;
    void add(const Mesh& m, Material mat) {
        const uint32_t base = uint32_t(positions.size());
        positions.insert(positions.end(), m.positions.begin(), m.positions.end());
        for (uint32_t i : m.indices) indices.push_back(base + i);
        material.insert(material.end(), m.indices.size() / 3, mat);
    }
};

Merged building(int detail, int floors = 4) {
    Building b;
    b.footprint = {{-10, -6}, {10, -6}, {10, 6}, {-10, 6}};
    b.floors = floors;
    b.height = 3.2 * floors;
    b.roof = RoofType::Flat;
    CityParams p;
    p.detail = detail;
    Lighting light(p);
    Mesh walls, windows, roofs;
    meshBuilding(b, 3, p, light, glm::dvec3(0.0), BuildingMeshes{&walls, &windows, &roofs});
    Merged m;
    m.add(walls, Material::Wall);
    m.add(windows, Material::Window);
    m.add(roofs, Material::Roof);
    return m;
}

// Distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
double pointTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return glm::length(p - a);
    const glm::dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return glm::length(p - b);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
    const glm::dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return glm::length(p - c);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
        return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
    const double denom = 1.0 / (va + vb + vc);
    return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

// Largest distance from the points of `pts` to the triangles of (positions, indices) where keep[t].
double farthest(const std::vector<glm::dvec3>& pts, const std::vector<glm::vec3>& pos, const std::vector<uint32_t>& idx,
                const std::vector<uint8_t>& keep) {
    double worst = 0;
    for (const glm::dvec3& p : pts) {
        double best = 1e300;
        for (size_t t = 0; t < idx.size() / 3; ++t)
            if (keep[t])
                best = std::min(best, pointTriangle(p, pos[idx[3 * t]], pos[idx[3 * t + 1]], pos[idx[3 * t + 2]]));
        worst = std::max(worst, best);
    }
    return worst;
}

// Sample points of the kept triangles: corners, edge midpoints and centroid.
std::vector<glm::dvec3> samples(const std::vector<glm::vec3>& pos, const std::vector<uint32_t>& idx,
                                const std::vector<uint8_t>& keep) {
    std::vector<glm::dvec3> s;
    for (size_t t = 0; t < idx.size() / 3; ++t) {
        if (!keep[t]) continue;
        const glm::dvec3 a = pos[idx[3 * t]], b = pos[idx[3 * t + 1]], c = pos[idx[3 * t + 2]];
        for (const glm::dvec3& q : {a, b, c, (a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5, (a + b + c) / 3.0})
            s.push_back(q);
    }
    return s;
}

}  // namespace

TEST(RecessFlatten, EveryRecessedWindowFlattenedByItsDepth) {
    const Merged m = building(2);
    const RecessFlattening f = flattenRecesses(m.positions, m.indices, m.material);
    CityParams p;
    ASSERT_GT(f.windows, 20u);
    // Each recessed window has four jamb quads (8 triangles); its glass is one quad.
    EXPECT_EQ(f.jambTriangles, 8 * f.windows);
    size_t glassTris = size_t(std::count(m.material.begin(), m.material.end(), Material::Window));
    EXPECT_EQ(glassTris, 2 * f.windows) << "every glass quad belongs to a flattened window";
    EXPECT_NEAR(f.maxRecessDepth, p.window_recess_m, 1e-4);
    // Glass vertices moved by the recess depth, horizontally (the facade normal); others unmoved.
    size_t moved = 0;
    for (size_t i = 0; i < m.positions.size(); ++i) {
        const glm::dvec3 d = glm::dvec3(f.moved[i]) - glm::dvec3(m.positions[i]);
        if (glm::length(d) == 0) continue;
        ++moved;
        EXPECT_NEAR(glm::length(d), p.window_recess_m, 1e-4);
        EXPECT_NEAR(d.z, 0.0, 1e-6);
    }
    EXPECT_EQ(moved, 4 * f.windows);
}

TEST(RecessFlatten, FlatMeshWithinTheRecessDepthOfTheOriginal) {
    const Merged m = building(2, 2);
    const RecessFlattening f = flattenRecesses(m.positions, m.indices, m.material);
    ASSERT_GT(f.windows, 0u);
    const size_t nt = m.indices.size() / 3;
    std::vector<uint8_t> all(nt, 1), kept(nt);
    for (size_t t = 0; t < nt; ++t) kept[t] = !f.jamb[t];
    // Both ways (Hausdorff over sample points): flat -> original and original -> flat.
    const double tol = 1e-4;
    EXPECT_LE(farthest(samples(f.moved, m.indices, kept), m.positions, m.indices, all), f.maxRecessDepth + tol);
    EXPECT_LE(farthest(samples(m.positions, m.indices, all), f.moved, m.indices, kept), f.maxRecessDepth + tol);
    // And the deviation is real: the moved glass lies a recess depth from the original glass plane.
    EXPECT_GT(farthest(samples(f.moved, m.indices, kept), m.positions, m.indices, all), 0.0);
}

TEST(RecessFlatten, NothingToFlattenWithoutRecesses) {
    for (int detail : {0, 1}) {
        const Merged m = building(detail);
        const RecessFlattening f = flattenRecesses(m.positions, m.indices, m.material);
        EXPECT_EQ(f.jambTriangles, 0u) << "detail " << detail;
        EXPECT_EQ(f.windows, 0u);
        EXPECT_EQ(f.maxRecessDepth, 0.0);
        EXPECT_TRUE(std::equal(f.moved.begin(), f.moved.end(), m.positions.begin()));
    }
    // Sills (detail 3) protrude: they are not jambs and stay.
    const Merged s = building(3);
    const RecessFlattening g = flattenRecesses(s.positions, s.indices, s.material);
    EXPECT_GT(g.windows, 0u);
    EXPECT_EQ(g.jambTriangles, 8 * g.windows);
}
