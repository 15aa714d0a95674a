// Pinhole and equidistant fisheye camera models (camera_model.h).
#include "runtime/scene/camera_model.h"

#include <cmath>

#include "foundation/units.h"

namespace vista {

bool CameraModel::pixelRay(double u, double v, glm::dvec3& dir) const {
    const double x = (u - cx) / fx, y = (v - cy) / fy;
    if (!fisheye()) {
        dir = glm::normalize(glm::dvec3(x, y, 1.0));
        return true;
    }
    const double theta = std::sqrt(x * x + y * y);
    if (theta > 0.5 * maxFovDeg * kPi / 180.0) return false;
    if (theta == 0.0) {
        dir = {0.0, 0.0, 1.0};
        return true;
    }
    const double s = std::sin(theta) / theta;
    dir = {x * s, y * s, std::cos(theta)};
    return true;
}

bool CameraModel::project(const glm::dvec3& p, glm::dvec2& uv) const {
    if (!fisheye()) {
        if (!(p.z > 0.0)) return false;
        uv = {cx + fx * p.x / p.z, cy + fy * p.y / p.z};
        return true;
    }
    const double rho = std::hypot(p.x, p.y);
    if (rho == 0.0) {
        if (!(p.z > 0.0)) return false;
        uv = {cx, cy};
        return true;
    }
    const double theta = std::atan2(rho, p.z);
    uv = {cx + fx * theta * p.x / rho, cy + fy * theta * p.y / rho};
    return true;
}

}  // namespace vista
