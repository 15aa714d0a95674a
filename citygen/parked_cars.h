// Parked cars: a few procedural low-poly car models and where they stand.
//
// carModels(): kCarModelCount models (hatchback, sedan, estate, SUV), each a
// body box, a cabin with sloped windscreen and rear window, and four wheels:
// kCarTriangles triangles, 4.0 .. 4.8 m long, 1.74 .. 1.9 m wide, 1.45 .. 1.6 m
// tall. Body colours come from a palette of kCarColourCount albedos.
// placeParkedCars(): candidate slots, then a greedy filter:
// - curb slots: along each side of every street road (lane model, lanes.h),
//   parallel to the carriageway, facing the traffic of that side, in the
//   strip directly outside the carriageway where it has room: a side without
//   sidewalk, or a sidewalk at least car width + kKerbGap + kMinWalkway wide
//   (the car stands on the sidewalk at its kerb side, leaving the walkway);
//   slots every kCurbSlot metres along the trimmed reference line;
// - lot slots: along every street frontage of every lot (the lot edges on its
//   block outline), every kLotSlot metres, the car parallel to the frontage
//   (front yard) or nose to it (driveway), kYardGap inside the lot.
// Each slot is kept with probability params.parked_car_share from its own
// stream (Rng(seed, slot key, Stream::Cars)), which also picks the model,
// colour and a small jitter. In canonical order (tile, then position) a slot
// becomes a car only if its footprint (an oriented rectangle grown by
// kCarClearance) lies inside the city square, inside its lot (lot slots),
// and overlaps no carriageway (node to node, half carriageway wide), no
// junction or link road area (a disc around every street node of degree >= 2
// of radius max(junction radius, trims at the node + half carriageway) +
// kCarClearance), no building footprint, no tree (the crown's radius around
// the trunk), no street light, no signal pole and no car kept before.
// z: the terrain at the centre, plus the sidewalk's lift on a sidewalk.
// Deterministic (the same params and city give the same cars, whatever the
// thread count); empty for parked_car_share 0.
// meshParkedCar(): the car's triangles into `mesh` (Material::Car, prelit
// from fixed albedos, counter-clockwise outward faces), positions relative to
// `origin` (city frame), every vertex carrying the label `id` (labels.h).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/city.h"
#include "citygen/lanes.h"
#include "citygen/lighting.h"
#include "citygen/mesh.h"

namespace vista {

constexpr int kCarModelCount = 4;
constexpr int kCarColourCount = 8;
constexpr size_t kCarTriangles = 54;   // per car, every model
constexpr double kCurbSlot = 6.5;      // metres of curb per slot
constexpr double kLotSlot = 7.0;       // metres of lot frontage per slot
constexpr double kKerbGap = 0.15;      // car side to the carriageway edge
constexpr double kMinWalkway = 1.0;    // sidewalk left free beside a car on it
constexpr double kYardGap = 0.6;       // car to the lot's frontage edge
constexpr double kCarClearance = 0.3;  // free margin around a car's footprint

struct CarModel {
    const char* name;
    double length, width, height;  // metres (wheels to roof)
    double clearance;              // body bottom above the ground
    double belt;                   // top of the body box (bonnet, boot) above the ground
    double cabinFront, cabinRear;  // cabin foot along the car from its centre (front positive)
    double roofFront, roofRear;    // roof edges along the car
    double wheelBase, wheelRadius;
};

const std::array<CarModel, kCarModelCount>& carModels();
glm::dvec3 carColour(int colour);  // linear albedo of palette entry `colour` (0 .. kCarColourCount-1)

// The car's footprint (length x width around position, turned by yaw), counter-clockwise.
std::vector<glm::dvec2> carFootprint(const ParkedCar& car);

std::vector<ParkedCar> placeParkedCars(const City& city, const LaneModel& lanes);
void meshParkedCar(const ParkedCar& car, const glm::dvec3& origin, const Lighting& light, Mesh& mesh, uint32_t id);
// The shape meshParkedCar() draws, for any model (the moving vehicles' vans,
// buses and trucks too): body in `bodyAlbedo`, footprint centred on
// `position` (ground level), front along `yaw`, every vertex of `material`
// and label `id`, positions relative to `origin`.
void meshCarShape(const CarModel& m, const glm::dvec3& bodyAlbedo, const glm::dvec3& position, double yaw,
                  const glm::dvec3& origin, const Lighting& light, Material material, Mesh& mesh, uint32_t id);

}  // namespace vista
