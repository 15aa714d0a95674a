// Bake: geometric sampling (bounding triangle, cameras, resolution, LDI, point removal).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include <sys/stat.h>
#include <unistd.h>

#include <osg/UserDataContainer>
#include <osgDB/ReaderWriter>
#include <osgDB/Registry>
#include <tbb/global_control.h>

#include "citygen/generate.h"
#include "citygen/polygon.h"
#include "bake/appearance.h"
#include "bake/assembly.h"
#include "bake/bake_cell.h"
#include "bake/cell_result.h"
#include "bake/depth_mesh.h"
#include "bake/far_set.h"
#include "bake/impostor_frame.h"
#include "bake/driver.h"
#include "bake/ldi_sampling.h"
#include "bake/placement.h"
#include "bake/point_removal.h"
#include "bake/sampling_plane.h"
#include "bake/view_cells.h"
#include "foundation/hash.h"
#include "foundation/units.h"
#include "nodes/baked_file.h"
#include "foundation/rng.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_file.h"
#include "nodes/render/mode_impostor.h"
#include "nodes/render/mode_full.h"
#include "nodes/render/mode_lodmesh.h"
#include "runtime/engine/image.h"
#include "runtime/engine/metrics.h"
#include "nodes/render/offscreen.h"

#include "tests/common/temp_dir.h"
#include "tests/bake/bake_fixtures.h"

namespace vista {
namespace {
using test::readBytes;

// ----------------------------------------------------------- sampling setup
TEST(Sampling, BoundingTriangleContainsPolygonWithMinimalCircumference) {
    Rng rng(5, 2, Stream::Bake);
    for (int trial = 0; trial < 20; ++trial) {
        std::vector<glm::dvec2> pts;
        for (int i = 0; i < 12; ++i) pts.emplace_back(rng.uniform(-20, 20), rng.uniform(-3, 8));
        auto poly = convexHull(pts);
        auto tri = boundingTriangle(poly);
        double top = -1e300;
        for (auto& q : poly) top = std::max(top, q.y);
        EXPECT_NEAR(tri[0].y, top, 1e-9);
        EXPECT_NEAR(tri[1].y, top, 1e-9);
        // Contains every polygon vertex (edge functions with a tolerance).
        for (auto& q : poly)
            for (int e = 0; e < 3; ++e) {
                const glm::dvec2 a = tri[size_t(e)], b = tri[size_t((e + 1) % 3)];
                const double cr = (b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x);
                EXPECT_LE(cr, 1e-6 * glm::length(b - a)) << "trial " << trial;  // clockwise triangle: inside is <= 0
            }
        // No random valid triangle with a horizontal top edge is shorter.
        const double best = trianglePerimeter(tri);
        for (int k = 0; k < 2000; ++k) {
            const double a = 3.14159265358979 + rng.uniform(0.01, 1.56), b = 4.71238898038469 + rng.uniform(0.01, 1.56);
            const glm::dvec2 nl(std::cos(a), std::sin(a)), nr(std::cos(b), std::sin(b));
            double hl = -1e300, hr = -1e300;
            for (auto& q : poly) {
                hl = std::max(hl, glm::dot(nl, q));
                hr = std::max(hr, glm::dot(nr, q));
            }
            const glm::dvec2 tl((hl - nl.y * top) / nl.x, top), tr((hr - nr.y * top) / nr.x, top);
            const double det = nl.x * nr.y - nl.y * nr.x;
            const glm::dvec2 bot((hl * nr.y - nl.y * hr) / det, (nl.x * hr - hl * nr.x) / det);
            EXPECT_GE(trianglePerimeter({tl, tr, bot}), best * (1 - 1e-6));
        }
    }
}

void expectCamerasWellDefined(const Box3& cell, const Box3& far) {
    auto s = setupSampling(cell, far);
    ASSERT_TRUE(s.isOk()) << s.status().message();
    for (const auto& c : s->cameras) {
        EXPECT_FALSE(far.contains(c)) << "camera inside the far-field box";
        EXPECT_NEAR(glm::dot(s->n, c), s->planeD, 1e-6 * (1 + std::abs(s->planeD)));
        for (int i = 0; i < 8; ++i) EXPECT_GT(glm::dot(s->n, far.corner(i) - c), 0.0);
        EXPECT_TRUE(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z));
    }
    EXPECT_GT(s->dNear, 0.0);
    // Every segment cell -> far crosses the plane inside the polygon (hence the triangle).
    Rng rng(9, 9, Stream::Bake);
    for (int k = 0; k < 500; ++k) {
        glm::dvec3 a, b;
        for (int ax = 0; ax < 3; ++ax) {
            a[ax] = rng.uniform(cell.lo[ax], cell.hi[ax]);
            b[ax] = rng.uniform(far.lo[ax], far.hi[ax]);
        }
        const double da = glm::dot(s->n, a) - s->planeD, db = glm::dot(s->n, b) - s->planeD;
        ASSERT_LE(da, 1e-9);
        ASSERT_GT(db, 0.0);
        const glm::dvec3 x = a + (b - a) * (-da / (db - da));
        const glm::dvec2 q(glm::dot(s->U, x), glm::dot(s->V, x));
        const auto& P = s->polygon;
        for (size_t e = 0; e < P.size(); ++e) {
            const glm::dvec2 p0 = P[e], p1 = P[(e + 1) % P.size()];
            EXPECT_GE((p1.x - p0.x) * (q.y - p0.y) - (p1.y - p0.y) * (q.x - p0.x), -1e-6 * (1 + glm::length(p1 - p0)));
        }
    }
}

TEST(Sampling, CameraPlacementIsWellDefined) {
    const Box3 cell{{-100, -5, 1.2}, {0, 5, 2.0}};
    expectCamerasWellDefined(cell, Box3{{150, -40, 0}, {210, 40, 30}});
    expectCamerasWellDefined(cell, Box3{{100, 30, -2}, {400, 300, 60}});  // off to the side
    // Hard case: the far-field box nearly touches the view cell.
    expectCamerasWellDefined(cell, Box3{{1e-3, -40, 0}, {60, 40, 30}});
    expectCamerasWellDefined(cell, Box3{{1e-3, -4, 1.5}, {0.5, 4, 1.7}});
    // Touching or overlapping is an error, never a camera inside the box.
    EXPECT_FALSE(setupSampling(cell, Box3{{0, -40, 0}, {60, 40, 30}}).isOk());
    EXPECT_FALSE(setupSampling(cell, Box3{{-10, -40, 0}, {60, 40, 30}}).isOk());
    EXPECT_FALSE(setupSampling(cell, Box3{{10, 0, 0}, {5, 1, 1}}).isOk());  // empty box
}

TEST(Sampling, ResolutionFactors) {
    SamplingSetup s;
    s.dNear = 100;
    s.circumradius = 50;
    SamplingParams p;
    p.fovYDeg = 45;
    EXPECT_NEAR(exactPerspectiveFactor(p), 1.17, 0.005);  // the thesis' value for 45 degrees
    p.fovYDeg = 60;
    EXPECT_NEAR(exactPerspectiveFactor(p), 4.0 / 3.0, 1e-12);  // 1 / cos^2(30 deg)
    EXPECT_DOUBLE_EQ(p.perspective, 1.17);                     // the default is the thesis' factor
    const double delta = outputPixelAngle(p);
    EXPECT_NEAR(delta, 2 * std::tan(M_PI / 6) / 480, 1e-15);
    EXPECT_NEAR(ldiStep(s, p), delta / 1.17 / std::sqrt(2.0), 1e-12);
    p.oversample = 2;
    EXPECT_NEAR(ldiStep(s, p), delta / 1.17 / std::sqrt(2.0) / 2, 1e-12);
    p.perspective = 1;
    p.diagonalFactor = false;
    EXPECT_NEAR(ldiStep(s, p), delta / 2, 1e-12);
}

struct ProjView {
    glm::dvec3 eye, fwd, right, up;
    int w = 160, h = 120;
    double f = 0;  // focal length in pixels
    bool project(const glm::dvec3& p, int& x, int& y) const {
        const glm::dvec3 d = p - eye;
        const double z = glm::dot(d, fwd);
        if (z <= 1e-6) return false;
        const double px = w * 0.5 + f * glm::dot(d, right) / z, py = h * 0.5 - f * glm::dot(d, up) / z;
        x = int(std::floor(px));
        y = int(std::floor(py));
        return x >= 0 && y >= 0 && x < w && y < h;
    }
    glm::dvec3 ray(double px, double py) const {
        return glm::normalize(fwd * f + right * (px - w * 0.5) - up * (py - h * 0.5));
    }
};

ProjView viewFrom(const glm::dvec3& eye, const glm::dvec3& target, int w, int h, double fovYDeg) {
    ProjView v;
    v.eye = eye;
    v.fwd = glm::normalize(target - eye);
    v.right = glm::normalize(glm::cross(v.fwd, glm::dvec3(0, 0, 1)));
    v.up = glm::cross(v.right, v.fwd);
    v.w = w;
    v.h = h;
    v.f = 0.5 * h / std::tan(0.5 * fovYDeg * 3.14159265358979 / 180.0);
    return v;
}

// Hole test: rendered from the cell's corners and centre, every pixel inside the
// geometry's footprint (the pixel and its 8 neighbours hit geometry) gets a point.
TEST(Sampling, NoHolesFromCellCornersAndCentre) {
    TriangleSoup soup = testFarField(false);
    auto scene = RayScene::build(soup);
    ASSERT_TRUE(scene.isOk()) << scene.status().message();
    const Box3 cell{{-100, -5, 1.2}, {0, 5, 2.0}};
    Box3 far{glm::dvec3(1e300), glm::dvec3(-1e300)};
    for (auto& p : soup.positions) {
        far.lo = glm::min(far.lo, glm::dvec3(p));
        far.hi = glm::max(far.hi, glm::dvec3(p));
    }
    auto s = setupSampling(cell, far);
    ASSERT_TRUE(s.isOk());
    SamplingParams sp;  // 640x480, 60 degrees
    LdiResult ldi = sampleLdi(**scene, *s, far, sp);
    auto keep = removeRedundant(ldi, *s, cell, sp);
    std::vector<glm::dvec3> pts;
    for (size_t i = 0; i < ldi.samples.size(); ++i)
        if (keep[i]) pts.emplace_back(ldi.samples[i].pos);
    const size_t removed = ldi.samples.size() - pts.size();
    EXPECT_GT(removed, 0u) << "point removal removed nothing";
    // The visibility pre-pass (points hidden from the cell are dropped) must not open holes either.
    {
        std::vector<glm::vec3> fp;
        for (const auto& q : pts) fp.emplace_back(q);
        AppearanceParams ap;
        ap.texelsX = ap.texelsY = 1;
        ap.minSamples = ap.maxSamples = 1;
        AppearanceStats ast;
        PointImpostorData d;
        computeAppearance(**scene, *s, fp, ap, 1, 5, d, ast, nullptr, &cell);
        EXPECT_GT(ast.dropped, 0u) << "no hidden layer was dropped";
        pts.clear();
        for (const auto& q : d.positions) pts.emplace_back(q);
    }
    std::vector<glm::dvec3> eyes;
    for (int i = 0; i < 8; ++i) eyes.push_back(cell.corner(i));
    eyes.push_back(cell.center());
    size_t interior = 0;
    for (const auto& eye : eyes) {
        // A 640x480 60-degree view towards the far field's centre; test the central 240x160 window.
        ProjView v = viewFrom(eye, far.center(), 640, 480, 60.0);
        std::vector<uint8_t> geo(size_t(v.w) * size_t(v.h), 0), cov(geo.size(), 0);
        for (int y = 160; y < 320; ++y)
            for (int x = 200; x < 440; ++x)
                geo[size_t(y) * size_t(v.w) + size_t(x)] =
                    (*scene)->intersect(glm::vec3(eye), glm::vec3(v.ray(x + 0.5, y + 0.5)), 0, 1e30f).hit;
        for (const auto& p : pts) {
            int x, y;
            if (v.project(p, x, y)) cov[size_t(y) * size_t(v.w) + size_t(x)] = 1;
        }
        for (int y = 161; y < 319; ++y)
            for (int x = 201; x < 439; ++x) {
                bool all = true;
                for (int dy = -1; dy <= 1 && all; ++dy)
                    for (int dx = -1; dx <= 1 && all; ++dx)
                        all = geo[size_t(y + dy) * size_t(v.w) + size_t(x + dx)] != 0;
                if (!all) continue;
                ++interior;
                if (!cov[size_t(y) * size_t(v.w) + size_t(x)] && std::getenv("VISTA_DEBUG_HOLE")) {
                    RayHit hh = (*scene)->intersect(glm::vec3(eye), glm::vec3(v.ray(x + 0.5, y + 0.5)), 0, 1e30f);
                    glm::dvec3 hp = eye + v.ray(x + 0.5, y + 0.5) * double(hh.t);
                    std::fprintf(stderr, "hit %f %f %f n %f %f %f\n", hp.x, hp.y, hp.z, hh.normal.x, hh.normal.y,
                                 hh.normal.z);
                    for (size_t i = 0; i < ldi.samples.size(); ++i) {
                        int px, py;
                        if (v.project(glm::dvec3(ldi.samples[i].pos), px, py) && std::abs(px - x) <= 1 &&
                            std::abs(py - y) <= 1) {
                            const glm::dvec3 q(ldi.samples[i].pos);
                            const double dd = glm::length(q - eye);
                            const bool occ =
                                (*scene)->occluded(glm::vec3(eye), glm::vec3((q - eye) / dd), 0, float(dd - 0.1));
                            bool inPts = false;
                            for (auto& z : pts)
                                if (glm::length(z - q) < 1e-4) inPts = true;
                            std::fprintf(stderr, " ldi %zu cam %d px %d %d pos %f %f %f keep %d occ %d final %d\n", i,
                                         ldi.samples[i].camera, px, py, q.x, q.y, q.z, int(keep[i]), int(occ),
                                         int(inPts));
                        }
                    }
                }
                ASSERT_TRUE(cov[size_t(y) * size_t(v.w) + size_t(x)])
                    << "hole at " << x << "," << y << " from eye " << eye.x << "," << eye.y << "," << eye.z;
            }
    }
    EXPECT_GT(interior, 5000u);
}

// Point removal on surfaces seen at grazing angles (streets and squares of the
// far field seen from eye height): the viewer sees them as obliquely as the
// cameras, so one camera's samples are sufficient there and the others' are
// removed. Checked against an independent count (samples of the best camera,
// i.e. the camera highest above the ground, lowest index on ties) and for holes
// from the cell's corners and centre.
TEST(Sampling, RemovalOnGrazingGroundKeepsOneCameraWithoutHoles) {
    TriangleSoup soup;
    addBox(soup, {150, -40, -1}, {400, 40, 0}, [](glm::vec3) { return glm::u8vec4(90, 120, 80, 255); });
    auto scene = RayScene::build(soup);
    ASSERT_TRUE(scene.isOk()) << scene.status().message();
    const Box3 cell{{-100, -5, 1.2}, {0, 5, 2.0}};
    const Box3 far{{150, -40, -1}, {400, 40, 0}};
    auto s = setupSampling(cell, far);
    ASSERT_TRUE(s.isOk());
    SamplingParams sp;
    LdiResult ldi = sampleLdi(**scene, *s, far, sp);
    auto keep = removeRedundant(ldi, *s, cell, sp);
    // Ground-top samples of the cameras above the ground (a camera below it only
    // records the top face from behind, through the box). Those cameras sample
    // the ground sufficiently for every viewpoint of the cell, so after removal
    // about one camera's worth of samples is left: at most 10 % more than the
    // larger of their counts (keeping every camera's samples would give about twice that).
    std::array<size_t, 3> top{0, 0, 0}, kept{0, 0, 0};
    for (size_t i = 0; i < ldi.samples.size(); ++i) {
        const auto& smp = ldi.samples[i];
        if (smp.normal.z < 0.9f || std::abs(smp.pos.z) > 1e-3f) continue;
        ++top[smp.camera];
        kept[smp.camera] += keep[i];
    }
    size_t above = 0, topAbove = 0, keptAbove = 0;
    for (int k = 0; k < 3; ++k)
        if (s->cameras[size_t(k)].z > 0.1) {
            ++above;
            topAbove = std::max(topAbove, top[size_t(k)]);
            keptAbove += kept[size_t(k)];
        }
    ASSERT_GE(above, 2u);
    ASSERT_GT(topAbove, 1000u);
    EXPECT_LE(double(keptAbove), 1.1 * double(topAbove));
    // No holes in the ground from the cell's corners and centre.
    std::vector<glm::dvec3> pts;
    for (size_t i = 0; i < ldi.samples.size(); ++i)
        if (keep[i]) pts.emplace_back(ldi.samples[i].pos);
    std::vector<glm::dvec3> eyes;
    for (int i = 0; i < 8; ++i) eyes.push_back(cell.corner(i));
    eyes.push_back(cell.center());
    size_t interior = 0;
    for (const auto& eye : eyes) {
        ProjView v = viewFrom(eye, glm::dvec3(275, 0, 0), 640, 480, 60.0);
        std::vector<uint8_t> geo(size_t(v.w) * size_t(v.h), 0), cov(geo.size(), 0);
        for (int y = 0; y < v.h; ++y)
            for (int x = 0; x < v.w; ++x)
                geo[size_t(y) * size_t(v.w) + size_t(x)] =
                    (*scene)->intersect(glm::vec3(eye), glm::vec3(v.ray(x + 0.5, y + 0.5)), 0, 1e30f).hit;
        for (const auto& q : pts) {
            int x, y;
            if (v.project(q, x, y)) cov[size_t(y) * size_t(v.w) + size_t(x)] = 1;
        }
        for (int y = 1; y + 1 < v.h; ++y)
            for (int x = 1; x + 1 < v.w; ++x) {
                bool all = true;
                for (int dy = -1; dy <= 1 && all; ++dy)
                    for (int dx = -1; dx <= 1 && all; ++dx)
                        all = geo[size_t(y + dy) * size_t(v.w) + size_t(x + dx)] != 0;
                if (!all) continue;
                ++interior;
                ASSERT_TRUE(cov[size_t(y) * size_t(v.w) + size_t(x)])
                    << "hole at " << x << "," << y << " from eye " << eye.x << "," << eye.y << "," << eye.z;
            }
    }
    EXPECT_GT(interior, 2000u);
}

}  // namespace
}  // namespace vista
