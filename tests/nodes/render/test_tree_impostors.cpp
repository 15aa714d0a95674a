// Tree impostors in osglod (nodes/render/mode_osglod.h): the far levels
// (from kOsgLodTreeImpostorLevel on) draw every tree of their chunk as an
// impostor (8 triangles per instance), fewer triangles than the simplified
// prototypes they replace.
#include <gtest/gtest.h>

#include <osg/Geode>
#include <osg/Geometry>
#include <osg/LOD>
#include <osg/NodeVisitor>

#include "citygen/generate.h"
#include "citygen/tree_impostor.h"
#include "nodes/render/mode_osglod.h"
#include "runtime/scene/scene_graph.h"
#include "runtime/scene/tree_impostor_graph.h"

namespace {

using namespace vista;

struct TreeTriangles {
    size_t prototype[3] = {0, 0, 0}, impostor[3] = {0, 0, 0}, instances[3] = {0, 0, 0};
};

// Triangles of the tree drawables per LOD level of the osglod graph.
struct CountTrees : osg::NodeVisitor {
    CountTrees() : osg::NodeVisitor(TRAVERSE_ALL_CHILDREN) {}
    TreeTriangles n;
    int levels = 0;
    void apply(osg::LOD& lod) override {
        ASSERT_EQ(lod.getNumChildren(), 3u);
        ++levels;
        for (unsigned l = 0; l < 3; ++l) {
            osg::Geode* g = lod.getChild(l)->asGeode();
            if (!g) continue;
            for (unsigned i = 0; i < g->getNumDrawables(); ++i) {
                const osg::Geometry* geo = g->getDrawable(i)->asGeometry();
                if (!geo || geo->getNumPrimitiveSets() == 0) continue;
                const osg::PrimitiveSet* ps = geo->getPrimitiveSet(0);
                const size_t tris = ps->getNumIndices() / 3 * size_t(std::max(1, ps->getNumInstances()));
                if (geo->getName().rfind(kTreeGeometryPrefix, 0) == 0) {
                    n.prototype[l] += tris;
                    n.instances[l] += size_t(ps->getNumInstances());
                } else if (isTreeImpostorName(geo->getName())) {
                    n.impostor[l] += tris;
                    n.instances[l] += size_t(ps->getNumInstances());
                    EXPECT_EQ(ps->getNumIndices(), unsigned(6 * kImpostorCells));
                    ASSERT_NE(geo->getStateSet(), nullptr);
                    EXPECT_NE(geo->getStateSet()->getTextureAttribute(0, osg::StateAttribute::TEXTURE), nullptr);
                }
            }
        }
    }
};

TEST(OsgLodTreeImpostors, FarLevelDrawsTreesAsImpostors) {
    CityParams p;
    p.size_m = 600;
    p.seed = 3;
    p.detail = 1;
    p.threads = 1;
    auto city = generateCity(p);
    ASSERT_TRUE(city.isOk()) << city.status().message();
    ASSERT_FALSE(city->trees.empty());
    auto model = decodeCityScene(buildCityScene(*city).get(), "test city");
    ASSERT_TRUE(model.isOk()) << model.status().message();
    ModeContext ctx;
    ctx.city = &*model;
    ctx.scene = sceneRoot(*model);
    auto mode = createRenderMode("osglod", ctx);
    ASSERT_TRUE(mode.isOk()) << mode.status().message();
    CountTrees count;
    (*mode)->viewerScene()->accept(count);
    ASSERT_GT(count.levels, 0);
    const TreeTriangles& n = count.n;
    const size_t trees = city->trees.size();
    for (int l = 0; l < 3; ++l) EXPECT_EQ(n.instances[l], trees) << "level " << l << " draws every tree";
    EXPECT_EQ(n.impostor[0], 0u);
    ASSERT_GT(n.prototype[0], 0u);
    for (int l = kOsgLodTreeImpostorLevel; l < 3; ++l) {
        EXPECT_EQ(n.prototype[l], 0u) << "level " << l << " draws no prototype mesh";
        EXPECT_EQ(n.impostor[l], trees * 2 * kImpostorCells) << "level " << l;
    }
    // Before impostors, levels 1 and 2 drew the prototypes simplified by
    // osgUtil::Simplifier at sample ratios 0.25 and 0.0625, which keeps at
    // least that fraction of the triangles (it stops there or earlier).
    EXPECT_LT(double(n.impostor[2]), kOsgLodRatio2 * double(n.prototype[0]))
        << "impostors: " << n.impostor[2] << ", level 0 trees: " << n.prototype[0];
    if (kOsgLodTreeImpostorLevel == 1) { EXPECT_LT(double(n.impostor[1]), kOsgLodRatio1 * double(n.prototype[0])); }
}

}  // namespace
