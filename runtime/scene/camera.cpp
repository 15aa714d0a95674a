#include "runtime/scene/camera.h"

#include <cmath>

namespace vista {

glm::dvec3 Camera::forward() const {
    return {std::sin(heading) * std::cos(pitch), std::cos(heading) * std::cos(pitch), std::sin(pitch)};
}

glm::dvec3 Camera::right() const {
    glm::dvec3 r0(std::cos(heading), -std::sin(heading), 0.0);  // horizontal right
    glm::dvec3 u0 = glm::cross(r0, forward());
    return std::cos(roll) * r0 - std::sin(roll) * u0;
}

glm::dvec3 Camera::up() const { return glm::cross(right(), forward()); }

glm::dvec3 Camera::rayDirection(double px, double py) const {
    double t = std::tan(0.5 * fovY);
    double aspect = double(width) / double(height);
    double sx = (2.0 * px / width - 1.0) * t * aspect;
    double sy = (1.0 - 2.0 * py / height) * t;
    return glm::normalize(forward() + sx * right() + sy * up());
}

glm::dmat4 Camera::view(const glm::dvec3& o) const {
    glm::dvec3 f = forward(), r = right(), u = up(), e = eye - o;
    glm::dmat4 m(1.0);
    m[0][0] = r.x;
    m[1][0] = r.y;
    m[2][0] = r.z;
    m[0][1] = u.x;
    m[1][1] = u.y;
    m[2][1] = u.z;
    m[0][2] = -f.x;
    m[1][2] = -f.y;
    m[2][2] = -f.z;
    m[3][0] = -glm::dot(r, e);
    m[3][1] = -glm::dot(u, e);
    m[3][2] = glm::dot(f, e);
    return m;
}

glm::dmat4 Camera::projection(double zFar) const {
    double t = 1.0 / std::tan(0.5 * fovY), aspect = double(width) / double(height);
    glm::dmat4 p(0.0);
    p[0][0] = t / aspect;
    p[1][1] = t;
    p[2][3] = -1.0;
    if (zFar <= 0) {  // infinite far plane
        p[2][2] = -1.0;
        p[3][2] = -2.0 * zNear;
    } else {
        p[2][2] = -(zFar + zNear) / (zFar - zNear);
        p[3][2] = -2.0 * zFar * zNear / (zFar - zNear);
    }
    return p;
}

}  // namespace vista
