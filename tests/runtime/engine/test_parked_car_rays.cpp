// Parked cars in the ray scene: a generated city with cars, written and
// loaded as a scene file; a ray cast straight down at a car's centre hits
// the car, and its ground-truth label (ground_truth.h rayLabel) is the car
// class with that car's own instance id. A ray beside the car sees the
// ground instead.
#include <gtest/gtest.h>

#include <cmath>

#include "citygen/generate.h"
#include "citygen/labels.h"
#include "citygen/parked_cars.h"
#include "runtime/engine/ground_truth.h"
#include "runtime/engine/lidar.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/city_file.h"
#include "tests/common/temp_dir.h"

using namespace vista;

TEST(ParkedCarRays, ARayDownAtACarReturnsItsClassAndInstanceId) {
    CityParams p;
    p.seed = 5;
    p.size_m = 500.0;
    p.tile_size_m = 125.0;
    p.origin_x = 1000.0;
    p.origin_y = -2000.0;
    p.parked_car_share = 0.5;
    auto city = generateCity(p);
    ASSERT_TRUE(city.isOk()) << city.status().message();
    ASSERT_GT(city->cars.size(), 10u);
    test::TempDir dir("vista_car_rays");
    const std::string path = dir.file("cars.osgb");
    ASSERT_TRUE(writeCityFile(*city, path).isOk());
    auto model = loadCityFile(path);
    ASSERT_TRUE(model.isOk()) << model.status().message();
    auto rays = RayScene::build(*model);
    ASSERT_TRUE(rays.isOk()) << rays.status().message();
    const glm::dvec3 origin(p.origin_x, p.origin_y, 0.0);
    const glm::vec3 down(0.0f, 0.0f, -1.0f);
    size_t checked = 0;
    for (size_t i = 0; i < city->cars.size(); i += 3) {
        const ParkedCar& car = city->cars[i];
        const glm::dvec3 eye = origin + car.position + glm::dvec3(0.0, 0.0, 30.0);
        const RayHit hit = (*rays)->intersect(glm::vec3(eye - (*rays)->frameOrigin()), down);
        ASSERT_TRUE(hit.hit) << "car " << i;
        const PixelLabel label = rayLabel(*model, **rays, hit);
        EXPECT_EQ(label.cls, uint8_t(SemanticClass::Car)) << "car " << i;
        EXPECT_EQ(label.id, makeInstanceId(InstanceKind::Car, i)) << "car " << i;
        // The roof: at most the model's height above the car's ground.
        EXPECT_NEAR(double(hit.t), 30.0 - carModels()[car.model].height, 0.35) << "car " << i;
        ++checked;
    }
    EXPECT_GT(checked, 3u);
    // Beside a car (3 m to its left, off any other car): not a car.
    size_t beside = 0;
    for (size_t i = 0; i < city->cars.size() && beside < 5; ++i) {
        const ParkedCar& car = city->cars[i];
        const glm::dvec2 side = glm::dvec2(car.position) + 3.0 * glm::dvec2(-std::sin(car.yaw), std::cos(car.yaw));
        bool nearOther = false;
        for (size_t j = 0; j < city->cars.size(); ++j)
            nearOther = nearOther || (j != i && glm::length(glm::dvec2(city->cars[j].position) - side) < 3.5);
        if (nearOther) continue;
        const glm::dvec3 eye = origin + glm::dvec3(side, car.position.z + 30.0);
        const RayHit hit = (*rays)->intersect(glm::vec3(eye - (*rays)->frameOrigin()), down);
        if (!hit.hit) continue;
        EXPECT_NE(rayLabel(*model, **rays, hit).cls, uint8_t(SemanticClass::Car)) << "beside car " << i;
        ++beside;
    }
    EXPECT_GT(beside, 0u);
    EXPECT_NE(lidarReflectivity(uint8_t(SemanticClass::Car)), lidarReflectivity(255));
}
