// LDI cameras and multi-layer sampling of one far field (thesis 5.3.2,
// 5.4.1; steps 4-5 of docs/reference/bake.md "Pipeline").
//
//  4. Three perspective LDI cameras at the bounding-triangle corners
//     (bake/sampling_plane.h), looking along n with an off-axis frustum around
//     the far box. Angular step from the circumcentre criterion:
//     alpha = delta / (fp * sqrt2) / oversample (tangent units), delta = output
//     pixel angle (2 tan(fovY/2) / H), fp = SamplingParams::perspective
//     (default 1.17, the thesis' factor; the exact 1 / cos^2(fovY/2) would be
//     1.33 at the image corner for 60 deg, but a far field seen along the
//     street lies near the image centre), sqrt2 = pixel diagonal. The planar
//     cameras' off-axis pixels already shrink by cos^2, so the thesis'
//     D^2 / (R^2 + D^2) term is not applied (docs/reference/bake.md).
//  5. Multi-layer hits (RayScene::allHitsMany: each LDI row in packets of 8)
//     clipped to the far box, up to maxLayers per pixel; each sample records its footprint.
// Positions in the impostor frame (metres). Deterministic: LDI rows are traced
// in parallel into per-row buffers concatenated in order. Thread-safe.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "bake/sampling_plane.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

struct SamplingParams {
    int outWidth = 640, outHeight = 480;  // target output resolution
    double fovYDeg = 60.0;                // target output vertical field of view
    double oversample = 1.0;              // multiplies the LDI resolution (per axis)
    double perspective = 1.17;            // fp, the perspective factor (1 = off)
    bool diagonalFactor = true;           // x sqrt(2)
    int maxLayers = 6;                    // LDI layers per pixel (3 left holes behind adjacent boxes: test)
    int64_t maxRaysPerCamera = 1000000;   // resolution cap (the step grows if exceeded)
    bool removeRedundant = true;          // step 6 (bake/point_removal.h)
};

double outputPixelAngle(const SamplingParams& p);        // radians per output pixel at the image centre
double exactPerspectiveFactor(const SamplingParams& p);  // 1 / cos^2(fovY / 2), for reference
// The LDI angular step (tangent units) from the circumcentre criterion.
double ldiStep(const SamplingSetup& s, const SamplingParams& p);

struct LdiCamera {
    glm::dvec3 pos{0.0};
    double x0 = 0, y0 = 0;  // tangent-plane coordinates of the lower-left image corner
    double step = 0;        // tangent units per pixel
    int width = 0, height = 0;
};

struct LdiSample {
    glm::vec3 pos{0.0f}, normal{0.0f}, color{0.0f};  // colour: RayScene::hitColor, 0..1
    float spacing = 0;                               // footprint of the camera pixel on the surface (metres)
    uint8_t camera = 0;
    uint32_t pixel = 0;  // j * width + i in its camera
};

struct LdiResult {
    std::array<LdiCamera, 3> cams;
    std::vector<LdiSample> samples;              // ordered by camera, pixel, layer
    std::array<std::vector<uint32_t>, 3> start;  // per camera: CSR over pixels into samples
    double requiredStep = 0;                     // from the criterion (before the cap)
    int64_t rays = 0;
};

// `scene` holds the far field in the impostor frame (RayScene::build(soup)).
LdiResult sampleLdi(const RayScene& scene, const SamplingSetup& s, const Box3& far, const SamplingParams& p);

// Footprint (metres) of camera `c`'s pixel at p on a surface with normal nrm.
double footprint(const LdiCamera& c, const SamplingSetup& s, const glm::dvec3& p, const glm::dvec3& nrm);

}  // namespace vista
