// Impostor placement by cost (issue 11, item 1; thesis 5.5 "placement
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
// this machine (docs/farfield-compare.md: llvmpipe, 349 ns per triangle, 495
// ns per point); pointsPerFarPixel: points a bake makes per visible far pixel
// (measured on the town's path cells; docs/farfield-compare.md).
//
// Deterministic: depends on (city, cell, far set, params) only; rays are cast
// in a fixed order on the calling thread. Thread-safe on a const scene.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "bake/far_set.h"
#include "bake/ldi_sampling.h"
#include "bake/view_cells.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

struct PlacementParams {
    bool byCost = false;            // false: every end with a far field gets an impostor (the old rule)
    double triangleNs = 349.0;      // raster cost of a triangle, ns (> 0)
    double pointNs = 495.0;         // raster cost of a point, ns (> 0)
    double pointsPerFarPixel = 32.0; // points the bake makes per visible far pixel (> 0; median of the town's path cells)
    int samplesAlong = 5, samplesAcross = 3;
    double rayStepPx = 2.0;         // output pixels per estimation ray (per axis)
    int maxRaysPerSample = 40000;
    // From-region visibility of the baked points (visibleFromCell): viewpoints
    // per axis along x across x heights.
    int visAlong = 7, visAcross = 3, visHeights = 1;
};

// Which tile (root child index) a city ray hit struck: mesh -> tile, instance
// -> tile (from bakeTiles()).
struct TileLookup {
    std::vector<int32_t> meshTile, instanceTile;
    static TileLookup build(const SceneModel& city, const std::vector<SceneTile>& tiles);
    int32_t tileOf(const HitSource& s) const;
};

struct PlacementEstimate {
    double farPixels = 0;        // mean over the sample points
    double maxFarPixels = 0;     // largest over the sample points
    int64_t rays = 0, farHits = 0;
    double savedMs = 0, costMs = 0;
    bool place = true;
    std::string describe() const;  // "saves X ms, costs Y ms (Z far pixels)"
};

// `cityRays` = RayScene::build(city) (scene-local frame around its frameOrigin()).
PlacementEstimate estimatePlacement(const RayScene& cityRays, const TileLookup& tiles, const ViewCell& cell, const FarSet& fs,
                                    const SamplingParams& sampling, const PlacementParams& p);

// Points (impostor-frame metres, as the bake makes them) that at least one
// viewpoint of the cell sees through the whole city (occlusion rays of
// cityRays from a grid of visAlong x visAcross x visHeights viewpoints over
// the cell box, ending 0.1 m + 0.2 % short of the point, so the point's own
// surface does not count). Sampled, not conservative: a point seen only
// from between the viewpoints can be lost (a gap of a few pixels). The far
// field's own occlusion counts too (the far tiles are in the city).
// Parallel over points; the result depends on the inputs only.
std::vector<uint8_t> visibleFromCell(const RayScene& cityRays, const ViewCell& cell, const ImpostorFrame& f,
                                     const std::vector<glm::vec3>& points, const PlacementParams& p);

}  // namespace vista
