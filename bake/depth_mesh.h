// Textured depth meshes of a far field (Chen et al. 2003, single-view
// meshes; docs/reference/bake.md "Textured LOD meshes"): a perspective colour + depth
// image of the far-field soup taken with Embree from the view cell's centre,
// triangulated on its sample grid and simplified to a triangle budget.
//
// Frame: the impostor frame of (cell, street end) (bake/impostor_frame.h):
// the image camera looks along +x (away from the cell, down the street), its
// screen x axis is -y (right), its screen y axis is +z (up). Sample (i, j)
// (i = 0 .. width-1 left to right, j = 0 .. height-1 bottom to top) looks
// along (1, -(tanX0 + i step), tanY0 + j step); its depth is the distance
// along +x (view depth z), 0 for a miss (sky).
//
// Simplification: the sample grid is covered by root blocks of rootBlock x
// rootBlock sample intervals; a greedy loop splits the leaf of largest error
// into four until the next split would exceed maxTriangles or no leaf is
// worse than errorPx. A leaf's error is the largest parallax, in image
// pixels, that the two-triangle approximation of its samples shows to a
// viewer `cellRadius` metres from the eye (cellRadius |1/z - 1/z~| / step,
// 1/z~ interpolated linearly in screen space as a plane's 1/z is), over its
// hit samples only. Misses (sky) are not refined geometrically: they take the
// depth of the nearest hit in their column (else the nearest column) and are
// transparent in the texture (alpha 0; the node alpha-tests), so the
// silhouette against the sky has pixel precision at no triangle cost; leaves
// without a hit draw nothing and do not count. Cracks at
// T-junctions are closed by moving the finer leaves' vertices on a coarser
// leaf's edge onto that edge (no extra triangles). "Skins" (Chen: triangles
// joining foreground and background across a depth discontinuity) are
// dropped: a one-sample triangle whose corners all missed or with a grid
// edge marked as a discontinuity (between two hits, a jump in 1/z over 5 % of
// the depth and 3x larger than the steps on either side), and a larger leaf
// that still holds a discontinuity when the budget ran out. Texture
// coordinates are projective (nodes/textured_depth_mesh.h).
// Contract: pure and deterministic (same input, same bytes, any thread
// count); parameters are validated by the driver (bake/driver.h).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "runtime/engine/ray_scene.h"
#include "nodes/textured_depth_mesh.h"

namespace vista {

struct DepthMeshParams {
    int maxTriangles = 4000;  // per view cell (each street end's mesh gets half), 1024 .. 10^7
    int imageSize = 512;      // largest image side in pixels, 64 .. 4096
    double errorPx = 0.5;     // stop splitting below this parallax error, pixels, 0 .. 100
};

struct DepthView {
    glm::dvec3 eye{0.0};                    // frame coordinates
    double tanX0 = 0, tanY0 = 0, step = 1;  // tangent of sample (0, 0) and the step per sample
    int width = 0, height = 0;              // samples (width - 1, height - 1 multiples of rootBlock)
    int rootBlock = 32;
    glm::dvec3 direction(double i, double j) const { return {1.0, -(tanX0 + i * step), tanY0 + j * step}; }  // not unit
};

// The view from `eye` covering the soup's vertices (horizontal tangent clamped
// to +-tan 60 deg, vertical to [-tan 45, tan 60 deg]), step = the larger of
// minStep (the target's pixel angle) and the extent / (imageSize - 1); the
// root block grows (32, 64, ...) until the root blocks take at most a quarter
// of maxEndTriangles. Vertices with x <= eye.x + 1 m are ignored.
DepthView chooseDepthView(const TriangleSoup& soup, const glm::dvec3& eye, double minStep, int imageSize,
                          int maxEndTriangles);

struct FarImage {
    DepthView view;
    std::vector<glm::u8vec4> color;  // width * height, row 0 at the bottom; miss = (0, 0, 0, 0)
    std::vector<float> depth;        // view depth z (metres along +x); 0 = miss
};
// One ray per sample through `scene` (the far-field soup, back faces culled).
FarImage renderFarImage(const RayScene& scene, const DepthView& view);

struct DepthMeshStats {
    uint64_t samples = 0, hits = 0, leaves = 0, triangles = 0, droppedTriangles = 0, snapped = 0;
    double maxLeafErrorPx = 0;  // largest finite error of a kept leaf
};

// The simplified textured depth mesh of `img` (at most maxTriangles triangles).
TexturedDepthMeshData buildDepthMesh(const FarImage& img, double cellRadius, int maxTriangles, double errorPx,
                                     DepthMeshStats& stats);

}  // namespace vista
