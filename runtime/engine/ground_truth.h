// Ground truth per frame (`vista render`): instance id, semantic class and
// metric depth per pixel, and the ray-cast half of it.
//
// LabelImage: row 0 at the top, width * height entries each. ids: instance
// ids (citygen/labels.h), 0 = sky / terrain; classes: SemanticClass, 0 = sky;
// depth: z-depth in metres along the camera's optical axis (eye-space -z,
// i.e. the distance of the hit point from the camera plane, not along the
// ray), +infinity for sky.
// rayLabel(): the label of a hit of a city RayScene built from `city`:
// mesh hits take the class of the mesh's material and the id of the hit
// triangle's first vertex; tree hits the instance's id and the class of the
// prototype part (trunk / leaves). A hit on geometry without labels gives
// id 0 and the material's class (Count -> 255 for unknown geometry).
// castLabels(): casts the camera's pixel-centre rays (far_field_rays.h
// PixelRays, the rasteriser's sample points) of `pixels` (indices y * width
// + x) from the eye, starting at the near plane (tnear = zNear / cos), and
// writes their labels into `out` (which has the camera's size). Parallel over
// `threads` workers (0 = all); deterministic. Thread-safe for distinct outputs.
// mergeLabels(): the labels of a frame whose near field was rasterised by the
// label pass (`raster`: the camera's size, row 0 at the top, depth 0 =
// nothing drawn) and whose other pixels come from rays. A drawn pixel keeps
// its raster label when `nearDistance` is unlimited (>= 1e299) or its hit
// lies within nearDistance metres of the eye along its pixel ray (PixelRays);
// every other pixel is cast (castLabels) when `rays` is not null and either a
// near distance applies or `castUncovered` (the far field fills uncovered
// pixels, as hybrid's does), else it stays sky. `out` is resized to the
// camera. Returns the number of pixels cast. Deterministic.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "runtime/scene/camera.h"
#include "runtime/scene/scene_model.h"

namespace vista {

class RayScene;
struct RayHit;

struct LabelImage {
    int width = 0, height = 0;
    std::vector<uint32_t> ids;
    std::vector<uint8_t> classes;
    std::vector<float> depth;
    void resize(int w, int h);  // every pixel sky
};

struct PixelLabel {
    uint32_t id = 0;
    uint8_t cls = 0;
};
PixelLabel rayLabel(const SceneModel& city, const RayScene& rays, const RayHit& hit);

void castLabels(const SceneModel& city, const RayScene& rays, const Camera& camera, const std::vector<uint32_t>& pixels,
                LabelImage& out, int threads = 0);

struct RasterLabels {
    const uint32_t* ids = nullptr;
    const uint8_t* classes = nullptr;
    const float* depth = nullptr;
};
size_t mergeLabels(const SceneModel& city, const RayScene* rays, const Camera& camera, const RasterLabels& raster,
                   double nearDistance, bool castUncovered, LabelImage& out, int threads = 0);

// .npy (format 1.0) bytes of a row-major height x width array of little-endian
// float32 ("<f4") or uint32 ("<u4") values.
std::string npyBytes(const float* data, int width, int height);
std::string npyBytes(const uint32_t* data, int width, int height);

}  // namespace vista
