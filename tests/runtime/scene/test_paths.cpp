// Walkthrough paths: determinism, speed / yaw-rate limits, staying on the
// streets, CSV round trip and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "runtime/scene/paths.h"
#include "foundation/units.h"

using namespace vista;

namespace {

// A 6 x 6 grid of streets, 120 m apart, plus one dead-end spur.
StreetGraph gridGraph() {
    StreetGraph g;
    const int n = 6;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) g.nodes.push_back({(i - 2.5) * 120.0, (j - 2.5) * 120.0});
    auto add = [&](uint32_t a, uint32_t b) {
        StreetEdge e;
        e.a = a;
        e.b = b;
        e.width = 8.0f;
        g.edges.push_back(e);
    };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            if (i + 1 < n) add(uint32_t(j * n + i), uint32_t(j * n + i + 1));
            if (j + 1 < n) add(uint32_t(j * n + i), uint32_t((j + 1) * n + i));
        }
    g.nodes.push_back({-2.5 * 120.0 - 80.0, 0.5 * 120.0});
    add(uint32_t(3 * n), uint32_t(g.nodes.size() - 1));
    return g;
}

CityParams flatParams() {
    CityParams p;
    p.hills_amplitude_m = 0.0;
    return p;
}

double wrap(double a) {
    while (a > kPi) a -= 2 * kPi;
    while (a < -kPi) a += 2 * kPi;
    return a;
}

std::string tmpFile(const std::string& name) {
    return (std::filesystem::temp_directory_path() / ("vista_test_paths_" + std::to_string(::getpid()) + "_" + name))
        .string();
}

}  // namespace

TEST(Paths, DeterministicPerSeed) {
    StreetGraph g = gridGraph();
    PathOptions o;
    o.duration = 40;
    auto a = generatePath(g, flatParams(), o), b = generatePath(g, flatParams(), o);
    ASSERT_TRUE(a.isOk()) << a.status().message();
    ASSERT_TRUE(b.isOk());
    ASSERT_EQ(a->samples.size(), b->samples.size());
    for (size_t i = 0; i < a->samples.size(); ++i) {
        EXPECT_EQ(a->samples[i].position, b->samples[i].position);
        EXPECT_EQ(a->samples[i].heading, b->samples[i].heading);
    }
    o.seed = 2;
    auto c = generatePath(g, flatParams(), o);
    ASSERT_TRUE(c.isOk());
    bool differs = false;
    for (size_t i = 0; i < c->samples.size(); ++i)
        differs = differs || c->samples[i].position != a->samples[i].position;
    EXPECT_TRUE(differs);
}

TEST(Paths, RespectsSpeedAndYawLimitsAndStaysOnStreets) {
    StreetGraph g = gridGraph();
    for (uint64_t seed : {1u, 2u, 3u, 4u, 5u}) {
        PathOptions o;
        o.seed = seed;
        o.duration = 90;
        auto p = generatePath(g, flatParams(), o);
        ASSERT_TRUE(p.isOk()) << p.status().message();
        ASSERT_EQ(p->samples.size(), size_t(std::floor(o.duration / o.dt + 1e-9)) + 1);
        double turned = 0, travelled = 0, maxTurn = 0;
        for (size_t i = 0; i < p->samples.size(); ++i) {
            const auto& s = p->samples[i];
            EXPECT_NEAR(s.position.z, 1.2, 1e-9);  // car eye height on flat ground
            double d = distanceToStreets(g, glm::dvec2(s.position));
            EXPECT_LE(d, 4.0) << "seed " << seed << " sample " << i << " is " << d
                              << " m off the centre line (half width 4 m)";
            if (i == 0) continue;
            const auto& q = p->samples[i - 1];
            double v = glm::length(glm::dvec2(s.position - q.position)) / o.dt;
            EXPECT_LE(v, o.maxSpeed + 1e-9);
            double dh = std::abs(wrap(s.heading - q.heading));
            EXPECT_LE(dh, o.maxYawRate * o.dt + 1e-9);
            turned += dh;
            maxTurn = std::max(maxTurn, dh);
            travelled += v * o.dt;
        }
        // It drives (at least a third of top speed on average) and turns at intersections.
        EXPECT_GT(travelled, o.maxSpeed * o.duration / 3);
        EXPECT_GT(turned, kPi / 2) << "seed " << seed << " never turned";
    }
}

TEST(Paths, EyeHeightsAndFlyOver) {
    StreetGraph g = gridGraph();
    CityParams p = flatParams();
    p.origin_x = 1.0e6;
    p.origin_y = -2.0e6;
    PathOptions o;
    o.duration = 5;
    o.kind = PathKind::Walk;
    auto w = generatePath(g, p, o);
    ASSERT_TRUE(w.isOk());
    EXPECT_NEAR(w->samples[0].position.z, 1.7, 1e-9);
    EXPECT_NEAR(w->samples[0].pitch, 0.0, 1e-12);
    // World coordinates carry the city origin.
    EXPECT_GE(distanceToStreets(g, glm::dvec2(w->samples[3].position)), 1e5);
    EXPECT_LE(distanceToStreets(g, glm::dvec2(w->samples[3].position) - glm::dvec2(1.0e6, -2.0e6)), 4.0);
    o.kind = PathKind::Fly;
    o.flyHeight = 60;
    auto f = generatePath(g, p, o);
    ASSERT_TRUE(f.isOk());
    EXPECT_NEAR(f->samples[10].position.z, 60.0, 1e-9);
    EXPECT_NEAR(f->samples[10].pitch, o.flyPitch, 1e-12);
}

TEST(Paths, CsvRoundTrip) {
    StreetGraph g = gridGraph();
    PathOptions o;
    o.duration = 3;
    o.kind = PathKind::Fly;
    auto p = generatePath(g, flatParams(), o);
    ASSERT_TRUE(p.isOk());
    std::string f = tmpFile("rt.csv");
    ASSERT_TRUE(savePathCsv(p.value(), f).isOk());
    auto q = loadPathCsv(f);
    ASSERT_TRUE(q.isOk()) << q.status().message();
    ASSERT_EQ(q->samples.size(), p->samples.size());
    for (size_t i = 0; i < p->samples.size(); ++i) {
        EXPECT_NEAR(q->samples[i].t, p->samples[i].t, 1e-6);
        EXPECT_NEAR(glm::length(q->samples[i].position - p->samples[i].position), 0.0, 1e-3);
        EXPECT_NEAR(wrap(q->samples[i].heading - p->samples[i].heading), 0.0, 1e-7);
        EXPECT_NEAR(q->samples[i].pitch, p->samples[i].pitch, 1e-7);
    }
    std::filesystem::remove(f);
}

TEST(Paths, BadInput) {
    EXPECT_FALSE(loadPathCsv(tmpFile("does_not_exist.csv")).isOk());
    auto write = [](const std::string& name, const std::string& text) {
        std::string f = tmpFile(name);
        std::ofstream(f) << text;
        return f;
    };
    std::string f1 = write("bad1.csv", "t_s,x_m,y_m,z_m,heading_deg,pitch_deg\n0,1,2,3,4,5\n0.1,1,2,abc,4,5\n");
    auto r1 = loadPathCsv(f1);
    ASSERT_FALSE(r1.isOk());
    EXPECT_NE(r1.status().message().find("line 3"), std::string::npos) << r1.status().message();
    std::string f2 = write("bad2.csv", "0,1,2,3,4,5\n0,1,2,3,4,5\n");
    auto r2 = loadPathCsv(f2);
    ASSERT_FALSE(r2.isOk());
    EXPECT_NE(r2.status().message().find("does not increase"), std::string::npos);
    std::string f3 = write("bad3.csv", "0,1,2,3,4\n");
    EXPECT_FALSE(loadPathCsv(f3).isOk());
    std::string f4 = write("bad4.csv", "t_s,x_m,y_m,z_m,heading_deg,pitch_deg\n");
    EXPECT_FALSE(loadPathCsv(f4).isOk());
    std::string f5 = write("bad5.csv", "0,1,2,nan,4,5\n");
    EXPECT_FALSE(loadPathCsv(f5).isOk());
    for (const auto& f : {f1, f2, f3, f4, f5}) std::filesystem::remove(f);
    // Finite but huge coordinates (the renderer and the ray caster could not
    // represent them) are refused with the field and its range; Earth-sized ones load.
    // The message prints the field as written, never as 309 digits.
    const std::pair<std::string, std::string> huge[] = {
        {"0,1e20,0,1.7,0,0\n", "field 2 (x_m) = '1e20' is out of range [-20000000, 20000000]"},
        {"0,0,-3e7,1.7,0,0\n", "field 3 (y_m) = '-3e7' is out of range"},
        {"0,0,0,1e6,0,0\n", "field 4 (z_m) = '1e6' is out of range [-100000, 100000]"},
        {"0,0,0,1.7,1e300,0\n", "field 5 (heading_deg) = '1e300' is out of range"},
        {"1e300,0,0,1.7,0,0\n", "field 1 (t_s) = '1e300' is out of range"},
        {"0,1e308,0,1.7,0,0\n", "field 2 (x_m) = '1e308' is out of range"}};
    for (const auto& [text, says] : huge) {
        const std::string f = write("huge.csv", text);
        auto r = loadPathCsv(f);
        ASSERT_FALSE(r.isOk()) << text;
        EXPECT_NE(r.status().message().find(says), std::string::npos) << r.status().message();
        std::filesystem::remove(f);
    }
    // A field that is not a number is named, with its line and text.
    const std::string fAbc = write("abc.csv", "t_s,x_m,y_m,z_m,heading_deg,pitch_deg\n1.5abc,0,0,1.7,0,0\n");
    auto abc = loadPathCsv(fAbc);
    ASSERT_FALSE(abc.isOk());
    EXPECT_NE(abc.status().message().find("line 2: field 1 (t_s) = '1.5abc' is not a number"), std::string::npos)
        << abc.status().message();
    std::filesystem::remove(fAbc);
    // A UTF-8 byte order mark before the header (spreadsheet exports) is skipped.
    const std::string fBom =
        write("bom.csv", "\xEF\xBB\xBFt_s,x_m,y_m,z_m,heading_deg,pitch_deg\n0,1,2,1.7,0,0\n0.5,2,2,1.7,0,0\n");
    auto bom = loadPathCsv(fBom);
    ASSERT_TRUE(bom.isOk()) << bom.status().message();
    EXPECT_EQ(bom->samples.size(), 2u);
    std::filesystem::remove(fBom);
    // Not a regular file: refused at once (a device would be read without end).
    auto dev = loadPathCsv("/dev/zero");
    ASSERT_FALSE(dev.isOk());
    EXPECT_NE(dev.status().message().find("not a regular file"), std::string::npos) << dev.status().message();
    const std::string fOk = write("earth.csv", "0,-2e7,2e7,1e5,-36000,89\n");
    EXPECT_TRUE(loadPathCsv(fOk).isOk());
    std::filesystem::remove(fOk);

    PathOptions o;
    EXPECT_FALSE(generatePath(StreetGraph{}, flatParams(), o).isOk());
    o.maxSpeed = 0;
    auto r = generatePath(gridGraph(), flatParams(), o);
    ASSERT_FALSE(r.isOk());
    EXPECT_NE(r.status().message().find("speed"), std::string::npos);
    EXPECT_FALSE(parsePathKind("boat").isOk());
}

TEST(Paths, SpreadCoversThePath) {
    Path p;
    for (int i = 0; i < 100; ++i) p.samples.push_back({double(i), {}, 0, 0});
    auto s = p.spread(5);
    ASSERT_EQ(s.size(), 5u);
    EXPECT_EQ(s.front(), 0u);
    EXPECT_EQ(s.back(), 99u);
    for (size_t i = 1; i < s.size(); ++i) EXPECT_GT(s[i], s[i - 1]);
}

TEST(Paths, RunsAreConsecutiveSamplesSpreadOverThePath) {
    Path p;
    for (int i = 0; i < 100; ++i) p.samples.push_back({double(i), {}, 0, 0});
    // 10 frames in 3 runs: lengths 4, 3, 3; starts 0, (100 - 3) / 2 rounded, 97.
    auto r = p.runs(10, 3);
    const std::vector<size_t> want = {0, 1, 2, 3, 49, 50, 51, 97, 98, 99};
    EXPECT_EQ(r, want);
    // One run: the first n samples; n runs: spread.
    auto c = p.frames(5, 1);
    EXPECT_EQ(c, (std::vector<size_t>{0, 1, 2, 3, 4}));
    EXPECT_EQ(p.frames(5, 0), p.spread(5));
    EXPECT_EQ(p.runs(5, 5), p.spread(5));
    // More runs than frames are clamped; more frames than samples repeat the last one.
    EXPECT_EQ(p.runs(3, 50).size(), 3u);
    auto longer = p.runs(150, 1);
    ASSERT_EQ(longer.size(), 150u);
    EXPECT_EQ(longer.back(), 99u);
    for (size_t i = 1; i < r.size(); ++i) EXPECT_GT(r[i], r[i - 1]);
}

TEST(Paths, RunUpStartsAtCruisingSpeedAndIsTheSameDrive) {
    // The run-up is the same simulation with its first runUp seconds dropped:
    // the path with run-up equals the tail of the path without it, and its
    // first step already moves at a good fraction of the top speed.
    StreetGraph g = gridGraph();
    PathOptions rest;
    rest.runUp = 0;
    rest.duration = 20;
    PathOptions cruise = rest;
    cruise.runUp = 6;
    cruise.duration = 14;
    auto a = generatePath(g, flatParams(), rest), b = generatePath(g, flatParams(), cruise);
    ASSERT_TRUE(a.isOk() && b.isOk());
    const size_t skip = size_t(std::floor(6.0 / rest.dt + 1e-9));
    ASSERT_EQ(a->samples.size(), b->samples.size() + skip);
    for (size_t i = 0; i < b->samples.size(); ++i) {
        EXPECT_EQ(b->samples[i].position, a->samples[i + skip].position) << i;
        EXPECT_NEAR(b->samples[i].t, a->samples[i + skip].t - 6.0, 1e-9);
    }
    const double v0rest = glm::length(a->samples[1].position - a->samples[0].position) / rest.dt;
    const double v0cruise = glm::length(b->samples[1].position - b->samples[0].position) / rest.dt;
    EXPECT_LT(v0rest, 0.1 * rest.maxSpeed);
    EXPECT_GT(v0cruise, 0.3 * rest.maxSpeed);
    PathOptions bad = rest;
    bad.runUp = -1;
    auto r = generatePath(g, flatParams(), bad);
    ASSERT_FALSE(r.isOk());
    EXPECT_NE(r.status().message().find("run-up"), std::string::npos);
}

TEST(Paths, MotionPerFrameMatchesAnIndependentSum) {
    Path p;
    // Straight line at 2 m per sample, heading turning 3 degrees per sample,
    // except one jump of 10 m and 30 degrees.
    for (int i = 0; i < 6; ++i) {
        PathSample s;
        s.t = i;
        s.position = glm::dvec3(2.0 * i + (i >= 5 ? 8.0 : 0.0), 0, 1.2);
        s.heading = degToRad(3.0 * i + (i >= 5 ? 27.0 : 0.0));
        p.samples.push_back(s);
    }
    PathMotion m = pathMotion(p, {0, 1, 2, 3, 4, 5});
    EXPECT_EQ(m.frames, 6u);
    EXPECT_NEAR(m.metresMedian, 2.0, 1e-12);
    EXPECT_NEAR(m.metresMax, 10.0, 1e-12);
    EXPECT_NEAR(m.degreesMedian, 3.0, 1e-9);
    EXPECT_NEAR(m.degreesMax, 30.0, 1e-9);
    // Every other frame: twice the motion.
    PathMotion h = pathMotion(p, {0, 2, 4});
    EXPECT_NEAR(h.metresMedian, 4.0, 1e-12);
    EXPECT_NEAR(h.degreesMax, 6.0, 1e-9);
    // Heading wrap: 179 -> -179 degrees is 2 degrees of rotation, not 358.
    p.samples[1].heading = degToRad(179.0);
    p.samples[2].heading = degToRad(-179.0);
    EXPECT_NEAR(pathMotion(p, {1, 2}).degreesMax, 2.0, 1e-9);
    EXPECT_EQ(pathMotion(p, {3}).frames, 0u);
}

TEST(Paths, CoarseSamplesAreTheFineDriveSampledLess) {
    // The vehicle is simulated in steps of at most 1/30 s whatever --dt: a
    // path sampled every 0.5 s is every 15th sample of the 1/30 s path (up to
    // the rounding of 0.5 / 15), for each kind, and the car still drives.
    StreetGraph g = gridGraph();
    for (PathKind kind : {PathKind::Car, PathKind::Walk, PathKind::Fly}) {
        PathOptions fine;
        fine.kind = kind;
        fine.maxSpeed = defaultSpeed(kind);
        fine.duration = 40;
        PathOptions coarse = fine;
        coarse.dt = 0.5;
        auto a = generatePath(g, flatParams(), fine), b = generatePath(g, flatParams(), coarse);
        ASSERT_TRUE(a.isOk() && b.isOk());
        ASSERT_EQ(b->samples.size(), 81u);
        for (size_t i = 0; i < b->samples.size(); ++i) {
            const PathSample& p = a->samples[i * 15];
            EXPECT_NEAR(b->samples[i].t, p.t, 1e-9);
            EXPECT_LT(glm::length(b->samples[i].position - p.position), 1e-3) << pathKindName(kind) << " " << i;
        }
    }
}
