// Crossing junction lanes as wide as their conflict (junction_conflicts.h):
// the distance a foe vehicle needs to clear a crossing lane against the
// closed form for straight lanes crossing at an angle, SUMO's own estimate
// (half the lane width) short of it at a slant; the net edit widening
// exactly the ego lanes of foe pairs to twice that distance, every other
// byte kept; bad files are errors that leave the file as it was.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "foundation/units.h"
#include "runtime/traffic/junction_conflicts.h"
#include "tests/common/temp_dir.h"

using namespace vista;
using vista::test::readBytes;
using vista::test::TempDir;
using vista::test::writeText;

namespace {

// A straight foe lane through (10, 0) at `deg` degrees to the ego lane (the
// x axis from 0 to 20), 10 m either side of the crossing.
Polyline2 slantedFoe(double deg) {
    const double a = degToRad(deg);
    return {{10.0 - 10.0 * std::cos(a), -10.0 * std::sin(a)}, {10.0 + 10.0 * std::cos(a), 10.0 * std::sin(a)}};
}

// A foe vehicle of width b on a straight lane crossing at angle a leaves the
// band |y| < egoWidth / 2 when its rear corner does: back distance s past
// the crossing with s sin a - (b / 2) cos a = egoWidth / 2.
double closedForm(double deg, double egoWidth, double foeWidth) {
    const double a = degToRad(deg);
    return (0.5 * egoWidth + 0.5 * foeWidth * std::cos(a)) / std::sin(a);
}

}  // namespace

TEST(JunctionConflicts, ClearanceOfStraightCrossingsMatchesTheClosedForm) {
    const Polyline2 ego = {{0.0, 0.0}, {20.0, 0.0}};
    for (double deg : {90.0, 60.0, 45.0, 30.0}) {
        for (double width : {1.8, 2.5}) {
            const double h = conflictHalfWidth(ego, slantedFoe(deg), width, 4.5, width);
            const double expect = closedForm(deg, width, width);
            EXPECT_GE(h, expect - 1e-9) << deg << " deg, width " << width;
            EXPECT_LT(h, expect + kConflictStepM + 1e-9) << deg << " deg, width " << width;
        }
    }
    // SUMO's estimate is half the lane width (3.25 m lanes): enough at right
    // angles, short by half a metre for cars at 45 degrees.
    EXPECT_LT(conflictHalfWidth(ego, slantedFoe(90.0), 1.8, 4.5, 1.8), 0.5 * 3.25);
    EXPECT_GT(conflictHalfWidth(ego, slantedFoe(45.0), 1.8, 4.5, 1.8), 0.5 * 3.25 + 0.5);
    // No crossing: nothing to clear.
    EXPECT_EQ(conflictHalfWidth(ego, {{0.0, 5.0}, {20.0, 6.0}}, 1.8, 4.5, 1.8), 0.0);
}

TEST(JunctionConflicts, ATurnStillBendingCountsUntilItsBodyHasLeftTheLane) {
    // A left turn of radius 12 m: a quarter circle from (0, 0) heading +y to
    // (-12, 12) heading -x (centre (-12, 0)), crossing the ego lane y = 6 at
    // 60 degrees, 2 pi m along the turn. Written out: the corners of a car
    // whose back is d past the crossing (its front 4.5 m on along the arc);
    // it is clear when every corner lies above y = 6 + 0.9.
    const double r = 12.0;
    Polyline2 turn;
    for (int i = 0; i <= 180; ++i) {
        const double a = degToRad(0.5 * i);
        turn.push_back({-12.0 + r * std::cos(a), r * std::sin(a)});
    }
    const Polyline2 ego = {{-30.0, 6.0}, {5.0, 6.0}};
    auto lowestCorner = [&](double d) {
        const double s = r * kPi / 6.0 + d, ab = s / r, af = (s + 4.5) / r;
        const double bx = -12.0 + r * std::cos(ab), by = r * std::sin(ab);
        const double fx = -12.0 + r * std::cos(af), fy = r * std::sin(af);
        const double len = std::hypot(fx - bx, fy - by), ny = (fx - bx) / len * 0.9;
        return std::min({by + ny, by - ny, fy + ny, fy - ny});
    };
    const double h = conflictHalfWidth(ego, turn, 1.8, 4.5, 1.8);
    EXPECT_GT(lowestCorner(h), 6.9 - 0.01) << h;  // the polyline's chords sit inside the arc by < 1 mm
    EXPECT_LT(lowestCorner(h - 2.0 * kConflictStepM), 6.9) << h;
    // The bend keeps the body on the lane longer than a straight lane at the
    // crossing's angle would.
    EXPECT_GT(h, closedForm(60.0, 1.8, 1.8) + 0.1);
}

namespace {

// Junction J: the straight lane :J_0_0 along x, the lane :J_1_0 crossing it
// at atan(3 / 4) (foes both ways; both 20 m long), and :J_2_0 starting where :J_0_0 starts
// (one source: never widened by it). A crossing lane is listed as a foe too.
// The pedestrian crossing :J_c1_0 meets :J_0_0 3 m from its start: :J_0_0
// may grow to 6 m at most; :J_c0_0 meets both lanes over 11 m from its
// start.
const char* kNet =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    "<net version=\"1.9\">\n"
    "    <edge id=\":J_0\" function=\"internal\">\n"
    "        <lane id=\":J_0_0\" index=\"0\" disallow=\"pedestrian\" speed=\"9.00\" length=\"20.00\" width=\"3.25\" "
    "shape=\"0.00,0.00 20.00,0.00\"/>\n"
    "    </edge>\n"
    "    <edge id=\":J_1\" function=\"internal\">\n"
    "        <lane id=\":J_1_0\" index=\"0\" allow=\"passenger\" speed=\"9.00\" length=\"20.00\" width=\"3.25\" "
    "shape=\"2.00,-6.00 18.00,6.00\"/>\n"
    "    </edge>\n"
    "    <edge id=\":J_2\" function=\"internal\">\n"
    "        <lane id=\":J_2_0\" index=\"0\" allow=\"passenger\" speed=\"9.00\" length=\"14.14\" width=\"3.25\" "
    "shape=\"0.00,0.00 10.00,10.00\"/>\n"
    "    </edge>\n"
    "    <edge id=\":J_c0\" function=\"crossing\" crossingEdges=\"a\">\n"
    "        <lane id=\":J_c0_0\" index=\"0\" allow=\"pedestrian\" length=\"7.00\" width=\"4.00\" "
    "shape=\"5.00,-15.00 5.00,5.00\"/>\n"
    "    </edge>\n"
    "    <edge id=\":J_c1\" function=\"crossing\" crossingEdges=\"b\">\n"
    "        <lane id=\":J_c1_0\" index=\"0\" allow=\"pedestrian\" length=\"6.00\" width=\"4.00\" "
    "shape=\"19.00,-3.00 19.00,3.00\"/>\n"
    "    </edge>\n"
    "    <junction id=\"J\" type=\"priority\" x=\"0\" y=\"0\" incLanes=\"a_0\" "
    "intLanes=\":J_0_0 :J_1_0 :J_2_0 :J_c0_0\" shape=\"\">\n"
    "        <request index=\"0\" response=\"0000\" foes=\"1110\" cont=\"0\"/>\n"
    "        <request index=\"1\" response=\"0001\" foes=\"0001\" cont=\"0\"/>\n"
    "        <request index=\"2\" response=\"0001\" foes=\"0001\" cont=\"0\"/>\n"
    "        <request index=\"3\" response=\"0000\" foes=\"0001\" cont=\"0\"/>\n"
    "    </junction>\n"
    "</net>\n";

}  // namespace

TEST(JunctionConflicts, TheNetEditWidensTheEgoLanesOfSlantedFoePairsOnly) {
    TempDir tmp("vista_junction_conflicts");
    const std::string path = tmp.file("n.net.xml");
    writeText(path, kNet);
    const std::vector<ConflictClass> classes = {{"passenger", 4.5, 1.8}, {"truck", 8.5, 2.5}};
    auto widened = widenConflictLanes(path, classes);
    ASSERT_TRUE(widened) << widened.status().message();
    EXPECT_EQ(*widened, 2u);
    const std::string out = readBytes(path);

    auto widthOf = [&](const char* lane) {
        const size_t at = out.find(std::string("<lane id=\"") + lane);
        const size_t w = out.find("width=\"", at) + 7;
        return out.substr(w, out.find('"', w) - w);
    };
    auto twice = [](double half) {
        char w[32];
        std::snprintf(w, sizeof w, "%.2f", std::ceil(2.0 * half * 100.0 - 1e-6) / 100.0);
        return std::string(w);
    };
    const double slant = radToDeg(std::atan2(3.0, 4.0));
    const Polyline2 lane0 = {{0, 0}, {20, 0}}, lane1 = {{2, -6}, {18, 6}};
    // :J_0_0 (ego; trucks allowed: 2.5 m) against cars on :J_1_0.
    const double h0 = conflictHalfWidth(lane0, lane1, 2.5, 4.5, 1.8);
    EXPECT_GE(h0, closedForm(slant, 2.5, 1.8) - 1e-9);
    EXPECT_LT(h0, closedForm(slant, 2.5, 1.8) + kConflictStepM + 1e-9);
    EXPECT_GT(2.0 * h0, 6.0);  // the crossing's cap decides
    EXPECT_EQ(widthOf(":J_0_0"), "6.00");
    // :J_1_0 (ego; cars: 1.8 m) against cars and trucks on :J_0_0: the wider
    // truck decides.
    const double h1 = conflictHalfWidth(lane1, lane0, 1.8, 8.5, 2.5);
    EXPECT_GT(h1, conflictHalfWidth(lane1, lane0, 1.8, 4.5, 1.8));
    EXPECT_EQ(widthOf(":J_1_0"), twice(h1));
    EXPECT_EQ(widthOf(":J_2_0"), "3.25");
    // Shrinking the widths back gives the input, byte for byte: nothing else changed.
    std::string back = out;
    for (const char* lane : {":J_0_0", ":J_1_0"}) {
        const size_t at = back.find(std::string("<lane id=\"") + lane);
        const size_t w = back.find("width=\"", at) + 7;
        back.replace(w, back.find('"', w) - w, "3.25");
    }
    EXPECT_EQ(back, kNet);
    // Run again: nothing left to widen, the bytes stay.
    auto again = widenConflictLanes(path, classes);
    ASSERT_TRUE(again);
    EXPECT_EQ(*again, 0u);
    EXPECT_EQ(readBytes(path), out);
}

TEST(JunctionConflicts, BadFilesAreErrorsAndLeaveTheFileAsItWas) {
    TempDir tmp("vista_junction_conflicts");
    const std::string missing = tmp.file("missing.net.xml");
    auto r = widenConflictLanes(missing, {{"passenger", 4.5, 1.8}});
    ASSERT_FALSE(r);
    EXPECT_NE(r.status().message().find(missing), std::string::npos) << r.status().message();

    const std::string text = kNet;
    const struct {
        const char* name;
        std::string body;
        const char* why;
    } cases[] = {
        {"truncated.net.xml", text.substr(0, text.find("</junction>")), "line"},
        {"other.net.xml", "<routes>\n</routes>\n", "not <net>"},
        {"empty.net.xml", "", "line"},
    };
    for (const auto& c : cases) {
        const std::string path = tmp.file(c.name);
        writeText(path, c.body);
        auto bad = widenConflictLanes(path, {{"passenger", 4.5, 1.8}});
        ASSERT_FALSE(bad) << c.name;
        EXPECT_NE(bad.status().message().find(path), std::string::npos) << bad.status().message();
        EXPECT_NE(bad.status().message().find(c.why), std::string::npos) << bad.status().message();
        EXPECT_EQ(readBytes(path), c.body) << c.name;
    }
    EXPECT_EQ(test::listTree(tmp.path()).size(), 3u);  // no temporary file left behind
}
