// Box3: an axis-aligned box in double precision (metres), the shape of a view
// cell and of a far field in an impostor frame (bake/impostor_frame.h).
//
// Contract: valid() = finite and lo <= hi on every axis; the other members
// assume a valid box. Plain value type; pure.
#pragma once
#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

namespace vista {

struct Box3 {
    glm::dvec3 lo{0.0}, hi{0.0};

    bool valid() const {
        for (int a = 0; a < 3; ++a)
            if (!std::isfinite(lo[a]) || !std::isfinite(hi[a]) || !(hi[a] >= lo[a])) return false;
        return true;
    }
    glm::dvec3 center() const { return 0.5 * (lo + hi); }
    glm::dvec3 corner(int i) const { return {(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z}; }
    // Euclidean distance from p to the box; 0 inside.
    double distance(const glm::dvec3& p) const {
        return glm::length(glm::max(glm::max(lo - p, p - hi), glm::dvec3(0.0)));
    }
    bool contains(const glm::dvec3& p, double eps = 0) const {
        for (int a = 0; a < 3; ++a)
            if (p[a] < lo[a] - eps || p[a] > hi[a] + eps) return false;
        return true;
    }
};

}  // namespace vista
