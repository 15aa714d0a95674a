// Helpers shared by the far-field frame tests: a test city and its ray scene, cameras,
// a fake near field, a per-pixel reference frame.
#pragma once

#include <gtest/gtest.h>
#include <algorithm>
#include <iterator>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include "citygen/lighting.h"
#include "runtime/engine/far_field.h"
#include "runtime/engine/far_field_rays.h"
#include "runtime/engine/frame_raycast.h"
#include "runtime/engine/horizon.h"
#include "runtime/engine/metrics.h"
#include "runtime/engine/ray_scene.h"
#include "tests/runtime/engine/fixtures.h"

using namespace vista;
using namespace vista::test;

// True when one of the frame's notes contains `what`.
inline bool has(const FrameStats& s, const std::string& what) {
    for (const auto& n : s.notes)
        if (n.find(what) != std::string::npos) return true;
    return false;
}

// A random city (world origin (ox, 0)) with its ray scene and a 64-cell height grid.
struct TestCity {
    SceneModel model;
    std::unique_ptr<RayScene> rays;
    HeightGrid grid;
};
inline TestCity testCity(uint32_t seed, int boxes, double ox = 0.0) {
    TestCity t;
    t.model = randomCity(seed, boxes, 400.0, ox, 0.0);
    auto r = RayScene::build(t.model);
    EXPECT_TRUE(r.isOk()) << r.status().message();
    if (!r.isOk()) return t;
    t.rays = std::move(r.value());
    t.grid = HeightGrid::build(t.model, t.rays->frameOrigin(), 64);
    return t;
}

inline Camera cam(const glm::dvec3& eye, double heading, double pitch = 0.0, int w = 120, int h = 80,
                  double roll = 0.0) {
    return testCamera(eye, heading, pitch, w, h, 0.8, roll);
}

inline glm::u8vec4 skyOf(const glm::dvec3& d) { return skyColor(std::asin(std::clamp(d.z, -1.0, 1.0))); }
inline glm::u8vec4 opaque(const RayHit& h) { return glm::u8vec4(h.color.x, h.color.y, h.color.z, 255); }

inline int channelDiff(const Image& a, const Image& b, size_t i) {
    int m = 0;
    for (int k = 0; k < 4; ++k) m = std::max(m, std::abs(int(a.rgba[i * 4 + k]) - int(b.rgba[i * 4 + k])));
    return m;
}
