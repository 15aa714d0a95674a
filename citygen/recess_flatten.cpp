// Window recesses flattened (recess_flatten.h).
#include "citygen/recess_flatten.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <unordered_map>

#include "foundation/status.h"

namespace vista {

namespace {

// The exact bits of a position: glass corners and the jambs' inner corners
// are the same floats (one double corner converted once per mesh).
struct PosKey {
    uint32_t x, y, z;
    bool operator==(const PosKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct PosHash {
    size_t operator()(const PosKey& k) const {
        uint64_t h = k.x * 0x9E3779B97F4A7C15ull;
        h ^= (h >> 29) + k.y * 0xBF58476D1CE4E5B9ull;
        h ^= (h >> 31) + k.z * 0x94D049BB133111EBull;
        return size_t(h ^ (h >> 32));
    }
};
PosKey keyOf(const glm::vec3& p) {
    PosKey k;
    std::memcpy(&k.x, &p.x, 4);
    std::memcpy(&k.y, &p.y, 4);
    std::memcpy(&k.z, &p.z, 4);
    return k;
}

uint32_t findRoot(std::vector<uint32_t>& parent, uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
}

struct Window {
    glm::dvec3 normal{0.0}, origin{0.0};
    std::vector<glm::dvec3> corners;  // unique glass positions
    std::vector<uint32_t> triangles;  // glass triangles
    double depth = 0;
};

}  // namespace

RecessFlattening flattenRecesses(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                                 const std::vector<Material>& triangleMaterial, double maxDepth) {
    VISTA_CHECK(indices.size() % 3 == 0 && triangleMaterial.size() == indices.size() / 3);
    for (uint32_t i : indices) VISTA_CHECK(i < positions.size());
    RecessFlattening out;
    const size_t nt = indices.size() / 3;
    out.jamb.assign(nt, 0);
    out.moved = positions;
    // Positional tolerance: the jambs' outer corners are computed apart from the
    // glass (facade point vs glass point + depth), so they agree to float rounding.
    const double eps = 2e-3;
    auto P = [&](size_t t, int k) { return glm::dvec3(positions[indices[3 * t + size_t(k)]]); };

    // Glass triangles and their front-face normals.
    std::vector<uint32_t> glass;
    std::vector<glm::dvec3> normal(nt, glm::dvec3(0.0));
    for (size_t t = 0; t < nt; ++t) {
        if (triangleMaterial[t] != Material::Window) continue;
        const glm::dvec3 c = glm::cross(P(t, 1) - P(t, 0), P(t, 2) - P(t, 0));
        const double len = glm::length(c);
        if (!(len > 1e-12)) continue;  // degenerate: never part of a window
        normal[t] = c / len;
        glass.push_back(uint32_t(t));
    }
    if (glass.empty()) return out;
    // Windows: glass triangles that share a position and a plane orientation.
    std::unordered_map<PosKey, std::vector<uint32_t>, PosHash> glassAt;  // position -> glass slots
    for (uint32_t s = 0; s < glass.size(); ++s)
        for (int k = 0; k < 3; ++k) glassAt[keyOf(positions[indices[3 * size_t(glass[s]) + size_t(k)]])].push_back(s);
    std::vector<uint32_t> parent(glass.size());
    std::iota(parent.begin(), parent.end(), 0u);
    for (const auto& [key, slots] : glassAt)
        for (size_t a = 1; a < slots.size(); ++a)
            if (glm::dot(normal[glass[slots[0]]], normal[glass[slots[a]]]) > 0.999)
                parent[findRoot(parent, slots[a])] = findRoot(parent, slots[0]);
    std::vector<Window> windows;
    std::vector<int64_t> windowOfRoot(glass.size(), -1);
    std::vector<uint32_t> windowOfSlot(glass.size());
    for (uint32_t s = 0; s < glass.size(); ++s) {
        const uint32_t r = findRoot(parent, s);
        if (windowOfRoot[r] < 0) {
            windowOfRoot[r] = int64_t(windows.size());
            Window w;
            w.normal = normal[glass[r]];
            w.origin = P(glass[r], 0);
            windows.push_back(w);
        }
        Window& w = windows[size_t(windowOfRoot[r])];
        windowOfSlot[s] = uint32_t(windowOfRoot[r]);
        w.triangles.push_back(glass[s]);
        for (int k = 0; k < 3; ++k) {
            const glm::dvec3 p = P(glass[s], k);
            if (std::none_of(w.corners.begin(), w.corners.end(), [&](const glm::dvec3& c) { return c == p; }))
                w.corners.push_back(p);
        }
    }
    // Jambs: wall triangles spanning a window's corners and the same corners moved out by one depth.
    auto jambDepth = [&](size_t t, const Window& w) -> double {
        double d = -1.0;
        for (int k = 0; k < 3; ++k) {
            const glm::dvec3 v = P(t, k);
            const double delta = glm::dot(v - w.origin, w.normal);
            if (delta < -eps || delta > maxDepth + eps) return -1.0;
            const glm::dvec3 q = v - w.normal * delta;
            if (std::none_of(w.corners.begin(), w.corners.end(),
                             [&](const glm::dvec3& c) { return glm::length(c - q) <= eps; }))
                return -1.0;
            if (delta > eps) {
                if (d < 0) d = delta;
                else if (std::abs(delta - d) > eps) return -1.0;
            }
        }
        return d;
    };
    for (size_t t = 0; t < nt; ++t) {
        if (triangleMaterial[t] != Material::Wall) continue;
        for (int k = 0; k < 3 && !out.jamb[t]; ++k) {
            auto it = glassAt.find(keyOf(positions[indices[3 * t + size_t(k)]]));
            if (it == glassAt.end()) continue;
            for (uint32_t s : it->second) {
                Window& w = windows[windowOfSlot[s]];
                const double d = jambDepth(t, w);
                if (d > 0) {
                    out.jamb[t] = 1;
                    ++out.jambTriangles;
                    w.depth = std::max(w.depth, d);
                    break;
                }
            }
        }
    }
    // Glass of windows with jambs: out onto the facade plane.
    std::vector<uint8_t> done(positions.size(), 0);
    for (const Window& w : windows) {
        if (!(w.depth > 0)) continue;
        ++out.windows;
        out.maxRecessDepth = std::max(out.maxRecessDepth, w.depth);
        const glm::vec3 shift(w.normal * w.depth);
        for (uint32_t t : w.triangles)
            for (int k = 0; k < 3; ++k) {
                const uint32_t vi = indices[3 * size_t(t) + size_t(k)];
                if (done[vi]) continue;
                done[vi] = 1;
                out.moved[vi] = positions[vi] + shift;
            }
    }
    return out;
}

}  // namespace vista
