// Helpers shared by the render-mode and bench tests: tiny scenes and cities, a test camera,
// the display check.
#pragma once

#include <gtest/gtest.h>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unistd.h>
#include <osg/Geode>
#include <osg/Geometry>
#include <osg/MatrixTransform>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>
#include "citygen/lighting.h"
#include "foundation/units.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"
#include "runtime/engine/metrics.h"
#include "nodes/far_field_node.h"
#include "nodes/render/offscreen.h"
#include "nodes/render/render_mode.h"
#include "runtime/scene/paths.h"
#include "runtime/engine/ray_scene.h"

using namespace vista;
namespace fs = std::filesystem;

#define REQUIRE_DISPLAY()                                                                         \
    do {                                                                                          \
        const char* d = std::getenv("DISPLAY");                                                   \
        if (!d || !*d) GTEST_SKIP() << "no X display: run the rendering tests under xvfb-run -a"; \
    } while (0)

// Axis-aligned box (5 faces, no bottom) as a SceneMesh in a local frame.
inline void addBox(SceneMesh& m, glm::vec3 lo, glm::vec3 hi, glm::u8vec4 c) {
    glm::vec3 p[8];
    for (int i = 0; i < 8; ++i) p[i] = {i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z};
    const int faces[5][4] = {{0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}, {4, 5, 7, 6}};
    for (const auto& f : faces) {
        uint32_t base = uint32_t(m.positions.size());
        for (int k = 0; k < 4; ++k) {
            m.positions.push_back(p[f[k]]);
            m.colors.push_back(c);
        }
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
    }
}
inline void addQuad(SceneMesh& m, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::u8vec4 col) {
    uint32_t base = uint32_t(m.positions.size());
    for (auto v : {a, b, c, d}) {
        m.positions.push_back(v);
        m.colors.push_back(col);
    }
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
}

// The OSG scene of a set of meshes, structured like a city file (tiles as
// double MatrixTransforms, prelit colours, lighting off).
inline osg::ref_ptr<osg::Group> sceneOf(const std::vector<SceneMesh>& meshes) {
    osg::ref_ptr<osg::Group> root = new osg::Group;
    root->getOrCreateStateSet()->setMode(GL_LIGHTING, osg::StateAttribute::OFF);
    for (const auto& m : meshes) {
        osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
        osg::ref_ptr<osg::Vec3Array> v = new osg::Vec3Array;
        osg::ref_ptr<osg::Vec4ubArray> c = new osg::Vec4ubArray;
        for (size_t i = 0; i < m.positions.size(); ++i) {
            v->push_back({m.positions[i].x, m.positions[i].y, m.positions[i].z});
            c->push_back({m.colors[i].x, m.colors[i].y, m.colors[i].z, m.colors[i].w});
        }
        c->setNormalize(true);
        g->setVertexArray(v.get());
        g->setColorArray(c.get(), osg::Array::BIND_PER_VERTEX);
        osg::ref_ptr<osg::DrawElementsUInt> de = new osg::DrawElementsUInt(GL_TRIANGLES);
        for (uint32_t i : m.indices) de->push_back(i);
        g->addPrimitiveSet(de.get());
        g->setUseDisplayList(false);
        g->setUseVertexBufferObjects(true);
        osg::ref_ptr<osg::Geode> geode = new osg::Geode;
        geode->addDrawable(g.get());
        osg::ref_ptr<osg::MatrixTransform> mt =
            new osg::MatrixTransform(osg::Matrixd::translate(m.origin.x, m.origin.y, m.origin.z));
        mt->addChild(geode.get());
        root->addChild(mt.get());
    }
    return root;
}

// A little "city": ground and a few coloured blocks, far from the world origin.
const glm::dvec3 kWorld(1.0e6, 2.0e6, 0.0);
inline SceneModel tinyCity() {
    SceneModel c;
    SceneMesh ground;
    ground.origin = kWorld;
    addQuad(ground, {-400, -400, 0}, {400, -400, 0}, {400, 400, 0}, {-400, 400, 0}, {90, 110, 80, 255});
    c.meshes.push_back(ground);
    SceneMesh blocks;
    blocks.origin = kWorld + glm::dvec3(0, 100, 0);
    addBox(blocks, {-60, -20, 0}, {-20, 20, 30}, {200, 80, 60, 255});
    addBox(blocks, {10, -10, 0}, {40, 30, 55}, {60, 90, 200, 255});
    addBox(blocks, {-15, 80, 0}, {25, 120, 90}, {220, 210, 170, 255});
    c.meshes.push_back(blocks);
    for (const auto& m : c.meshes) c.triangles += m.indices.size() / 3;
    setSceneRoot(c, sceneOf(c.meshes));
    return c;
}
