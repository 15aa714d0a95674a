// Bake: the node types of a baked file, their serializers and quantization.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include <sys/stat.h>
#include <unistd.h>

#include <osg/UserDataContainer>
#include <osgDB/ReaderWriter>
#include <osgDB/Registry>
#include <tbb/global_control.h>

#include "citygen/generate.h"
#include "citygen/polygon.h"
#include "bake/appearance.h"
#include "bake/assembly.h"
#include "bake/bake_cell.h"
#include "bake/cell_result.h"
#include "bake/depth_mesh.h"
#include "bake/far_set.h"
#include "bake/impostor_frame.h"
#include "bake/driver.h"
#include "bake/ldi_sampling.h"
#include "bake/placement.h"
#include "bake/point_removal.h"
#include "bake/sampling_plane.h"
#include "bake/view_cells.h"
#include "foundation/hash.h"
#include "foundation/units.h"
#include "nodes/baked_file.h"
#include "foundation/rng.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_file.h"
#include "nodes/render/mode_impostor.h"
#include "nodes/render/mode_full.h"
#include "nodes/render/mode_lodmesh.h"
#include "runtime/engine/image.h"
#include "runtime/engine/metrics.h"
#include "nodes/render/offscreen.h"

#include "tests/common/temp_dir.h"
#include "tests/bake/bake_fixtures.h"

namespace vista {
namespace {
using test::readBytes;

// --------------------------------------------------------- nodes, serializers
std::string toOsgb(const osg::Node& n) {
    osgDB::ReaderWriter* rw = osgDB::Registry::instance()->getReaderWriterForExtension("osgb");
    EXPECT_NE(rw, nullptr);
    std::ostringstream o;
    rw->writeNode(n, o);
    return o.str();
}
osg::ref_ptr<osg::Node> fromOsgb(const std::string& s) {
    osgDB::ReaderWriter* rw = osgDB::Registry::instance()->getReaderWriterForExtension("osgb");
    std::istringstream i(s);
    return rw->readNode(i).getNode();
}

TEST(Nodes, SerializersRoundTrip) {
    ImpostorResult r = bakeTestImpostor(2, smallParams());
    osg::ref_ptr<ViewCellSwitch> sw = new ViewCellSwitch;
    sw->addChild(new osg::Group);  // a "tile"
    sw->setTileCount(1);
    osg::ref_ptr<PointImpostor> pi = new PointImpostor;
    pi->setData(r.data);
    osg::ref_ptr<osg::Geode> g = new osg::Geode;
    g->addDrawable(pi.get());
    sw->addChild(g.get());
    ViewCellBox b;
    b.center = {1, 2, 1.6};
    b.halfLength = 10;
    b.halfWidth = 4;
    b.halfHeight = 0.4;
    sw->setCells({b, ViewCellBox{}});
    sw->setCellChildren(0, {0}, {1});
    ASSERT_EQ(sw->validate(), "");
    const std::string bytes = toOsgb(*sw);
    osg::ref_ptr<osg::Node> back = fromOsgb(bytes);
    auto* sw2 = dynamic_cast<ViewCellSwitch*>(back.get());
    ASSERT_NE(sw2, nullptr);
    EXPECT_EQ(sw2->validate(), "");
    EXPECT_EQ(sw2->getTileCount(), 1u);
    EXPECT_EQ(sw2->hiddenOf(0), std::vector<uint32_t>{0});
    EXPECT_EQ(sw2->impostorsOf(0), std::vector<uint32_t>{1});
    EXPECT_EQ(sw2->cellAt({1, 2, 1.6}), 0);
    EXPECT_EQ(sw2->cellAt({1, 20, 1.6}), -1);
    auto* g2 = sw2->getChild(1)->asGeode();
    ASSERT_NE(g2, nullptr);
    auto* pi2 = dynamic_cast<PointImpostor*>(g2->getDrawable(0));
    ASSERT_NE(pi2, nullptr);
    EXPECT_EQ(pi2->pointCount(), r.data.positions.size());
    EXPECT_EQ(pi2->getTexelsX(), 8);
    EXPECT_EQ(pi2->getTexturedCount(), pi->getTexturedCount());
    EXPECT_EQ(pi2->getPlaneU(), pi->getPlaneU());
    EXPECT_EQ(toOsgb(*back), bytes);  // write -> read -> write is stable
    // Bad per-cell indices are reported, not followed.
    sw2->setCellChildren(0, {5}, {1});
    EXPECT_NE(sw2->validate(), "");
}

TEST(Nodes, PointImpostorQuantizesWithinHalfAStepAndValidates) {
    PointImpostorData d;
    Rng rng(5, 0, Stream::Bake);
    for (int k = 0; k < 2000; ++k)
        d.positions.emplace_back(float(rng.uniform(100, 700)), float(rng.uniform(-300, 300)),
                                 float(rng.uniform(0, 80)));
    d.positions.emplace_back(100.0f, -300.0f, 0.0f);  // the extremes are representable exactly up to rounding
    d.positions.emplace_back(700.0f, 300.0f, 80.0f);
    d.colors.assign(d.positions.size(), glm::u8vec4(10, 20, 30, 255));
    d.block.assign(d.positions.size(), -1);
    d.block[7] = 0;
    d.texels.assign(16, glm::u8vec4(200, 0, 0, 255));
    osg::ref_ptr<PointImpostor> pi = new PointImpostor;
    pi->setData(d);
    ASSERT_EQ(pi->validate(), "");
    const float step = pi->getDequant().w();
    EXPECT_LE(step, 300.0f / 32767.0f * 1.0001f);  // largest half-extent / 32767
    const osg::BoundingBox bb = pi->getBoundingBox();
    double worst = 0;
    for (size_t k = 0; k < d.positions.size(); ++k) {
        const osg::Vec3f q = pi->position(k);
        const glm::vec3& p = d.positions[k];
        worst = std::max(
            {worst, std::abs(double(q.x()) - p.x), std::abs(double(q.y()) - p.y), std::abs(double(q.z()) - p.z)});
        EXPECT_TRUE(bb.contains(q)) << k;
    }
    EXPECT_LE(worst, 0.5 * step * 1.001 + 1e-4);  // float rounding of the dequantized value
    EXPECT_EQ(pi->getTexturedCount(), 1u);
    // Corruptions are reported.
    auto broken = [&](const std::function<void(PointImpostor&)>& f) {
        osg::ref_ptr<PointImpostor> b = new PointImpostor;
        b->setData(d);
        f(*b);
        return b->validate();
    };
    EXPECT_NE(broken([](PointImpostor& b) { b.setColorArray(new osg::Vec4ubArray(3), osg::Array::BIND_PER_VERTEX); }),
              "");
    EXPECT_NE(
        broken([](PointImpostor& b) { (*static_cast<osg::Vec2sArray*>(b.getTexCoordArray(0)))[0].set(30000, 0); }), "");
    EXPECT_NE(broken([](PointImpostor& b) { b.setDequant(osg::Vec4f(0, 0, 0, 0)); }), "");
    EXPECT_NE(broken([](PointImpostor& b) { b.setTexturedCount(5); }), "");
    EXPECT_NE(broken([&](PointImpostor& b) { b.setVertexArray(new osg::Vec3Array(unsigned(d.positions.size()))); }),
              "");
    EXPECT_NE(broken([](PointImpostor& b) { static_cast<osg::DrawArrays*>(b.getPrimitiveSet(0))->setCount(5000); }),
              "");
}

}  // namespace
}  // namespace vista
