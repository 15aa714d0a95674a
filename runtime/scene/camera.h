// Camera: one viewpoint of a walkthrough, shared by every renderer so that
// rasterised, ray-cast and composited images line up pixel for pixel.
//
// Conventions: world frame x east, y north, z up (metres, double).
// heading = radians clockwise from north (+y) towards east (+x); pitch =
// radians above the horizontal; roll = radians, positive tilts the image
// clockwise. fovY = vertical field of view (radians, 0 < fovY < pi).
// Images are row-major, row 0 at the TOP; pixel (x, y) has its centre at
// (x + 0.5, y + 0.5). Pure functions; thread-safe.
#pragma once
#include <glm/glm.hpp>

namespace vista {

struct Camera {
    glm::dvec3 eye{0.0};               // world position
    double heading = 0;                // radians
    double pitch = 0;                  // radians
    double roll = 0;                   // radians
    double fovY = 0.7853981633974483;  // 45 degrees
    int width = 640, height = 480;
    double zNear = 0.3;  // metres
    double time = 0.0;   // seconds on the walkthrough's clock (path sample time): what moving agents show

    // Unit vectors of the view frame in world coordinates.
    glm::dvec3 forward() const;
    glm::dvec3 right() const;
    glm::dvec3 up() const;
    // World direction (unit) of the ray through the centre of pixel (px, py)
    // (fractional coordinates allowed: (0,0) is the top-left image corner).
    glm::dvec3 rayDirection(double px, double py) const;
    // Column-major OpenGL-style matrices. view() maps world -> eye space
    // relative to `frameOrigin` (pass the same origin to the model matrices,
    // so float precision holds far from the world origin).
    glm::dmat4 view(const glm::dvec3& frameOrigin = glm::dvec3(0.0)) const;
    glm::dmat4 projection(double zFar) const;  // zFar <= 0 means infinity
    bool upright(double tolerance = 1e-6) const { return roll < tolerance && roll > -tolerance; }
};

}  // namespace vista
