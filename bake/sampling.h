// Geometric sampling of one far field for one view cell (thesis 5.3.2, 5.4.1).
//
// All positions are in the impostor frame (metres, double), where the far
// field's box `far` and the view cell box `cell` are axis-aligned boxes.
//  1. Sampling plane: normal n = horizontal direction from the cell centre to
//     the far-box centre; the plane touches the cell on its far-field side
//     (dot(n, x) = max over the cell corners), so every viewing ray from the
//     cell to the far field crosses it inside the shaft.
//  2. Shaft polygon: the convex hull of the cell and the far box (the region
//     bounded by their supporting planes) cut by the sampling plane: the
//     convex hull of the crossings of the 64 corner-to-corner segments.
//  3. Bounding triangle: top edge parallel to the ground (along U), minimum
//     circumference, containing the polygon (2D search over the two side
//     directions, each side a supporting line).
//  4. Three perspective LDI cameras at the triangle corners, looking along n
//     with an off-axis frustum around the far box. Angular step from the
//     circumcentre criterion: alpha = delta * D^2 / (R^2 + D^2) / (fp * sqrt2)
//     / oversample, where delta = output pixel angle (2 tan(fovY/2) / H),
//     D = nearest far-box depth in front of the plane, R = circumradius,
//     fp = SamplingParams::perspective (default 1.17, the thesis' factor; the
//     exact 1 / cos^2(fovY/2) would be 1.33 at the image corner for 60 deg, but
//     a far field seen along the street lies near the image centre), sqrt2 =
//     pixel diagonal.
//  5. Multi-layer hits (FarScene::allHits) clipped to the far box.
//  6. Removal of points sampled better (smaller footprint) and sufficiently
//     by another camera that has a sample of the same surface there.
//     Sufficient: that camera's pixel steps, moved onto the surface plane and
//     projected into the target view from the nearest cell point and the 8
//     cell corners, span a lattice whose triangulation edges (reduced basis,
//     plus the shorter diagonal with the sqrt2 factor) are <= 1 pixel / fp.
// Contract: setupSampling() returns an error when the far box is not strictly
// in front of the sampling plane (cell touching or intersecting the far box)
// or a box is empty/non-finite; otherwise the cameras lie on the plane, never
// inside the far box, and every far-box corner is in front of every camera.
// Deterministic: LDI rows are traced in parallel into per-row buffers that are
// concatenated in order. Thread-safe (no shared state).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "bake/far_scene.h"
#include "foundation/status.h"

namespace vista {

struct Box3 {
    glm::dvec3 lo{0.0}, hi{0.0};
    bool valid() const;
    glm::dvec3 center() const { return 0.5 * (lo + hi); }
    glm::dvec3 corner(int i) const { return {(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z}; }
    double distance(const glm::dvec3& p) const;  // 0 inside
    bool contains(const glm::dvec3& p, double eps = 0) const;
};

struct SamplingParams {
    int outWidth = 640, outHeight = 480;  // target output resolution
    double fovYDeg = 60.0;                // target output vertical field of view
    double oversample = 1.0;              // multiplies the LDI resolution (per axis)
    double perspective = 1.17;            // fp, the perspective factor (1 = off)
    bool diagonalFactor = true;           // x sqrt(2)
    int maxLayers = 6;                    // LDI layers per pixel (3 left holes behind adjacent boxes: test)
    int64_t maxRaysPerCamera = 1000000;   // resolution cap (the step grows if exceeded)
    bool removeRedundant = true;
};

struct SamplingSetup {
    glm::dvec3 n{1, 0, 0}, U{0, -1, 0}, V{0, 0, 1};  // plane normal, right, up (orthonormal)
    double planeD = 0;                                // plane: dot(n, x) = planeD
    std::vector<glm::dvec2> polygon;                  // shaft cut, plane coords (U, V), counter-clockwise
    glm::dvec2 rectLo{0.0}, rectHi{0.0};              // bounding rectangle of the polygon
    std::array<glm::dvec2, 3> tri{};                  // bounding triangle: top-left, top-right, bottom
    std::array<glm::dvec3, 3> cameras{};              // triangle corners in the frame
    glm::dvec2 circumcentre{0.0};
    double circumradius = 0;
    double dNear = 0;   // nearest far-box depth in front of the plane
    double dFar = 0;    // farthest

    glm::dvec3 toFrame(const glm::dvec2& q) const { return n * planeD + U * q.x + V * q.y; }
};

// Convex hull (counter-clockwise, no collinear points). Exposed for tests.
std::vector<glm::dvec2> convexHull2D(std::vector<glm::dvec2> pts);
double trianglePerimeter(const std::array<glm::dvec2, 3>& t);
// Minimum-circumference triangle with a top edge parallel to the x axis that
// contains the convex polygon `poly` (non-empty). Returns top-left, top-right, bottom.
std::array<glm::dvec2, 3> boundingTriangle(const std::vector<glm::dvec2>& poly);

Result<SamplingSetup> setupSampling(const Box3& cell, const Box3& far);

double outputPixelAngle(const SamplingParams& p);  // radians per output pixel at the image centre
double exactPerspectiveFactor(const SamplingParams& p);   // 1 / cos^2(fovY / 2), for reference
// The LDI angular step (tangent units) from the circumcentre criterion.
double ldiStep(const SamplingSetup& s, const SamplingParams& p);

struct LdiCamera {
    glm::dvec3 pos{0.0};
    double x0 = 0, y0 = 0;   // tangent-plane coordinates of the lower-left image corner
    double step = 0;         // tangent units per pixel
    int width = 0, height = 0;
};

struct LdiSample {
    glm::vec3 pos{0.0f}, normal{0.0f}, color{0.0f};
    float spacing = 0;   // footprint of the camera pixel on the surface (metres)
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

LdiResult sampleLdi(const FarScene& scene, const SamplingSetup& s, const Box3& far, const SamplingParams& p);

// Footprint (metres) of camera `c`'s pixel at p on a surface with normal nrm.
double footprint(const LdiCamera& c, const SamplingSetup& s, const glm::dvec3& p, const glm::dvec3& nrm);

// keep[i] = false for samples sampled better and sufficiently by another camera.
std::vector<uint8_t> removeRedundant(const LdiResult& ldi, const SamplingSetup& s, const Box3& cell, const SamplingParams& p);

}  // namespace vista
