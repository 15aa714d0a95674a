// The rotating LiDAR: ranges and labels against planes placed by hand (an
// analytic independent computation), each point cast from the pose of its
// firing time (a moving sensor sees a wall where it was when that column
// fired), intensity from reflectivity and incidence, misses counted, and bad
// specs refused with the field named.
#include <gtest/gtest.h>

#include <cmath>

#include "citygen/labels.h"
#include "foundation/units.h"
#include "runtime/engine/lidar.h"
#include "runtime/engine/ray_scene.h"
#include "tests/runtime/engine/fixtures.h"

using namespace vista;

namespace {

// Road from -500 to 500 m at z = 0 and, when wallY > 0, a wall 1 m thick
// whose near face is the plane y = wallY (x in [-200, 200], 50 m high).
SceneModel planes(double wallY) {
    SceneModel city;
    city.params.size_m = 1000;
    SceneMesh road;
    road.material = Material::Road;
    test::addGround(road, glm::vec2(-500.0f), glm::vec2(500.0f), 0.0f, {90, 90, 90, 255});
    city.meshes.push_back(road);
    if (wallY > 0) {
        SceneMesh wall;
        wall.material = Material::Wall;
        test::addBox(wall, {-200.0f, float(wallY), 0.0f}, {200.0f, float(wallY) + 1.0f, 50.0f}, {200, 180, 160, 255});
        city.meshes.push_back(wall);
    }
    city.triangles = 0;
    for (const auto& m : city.meshes) city.triangles += m.indices.size() / 3;
    return city;
}

}  // namespace

TEST(Lidar, GroundRangesLabelsAndIntensityMatchTheGeometry) {
    const SceneModel city = planes(0);
    auto rays = RayScene::build(city);
    ASSERT_TRUE(rays.isOk()) << rays.status().message();
    LidarSpec spec;
    spec.elevationDeg = evenBeamTable(16, -15.0, 15.0);
    spec.columns = 360;
    spec.maxRange = 100;
    const double h = 2.0;
    LidarPose pose;
    pose.position = {3.0, -4.0, h};
    pose.heading = 0.7;
    const LidarSweep s = castLidarSweep(
        city, **rays, spec, [&](double) { return pose; }, 0.0);
    // Independent count: a beam returns from the road where h / sin(-el) <= maxRange.
    size_t returning = 0;
    for (double el : spec.elevationDeg)
        if (el < 0 && h / std::sin(-el * kPi / 180.0) <= spec.maxRange) ++returning;
    ASSERT_GT(returning, 0u);
    EXPECT_EQ(s.rays, 16u * 360u);
    EXPECT_EQ(s.points.size(), returning * 360u);
    EXPECT_EQ(s.misses, s.rays - s.points.size());
    for (const LidarPoint& p : s.points) {
        const double el = spec.elevationDeg[p.beam] * kPi / 180.0;
        ASSERT_LT(el, 0.0);
        EXPECT_NEAR(p.range, h / std::sin(-el), 0.01);
        EXPECT_NEAR(p.sensor.z, -h, 0.01);  // the road, h below the sensor
        EXPECT_NEAR(glm::length(p.sensor), p.range, 1e-3);
        EXPECT_EQ(p.semantic, uint8_t(SemanticClass::Road));
        EXPECT_NEAR(p.intensity, lidarReflectivity(uint8_t(SemanticClass::Road)) * std::sin(-el), 1e-4);
    }
}

TEST(Lidar, EachPointIsCastFromThePoseOfItsFiringTime) {
    // Driving north (+y) at 20 m/s toward a wall at y = 30 with one horizontal
    // beam, 10 revolutions per second: over one sweep the sensor moves 2 m.
    const double wallY = 30.0, speed = 20.0, h = 2.0;
    const SceneModel city = planes(wallY);
    auto rays = RayScene::build(city);
    ASSERT_TRUE(rays.isOk());
    LidarSpec spec;
    spec.elevationDeg = {0.0};
    spec.columns = 1000;
    spec.maxRange = 200;
    auto poseAt = [&](double t) {
        LidarPose p;
        p.position = {0.0, speed * t, h};
        return p;
    };
    const double t0 = 0.25;
    const LidarSweep s = castLidarSweep(city, **rays, spec, poseAt, t0);
    size_t wall = 0, wouldBeOff = 0;
    for (const LidarPoint& p : s.points) {
        if (p.semantic != uint8_t(SemanticClass::BuildingWall)) continue;
        ++wall;
        // Independent reconstruction: x forward = +y world, y left = -x world.
        const LidarPose at = poseAt(t0 + double(p.time));
        const glm::dvec3 world = at.position + glm::dvec3(-p.sensor.y, p.sensor.x, p.sensor.z);
        EXPECT_NEAR(world.y, wallY, 0.01) << "time " << p.time;
        // The range a ray from that pose at the column's azimuth travels to the plane.
        const double az = std::atan2(double(p.sensor.y), double(p.sensor.x));
        EXPECT_NEAR(p.range, (wallY - at.position.y) / std::cos(az), 0.01);
        // Cast from the sweep's first pose instead, the point would be off the wall.
        const glm::dvec3 fromStart = poseAt(t0).position + glm::dvec3(-p.sensor.y, p.sensor.x, p.sensor.z);
        if (std::abs(fromStart.y - wallY) > 0.5) ++wouldBeOff;
    }
    EXPECT_GT(wall, 300u);        // the wall fills most of the forward half
    EXPECT_GT(wouldBeOff, 100u);  // motion within the sweep matters
    // Firing times cover the sweep in column order.
    for (size_t i = 1; i < s.points.size(); ++i) EXPECT_GE(s.points[i].time, s.points[i - 1].time);
    EXPECT_LT(s.points.back().time, 1.0 / spec.rotationHz);
}

TEST(Lidar, SpinDirectionAndStartAzimuthOrderTheColumns) {
    const SceneModel city = planes(30.0);
    auto rays = RayScene::build(city);
    ASSERT_TRUE(rays.isOk());
    LidarSpec spec;
    spec.elevationDeg = {0.0};
    spec.columns = 8;
    spec.startAzimuthDeg = 0.0;  // first column straight ahead, at the wall
    for (bool cw : {true, false}) {
        spec.clockwise = cw;
        const LidarSweep s = castLidarSweep(
            city, **rays, spec,
            [](double) {
                return LidarPose{{0, 0, 2}};
            },
            0.0);
        // Columns at 0, 45 and 315 degrees face the wall (45 deg: y left > 0 counter-clockwise).
        ASSERT_EQ(s.points.size(), 3u);
        EXPECT_NEAR(s.points[0].sensor.y, 0.0f, 1e-3);
        EXPECT_EQ(s.points[1].sensor.y > 0, !cw) << (cw ? "clockwise" : "counter-clockwise");
    }
}

TEST(Lidar, NearerThanTheMinimumRangeIsAMiss) {
    const SceneModel city = planes(0);
    auto rays = RayScene::build(city);
    ASSERT_TRUE(rays.isOk());
    LidarSpec spec;
    spec.elevationDeg = {-90.0, -30.0};  // 2 m and 4 m to the road
    spec.columns = 4;
    spec.minRange = 3.0;
    const LidarSweep s = castLidarSweep(
        city, **rays, spec,
        [](double) {
            return LidarPose{{0, 0, 2}};
        },
        0.0);
    EXPECT_EQ(s.points.size(), 4u);
    EXPECT_EQ(s.misses, 4u);
    for (const auto& p : s.points) EXPECT_EQ(p.beam, 1);
}

TEST(Lidar, BadSpecsNameTheField) {
    auto message = [](const LidarSpec& s) { return validateLidarSpec(s).message(); };
    LidarSpec ok;
    ok.elevationDeg = evenBeamTable(64, -24.8, 2.0);
    EXPECT_TRUE(validateLidarSpec(ok).isOk());
    LidarSpec s = ok;
    s.elevationDeg.clear();
    EXPECT_NE(message(s).find("beams"), std::string::npos);
    s = ok;
    s.elevationDeg[3] = 91;
    EXPECT_NE(message(s).find("elevation"), std::string::npos);
    s = ok;
    s.columns = 0;
    EXPECT_NE(message(s).find("columns"), std::string::npos);
    s = ok;
    s.maxRange = s.minRange;
    EXPECT_NE(message(s).find("max_range"), std::string::npos);
    s = ok;
    s.rotationHz = std::nan("");
    EXPECT_NE(message(s).find("rotation_hz"), std::string::npos);
    const auto t = evenBeamTable(64, -24.8, 2.0);
    EXPECT_DOUBLE_EQ(t.front(), -24.8);
    EXPECT_DOUBLE_EQ(t.back(), 2.0);
}
