// CameraRayTable: a camera model's ray direction through every pixel centre
// (CameraModel::pixelRay of (u, v) for u < width, v < height, row-major,
// row 0 at the top), computed once and shared by the many uses of one model:
// the ray casts of a rig camera's firings (rig_camera.h) and the fisheye
// masks of its boxes (boxes.h FrameBoxOptions). The directions are the very
// doubles pixelRay returns, so a user gives the same bytes with or without
// the table. `inside[p]` is 0 for a fisheye pixel outside the image circle
// (its direction is then the zero vector).
// Tiles: the image in kTile x kTile pixel squares (row-major, the last row
// and column of tiles cut at the image's edge), each with a cap (a cone of
// directions around a unit axis) that holds the directions of every pixel of
// the tile inside the image circle, its half angle padded by 1e-7 rad so
// that rounding never makes it too narrow. A user tests a whole tile
// against a plane through the eye (boxes.h: the fisheye masks skip the tiles
// a triangle cannot cover and fill the tiles it covers whole). A tile
// without a pixel inside the circle, or whose cap is not narrower than a
// hemisphere, has no cap (`hasCap` false).
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

    static constexpr int kTile = 8;
    struct TileCap {
        glm::dvec3 axis{0.0};  // unit
        double cosR = 1, sinR = 0;
        bool hasCap = false;  // false: no pixel inside the circle, or a cap too wide
        bool anyInside = false;
    };
    int tilesX() const { return _tilesX; }
    int tilesY() const { return _tilesY; }
    const TileCap& tile(int tx, int ty) const { return _tiles[size_t(ty) * size_t(_tilesX) + size_t(tx)]; }

private:
    CameraModel _model;
    std::vector<glm::dvec3> _dir;
    std::vector<uint8_t> _inside;
    int _tilesX = 0, _tilesY = 0;
    std::vector<TileCap> _tiles;
};

}  // namespace vista
