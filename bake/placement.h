// Impostor placement by cost (thesis 5.5 "placement
// strategies"): before a street end's far field is baked, estimate from the
// view cell what drawing it costs and what its point impostor would cost,
// and bake an impostor only where it saves more than it costs.
//
// Estimate (a sampled from-region visibility, not a conservative one): rays
// of the whole city's ray scene (occluders included) from a grid of points
// over the cell (samplesAlong x samplesAcross at the box's centre height)
// into the angular box that the far field's bounding box covers, one ray per
// `rayStepPx` output pixels (SamplingParams: output pixel angle), at most
// maxRaysPerSample per point (the step grows). A ray whose first hit lies in
// a tile of the far set sees the far field. Per sample point: far pixels =
// such rays x rayStepPx^2; the estimate takes the mean over the points.
//   saved  = far-set triangles x triangleNs      (drawn as geometry otherwise)
//   cost   = pointsPerFarPixel x far pixels x pointNs (the points drawn instead)
// place iff saved > cost. triangleNs / pointNs: the raster costs measured on
// this machine (llvmpipe: 349 ns per triangle, 495 ns per point);
// pointsPerFarPixel: points a bake makes per visible far pixel (measured on a
// whole bake; docs/measurements/bake.md).
//
// Deterministic: depends on (city, cell, far set, params) only; rays are cast
// in a fixed order (rows of coherent packets) on the calling thread. Thread-safe on a const scene.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "bake/far_set.h"
#include "bake/ldi_sampling.h"
#include "bake/view_cells.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

// `vista bake --storage-budget auto`: MB of impostor data per km2 of the
// street graph's bounding box (the thesis stored 165 MB for 4 km2; docs/reference/bake.md).
constexpr double kAutoBudgetMbPerKm2 = 25.0;

struct PlacementParams {
    bool byCost = false;        // false: every end with a far field gets an impostor (--placement all)
    double triangleNs = 349.0;  // raster cost of a triangle, ns (> 0)
    double pointNs = 495.0;     // raster cost of a point, ns (> 0)
    double pointsPerFarPixel =
        31.0;  // points the bake makes per visible far pixel (> 0; the default city baked whole under its storage
               // budget: sum of points / sum of estimated far pixels over its impostors)
    double bytesPerPoint = 15.0;  // stored bytes per point, texels included (> 0; the same bake)
    // Storage budget (planPlacement): 0 = none; else the street ends whose
    // impostors save the most milliseconds per predicted megabyte, until the
    // predicted megabytes reach budgetMb. `vista bake` sets it from
    // --storage-budget (default: budgetMbPerKm2 x the street graph's area).
    double budgetMb = 0;
    double budgetMbPerKm2 = 0;  // > 0: the driver sets budgetMb from the street graph's bounding box
    // How a viewpoint tests the points (visibleFromCell): true = a depth image
    // of the city from the viewpoint first (one ray per visStepPx output
    // pixels, at most maxVisRaysPerView; points more than visMaxTan off its
    // axis skip it), then an occlusion ray for the points it leaves;
    // false = an occlusion ray for every point (--visibility rays).
    int samplesAlong = 5, samplesAcross = 3;
    double rayStepPx = 2.0;  // output pixels per estimation ray (per axis)
    int maxRaysPerSample = 40000;
    // From-region visibility of the baked points (visibleFromCell): viewpoints
    // per axis along x across x heights.
    int visAlong = 7, visAcross = 3, visHeights = 1;
    bool visByImage = true;
    double visStepPx = 1.0;
    int64_t maxVisRaysPerView = 1000000;
    double visMaxTan = 1.5;
};

// Which tile (root child index) a city ray hit struck: mesh -> tile, instance
// -> tile (from bakeTiles()).
struct TileLookup {
    std::vector<int32_t> meshTile, instanceTile;
    static TileLookup build(const SceneModel& city, const std::vector<SceneTile>& tiles);
    int32_t tileOf(const HitSource& s) const;
};

struct PlacementEstimate {
    double farPixels = 0;     // mean over the sample points
    double maxFarPixels = 0;  // largest over the sample points
    int64_t rays = 0, farHits = 0;
    double savedMs = 0, costMs = 0;
    bool place = true;
    std::string describe() const;  // "saves X ms, costs Y ms (Z far pixels)"
};

// Predicted stored megabytes of the end's impostor: pointsPerFarPixel x far
// pixels x bytesPerPoint.
double predictedMb(const PlacementEstimate& e, const PlacementParams& p);

// `cityRays` = RayScene::build(city) (scene-local frame around its frameOrigin()).
PlacementEstimate estimatePlacement(const RayScene& cityRays, const TileLookup& tiles, const ViewCell& cell,
                                    const FarSet& fs, const SamplingParams& sampling, const PlacementParams& p);

// The placement of a whole city under a storage budget: every street end
// whose far field is large enough is estimated (estimatePlacement); the ends
// that pay (place) are ranked by (saved - cost) ms per predicted MB,
// descending (ties: cell id, end), and taken in that order while the sum of
// their predicted MB stays within p.budgetMb (an end that does not fit is
// passed over; smaller ones after it may still fit).
struct PlannedEnd {
    uint32_t cell = 0;
    uint8_t end = 0;
    PlacementEstimate estimate;
    double predictedMb = 0;
    int rank = -1;                 // 0-based among the ends that pay; -1 if it does not pay
    bool inBudget = false;         // chosen: bake its impostor
    std::string describe() const;  // the note of the end: placed / not placed and why
};
struct PlacementPlan {
    std::vector<PlannedEnd> ends;                     // sorted by (cell, end)
    double budgetMb = 0, chosenMb = 0, payingMb = 0;  // predicted MB of the chosen / of all paying ends
    size_t chosen = 0, paying = 0;
    const PlannedEnd* find(uint32_t cell, int end) const;  // null if the end was not estimated
};
// Ranks the estimates (any order; each with its predictedMb) under the budget.
PlacementPlan rankPlacement(std::vector<PlannedEnd> ends, double budgetMb);

// Points (impostor-frame metres, as the bake makes them) that at least one
// viewpoint of the cell sees through the whole city. Viewpoints: a grid of
// visAlong x visAcross x visHeights over the cell box, the centre first; each
// tests the points not yet seen. A point is seen from v when the city leaves
// the segment from v to it open up to 0.1 m + 0.2 % short of the point (its
// own surface does not count). p.visByImage = false: one occlusion ray of
// cityRays per point and viewpoint (exact for the viewpoints). true (the
// default): per viewpoint first a planar depth image of the city over the
// points' directions (axis: towards the points' centroid), one ray per
// p.visStepPx output pixels (pixelAngle radians); only the points that the
// farthest first hit of the 4 image rays around their direction reaches
// (or more than visMaxTan off the axis) get the occlusion ray. The result
// is the rays' result minus points seen only through a gap narrower than an
// image pixel; the work drops from one ray per point and viewpoint to the
// image's rays plus a projection per point. Either way sampled over the cell, not conservative: a
// point seen only from between the viewpoints can be lost. The far field's
// own occlusion counts too (the far tiles are in the city).
// Parallel over rays and points; the result depends on the inputs only.
std::vector<uint8_t> visibleFromCell(const RayScene& cityRays, const ViewCell& cell, const ImpostorFrame& f,
                                     const std::vector<glm::vec3>& points, double pixelAngle, const PlacementParams& p);

}  // namespace vista
