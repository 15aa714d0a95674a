// Camera models of a sensor rig: a pinhole camera with general intrinsics
// and an equidistant fisheye, as maps between pixels and ray directions.
//
// Conventions: the camera frame is OpenCV's (x right, y down, z forward
// along the optical axis), metres. Pixel coordinates (u, v): u = column,
// v = row from the top, pixel centres at integer coordinates (pixel (0, 0)
// covers [-0.5, 0.5]^2), so a centred principal point is cx = (width - 1) / 2.
// Pinhole: u = cx + fx x / z, v = cy + fy y / z (z > 0).
// Equidistant fisheye (r = f theta): theta = the angle between the ray and
// the optical axis, phi its azimuth around it; u = cx + fx theta cos(phi),
// v = cy + fy theta sin(phi). Pixels whose theta exceeds maxFovDeg / 2 lie
// outside the image circle: they see nothing.
// pixelRay(): the unit direction (camera frame) through (u, v); false for a
// fisheye pixel outside the image circle. project(): the pixel of a point
// or direction in the camera frame (only its direction matters); false when
// it has none (pinhole: z <= 0; fisheye: exactly behind, theta = pi, or the
// zero vector). project() does not clip to the image or the image circle.
// The two are inverse to each other within floating-point rounding.
// Pure functions; thread-safe. Ranges are checked where a rig is read
// (runtime/engine/rig.h), not here.
#pragma once
#include <glm/glm.hpp>

namespace vista {

struct CameraModel {
    enum class Kind { Pinhole, Fisheye };
    Kind kind = Kind::Pinhole;
    int width = 640, height = 480;
    double fx = 554.2562584220407, fy = 554.2562584220407;  // pixels (pinhole: 60 degrees vertical at 640x480)
    double cx = 319.5, cy = 239.5;                          // pixels
    double maxFovDeg = 180.0;                               // fisheye: full field of view of the image circle

    bool fisheye() const { return kind == Kind::Fisheye; }
    bool pixelRay(double u, double v, glm::dvec3& dir) const;
    bool project(const glm::dvec3& p, glm::dvec2& uv) const;
};

}  // namespace vista
