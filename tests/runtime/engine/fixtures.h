// Hand-built SceneModel fixtures for the far-field tests (no generator, no GL).
#pragma once
#include <cstdint>
#include <random>
#include <vector>

#include <glm/glm.hpp>

#include "runtime/engine/adaptive_split.h"
#include "runtime/scene/camera.h"
#include "runtime/scene/city_file.h"

namespace vista::test {

// A camera at `eye` (world) looking along heading/pitch/roll (radians).
inline Camera testCamera(const glm::dvec3& eye, double heading, double pitch, int w, int h, double fovY,
                         double roll = 0.0) {
    Camera c;
    c.eye = eye;
    c.heading = heading;
    c.pitch = pitch;
    c.roll = roll;
    c.width = w;
    c.height = h;
    c.fovY = fovY;
    return c;
}

// Appends an axis-aligned box [lo, hi] (relative to mesh.origin) with one colour per face.
inline void addBox(SceneMesh& m, const glm::vec3& lo, const glm::vec3& hi, glm::u8vec4 color) {
    const glm::vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                            {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
    for (const auto& f : faces) {
        uint32_t base = uint32_t(m.positions.size());
        for (int k = 0; k < 4; ++k) {
            m.positions.push_back(c[f[k]]);
            m.colors.push_back(color);
        }
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
    }
}

// Appends a horizontal quad at height z covering [lo, hi] in x/y.
inline void addGround(SceneMesh& m, const glm::vec2& lo, const glm::vec2& hi, float z, glm::u8vec4 color) {
    uint32_t base = uint32_t(m.positions.size());
    m.positions.push_back({lo.x, lo.y, z});
    m.positions.push_back({hi.x, lo.y, z});
    m.positions.push_back({hi.x, hi.y, z});
    m.positions.push_back({lo.x, hi.y, z});
    for (int k = 0; k < 4; ++k) m.colors.push_back(color);
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
}

// A random "city": ground plane plus `boxes` boxes of random size and height in
// [-extent/2, extent/2]^2, world origin (ox, oy).
inline SceneModel randomCity(uint32_t seed, int boxes, double extent = 400.0, double ox = 0.0, double oy = 0.0) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(float(-extent / 2), float(extent / 2)), size(3.0f, 25.0f),
        height(3.0f, 60.0f);
    std::uniform_int_distribution<int> col(30, 220);
    SceneModel city;
    city.params.origin_x = ox;
    city.params.origin_y = oy;
    city.params.size_m = extent;
    SceneMesh ground;
    ground.origin = glm::dvec3(ox, oy, 0.0);
    addGround(ground, glm::vec2(float(-extent / 2)), glm::vec2(float(extent / 2)), 0.0f, {90, 90, 90, 255});
    city.meshes.push_back(ground);
    SceneMesh b;
    b.origin = glm::dvec3(ox, oy, 0.0);
    for (int i = 0; i < boxes; ++i) {
        glm::vec3 lo(pos(rng), pos(rng), 0.0f);
        glm::vec3 hi = lo + glm::vec3(size(rng), size(rng), height(rng));
        addBox(b, lo, hi, glm::u8vec4(uint8_t(col(rng)), uint8_t(col(rng)), uint8_t(col(rng)), 255));
    }
    city.meshes.push_back(b);
    city.triangles = (ground.indices.size() + b.indices.size()) / 3;
    return city;
}

// A split object (adaptive_split.h): the box lo .. hi holding `tris` triangles.
inline SplitObject splitBox(glm::dvec3 lo, glm::dvec3 hi, uint64_t tris) {
    SplitObject o;
    o.lo = lo;
    o.hi = hi;
    o.triangles = tris;
    return o;
}

}  // namespace vista::test
