// CameraRayTable: a camera model's ray direction through every pixel centre
// (CameraModel::pixelRay of (u, v) for u < width, v < height, row-major,
// row 0 at the top), computed once and shared by the many uses of one model:
// the ray casts of a rig camera's firings (rig_camera.h) and the fisheye
// masks of its boxes (boxes.h FrameBoxOptions). The directions are the very
// doubles pixelRay returns, so a user gives the same bytes with or without
// the table. `inside[p]` is 0 for a fisheye pixel outside the image circle
// (its direction is then the zero vector).
// Memory: 25 bytes per pixel (7.7 MB at 640x480). Built in parallel over
// `threads` workers (0 = all); immutable afterwards and safe to share
// between threads.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "runtime/scene/camera_model.h"

namespace vista {

class CameraRayTable {
public:
    CameraRayTable() = default;
    explicit CameraRayTable(const CameraModel& model, int threads = 0);

    // True when the table was built for a model with exactly these intrinsics.
    bool matches(const CameraModel& model) const;
    const CameraModel& model() const { return _model; }
    // Pixel p = v * width + u.
    bool inside(size_t p) const { return _inside[p] != 0; }
    const glm::dvec3& dir(size_t p) const { return _dir[p]; }

private:
    CameraModel _model;
    std::vector<glm::dvec3> _dir;
    std::vector<uint8_t> _inside;
};

}  // namespace vista
