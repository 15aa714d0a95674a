// Appearance of the sampled points (thesis 5.3.3, 5.4.2, 5.4.3): Monte Carlo
// integration of the plenoptic image function per point into texelsX x
// texelsY texels over the sampling rectangle, then compression.
//
// Per texel i of point p: viewpoints s on the sampling plane drawn from a
// Gaussian around the texel centre (sigma = viewSigma texel widths, clamped to
// the rectangle); an occlusion ray s -> p (v_j: samples where p is hidden are
// rejected); a pixel ray from s towards p offset by a uniform sub-pixel
// position (random camera orientation) plus a Gaussian of pixelSigma output
// pixels (the monitor filter q_j); its first hit's prelit colour, or the sky
// colour (lighting.h) on a miss. Pass 1 takes minSamples visible samples per
// texel; if the pooled luma standard deviation is below singleColorThreshold
// the point gets one colour. With significance > 0 a one-way analysis of
// variance over the texels decides whether the colour depends on the viewpoint
// at all: if the F statistic of the texels' luma (between-texel over
// within-texel mean square) is below the F(k-1, N-k) quantile at 1 -
// significance, the spread is Monte Carlo noise (e.g. a pixel filter covering
// several surfaces, the same from every viewpoint) and the point gets one
// colour, the mean of all its samples. Otherwise each texel continues until the
// standard error of its luma mean is below varianceThreshold (or maxSamples),
// and the test is repeated on the final samples. Texels
// whose samples never see p take the mean of the others; a point never seen
// from any sample is dropped (not visible from the view cell).
// Visibility pre-pass (when `cell` is given): a point hidden (within the far
// field) from the cell's 8 corners, its centre and cellVisibilityRays - 9
// random cell positions is dropped before any Monte Carlo work.
// Compression: a point whose texel colours differ by less than
// singleColorThreshold (max channel std dev) becomes single-coloured.
// Colours are 0..1 floats of the 8-bit prelit values (no gamma;
// RayScene::hitColor).
// Determinism: point k draws from Rng(seed, hashKeys(entity, k), Stream::Bake);
// points are processed in parallel into fixed slots.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "bake/sampling_plane.h"
#include "runtime/engine/ray_scene.h"
#include "nodes/point_impostor.h"

namespace vista {

struct AppearanceParams {
    int texelsX = 8, texelsY = 2;
    int minSamples = 2;                       // visible samples per texel in pass 1
    int maxSamples = 8;                       // per texel
    double varianceThreshold = 2.0 / 255;     // std error of the texel luma mean (0..1)
    double singleColorThreshold = 3.0 / 255;  // std dev (0..1) below which one colour suffices
    double significance = 0.01;               // F-test level for view dependence (0 = off)
    double viewSigma = 0.5;                   // texel widths
    double pixelSigma = 0.5;                  // output pixels
    double pixelAngle = 0.0024;               // radians per output pixel (from SamplingParams)
    int cellVisibilityRays = 17;              // visibility pre-pass from the view cell (0 = off)
};

struct AppearanceStats {
    int64_t rays = 0;     // occlusion + pixel rays
    int64_t samples = 0;  // visible samples
    size_t dropped = 0;   // points never visible
    size_t singleColor = 0;
    size_t textured = 0;
    size_t noiseOnly = 0;  // points made single-coloured by the F test
};

// Fills `out` (positions, colours, blocks, texels, plane) from `points` (frame
// coordinates). Returns the indices of the kept points in `kept` (ascending).
// `scene` holds the far field in the impostor frame (RayScene::build(soup)).
void computeAppearance(const RayScene& scene, const SamplingSetup& s, const std::vector<glm::vec3>& points,
                       const AppearanceParams& p, uint64_t seed, uint64_t entity, PointImpostorData& out,
                       AppearanceStats& stats, std::vector<uint32_t>* kept = nullptr, const Box3* cell = nullptr);

}  // namespace vista
