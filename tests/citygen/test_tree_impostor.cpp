// Tree impostors (citygen/tree_impostor.h): the atlas is deterministic and
// independent of the thread count, its coverage matches an independent
// Monte Carlo estimate of the projected prototype, and the quads have the
// prototype's height and width.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <tbb/global_control.h>

#include "citygen/lighting.h"
#include "citygen/tree_impostor.h"
#include "citygen/trees.h"

namespace {

using namespace vista;

std::vector<TreePrototype> prototypes() {
    CityParams p;
    return makeTreePrototypes(p, Lighting(p));
}

TreeImpostor impostorOf(const TreePrototype& t, int cell = kImpostorCellPixels) {
    return makeTreeImpostor(t.mesh.positions, t.mesh.colors, t.mesh.indices, cell);
}

TEST(TreeImpostor, AtlasIsDeterministicAndIndependentOfThreadCount) {
    const auto protos = prototypes();
    ASSERT_FALSE(protos.empty());
    for (size_t i = 0; i < protos.size(); i += 3) {
        const TreeImpostor a = impostorOf(protos[i]), b = impostorOf(protos[i]);
        TreeImpostor one;
        {
            tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
            one = impostorOf(protos[i]);
        }
        ASSERT_EQ(a.atlas.size(), size_t(4 * 2 * kImpostorCellPixels * 2 * kImpostorCellPixels));
        EXPECT_TRUE(a.atlas == b.atlas) << "prototype " << i;
        EXPECT_TRUE(a.atlas == one.atlas) << "prototype " << i << ": 1 thread differs";
        EXPECT_TRUE(a.positions == one.positions && a.texcoords == one.texcoords);
    }
}

// Point-in-triangle in double (an independent coverage test: no fixed point,
// no edge functions shared with the baker).
bool inTriangle(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
    auto cross = [](const glm::dvec2& u, const glm::dvec2& v) { return u.x * v.y - u.y * v.x; };
    const double d1 = cross(b - a, p - a), d2 = cross(c - b, p - b), d3 = cross(a - c, p - c);
    const bool neg = d1 < 0 || d2 < 0 || d3<0, pos = d1> 0 || d2 > 0 || d3 > 0;
    return !(neg && pos);
}

// Coverage per cell: alpha sum / (255 x the inner square) = the fraction of
// the quad covered by the projected prototype; an independent estimate
// samples 20,000 random points of the quad against every projected triangle
// (projection axes written out here: yaw k x 60 degrees, top view = xy).
// Tolerance: 0.015 of the quad's area (Monte Carlo 3 sigma <= 0.011, plus
// edge texels' coverage quantised to 1/16).
TEST(TreeImpostor, CoverageMatchesProjectedTriangles) {
    const auto protos = prototypes();
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    const int cellPx = kImpostorCellPixels, inner = cellPx - 2 * kImpostorPadPixels, W = 2 * cellPx;
    int checked = 0;
    for (size_t pi = 0; pi < protos.size(); pi += 2) {
        const Mesh& m = protos[pi].mesh;
        const TreeImpostor imp = impostorOf(protos[pi]);
        ASSERT_FALSE(imp.empty());
        double R = 0, z0 = 1e30, z1 = -1e30;
        for (const auto& p : m.positions) {
            R = std::max(R, std::hypot(double(p.x), double(p.y)));
            z0 = std::min(z0, double(p.z));
            z1 = std::max(z1, double(p.z));
        }
        for (int cell = 0; cell < kImpostorCells; ++cell) {
            // Projection to quad coordinates in [0, 1]^2.
            const double yaw = cell * (3.14159265358979323846 / 3.0);
            auto project = [&](const glm::vec3& p) {
                if (cell == 3) return glm::dvec2((p.x + R) / (2 * R), (p.y + R) / (2 * R));
                const double s = p.x * std::cos(yaw) + p.y * std::sin(yaw);
                return glm::dvec2((s + R) / (2 * R), (p.z - z0) / (z1 - z0));
            };
            std::vector<glm::dvec2> q(m.positions.size());
            for (size_t i = 0; i < q.size(); ++i) q[i] = project(m.positions[i]);
            const int samples = 20000;
            int hit = 0;
            for (int s = 0; s < samples; ++s) {
                const glm::dvec2 p(uni(rng), uni(rng));
                for (size_t t = 0; t < m.indices.size(); t += 3)
                    if (inTriangle(p, q[m.indices[t]], q[m.indices[t + 1]], q[m.indices[t + 2]])) {
                        ++hit;
                        break;
                    }
            }
            const double expected = double(hit) / samples;
            double alpha = 0;
            const int cx = (cell % 2) * cellPx, cy = (cell / 2) * cellPx;
            for (int y = 0; y < cellPx; ++y)
                for (int x = 0; x < cellPx; ++x) {
                    const uint8_t a = imp.atlas[(size_t(cy + y) * W + size_t(cx + x)) * 4 + 3];
                    alpha += a;
                    const bool border = x < kImpostorPadPixels || y < kImpostorPadPixels ||
                                        x >= cellPx - kImpostorPadPixels || y >= cellPx - kImpostorPadPixels;
                    if (border) {
                        EXPECT_EQ(a, 0) << "padding texel " << x << "," << y << " of cell " << cell << " is covered";
                    }
                }
            const double measured = alpha / 255.0 / (double(inner) * inner);
            EXPECT_NEAR(measured, expected, 0.015) << "prototype " << pi << " cell " << cell;
            EXPECT_GT(expected, 0.05) << "a tree covers part of every view";
            ++checked;
        }
    }
    EXPECT_GE(checked, 8);
}

// Quads: the prototype's height (z range) and width (2 x its largest distance
// from the trunk axis), within 0.1 mm; texture coordinates inside the atlas.
TEST(TreeImpostor, QuadsHaveThePrototypesHeightAndWidth) {
    for (const TreePrototype& t : prototypes()) {
        const TreeImpostor imp = impostorOf(t);
        double R = 0, z0 = 1e30, z1 = -1e30;
        for (const auto& p : t.mesh.positions) {
            R = std::max(R, std::hypot(double(p.x), double(p.y)));
            z0 = std::min(z0, double(p.z));
            z1 = std::max(z1, double(p.z));
        }
        ASSERT_EQ(imp.triangleCount(), size_t(2 * kImpostorCells));
        ASSERT_EQ(imp.positions.size(), size_t(4 * kImpostorCells));
        double qz0 = 1e30, qz1 = -1e30;
        for (int q = 0; q < kImpostorVerticalQuads; ++q) {
            const glm::vec3* c = &imp.positions[size_t(4 * q)];
            EXPECT_NEAR(glm::distance(glm::dvec2(c[0]), glm::dvec2(c[1])), 2 * R, 1e-4) << "quad " << q << " width";
            EXPECT_NEAR(std::abs(double(c[2].z) - c[1].z), z1 - z0, 1e-4) << "quad " << q << " height";
            for (int k = 0; k < 4; ++k) {
                qz0 = std::min(qz0, double(c[k].z));
                qz1 = std::max(qz1, double(c[k].z));
                EXPECT_NEAR(std::hypot(double(c[k].x), double(c[k].y)), R, 1e-4) << "corners on the crown's radius";
            }
        }
        EXPECT_NEAR(qz0, z0, 1e-4);
        EXPECT_NEAR(qz1, z1, 1e-4);
        const glm::vec3* top = &imp.positions[size_t(4 * kImpostorVerticalQuads)];
        for (int k = 0; k < 4; ++k) {
            EXPECT_NEAR(top[k].z, z0 + kImpostorTopQuadHeight * (z1 - z0), 1e-4);
            EXPECT_NEAR(std::max(std::abs(top[k].x), std::abs(top[k].y)), R, 1e-4);
        }
        for (const auto& uv : imp.texcoords) {
            EXPECT_GE(uv.x, 0.0f);
            EXPECT_LE(uv.x, 1.0f);
            EXPECT_GE(uv.y, 0.0f);
            EXPECT_LE(uv.y, 1.0f);
        }
    }
}

TEST(TreeImpostor, EmptyMeshGivesNoQuads) {
    const TreeImpostor imp = makeTreeImpostor({}, {}, {});
    EXPECT_TRUE(imp.empty());
    EXPECT_TRUE(std::all_of(imp.atlas.begin(), imp.atlas.end(), [](uint8_t b) { return b == 0; }));
    // A flat (zero-height) mesh: no quads either.
    const TreeImpostor flat = makeTreeImpostor({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},
                                               {glm::u8vec4(255), glm::u8vec4(255), glm::u8vec4(255)}, {0, 1, 2});
    EXPECT_TRUE(flat.empty());
}

}  // namespace
