// The offscreen renderer leaves its caller's thread on every core it had:
// osgViewer pins a single-threaded viewer's main thread to core 0 unless told
// not to, and every thread started afterwards (TBB's ray casting, the far
// field's overlap thread) then shares that one core (render/offscreen.cpp).
#include <sched.h>

#include <chrono>
#include <cstdlib>
#include <thread>

#include <gtest/gtest.h>
#include <osg/Geode>
#include <osg/Geometry>
#include <osg/BufferObject>
#include <osg/ContextData>
#include <osg/Group>
#include <osgUtil/SceneView>
#include <osgViewer/Renderer>
#include <osgViewer/Viewer>
#include <tbb/task_arena.h>

#include "nodes/render/offscreen.h"
#include "runtime/engine/frame_stats.h"
#include "runtime/scene/camera.h"

using namespace vista;

TEST(Offscreen, LeavesTheCallersThreadOnAllItsCores) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no X display (run under xvfb-run -a)";
    cpu_set_t before;
    CPU_ZERO(&before);
    ASSERT_EQ(sched_getaffinity(0, sizeof before, &before), 0);
    if (CPU_COUNT(&before) < 2) GTEST_SKIP() << "this thread may run on one core only: nothing to lose";
    auto renderer = OffscreenRenderer::create(64, 48);
    ASSERT_TRUE(renderer.isOk()) << renderer.status().message();
    Camera cam;
    cam.width = 64;
    cam.height = 48;
    cam.eye = glm::dvec3(0, 0, 2);
    osg::ref_ptr<osg::Group> empty = new osg::Group;
    Image color;
    std::vector<float> depth;
    FrameStats stats;
    for (int i = 0; i < 2; ++i)  // the viewer sets its threading up in the first frame
        ASSERT_TRUE((*renderer)->render(empty.get(), cam, 0.0, &color, &depth, stats).isOk());
    cpu_set_t after;
    CPU_ZERO(&after);
    ASSERT_EQ(sched_getaffinity(0, sizeof after, &after), 0);
    EXPECT_TRUE(CPU_EQUAL(&before, &after)) << "cores before " << CPU_COUNT(&before) << ", after " << CPU_COUNT(&after);
    // A thread started now (as the far field's overlap thread is) inherits the mask.
    int inherited = 0;
    std::thread t([&] {
        cpu_set_t s;
        CPU_ZERO(&s);
        if (sched_getaffinity(0, sizeof s, &s) == 0) inherited = CPU_COUNT(&s);
    });
    t.join();
    EXPECT_EQ(inherited, CPU_COUNT(&before));
    EXPECT_GE(tbb::this_task_arena::max_concurrency(), 2);
}

// The read-back (nodes/gl_readback.h, colour as BGRA swizzled to RGBA): a
// quad of one colour over the upper half of the view comes back in RGBA order,
// row 0 at the top, with depth below 1 there and exactly 1 (nothing drawn) and
// the clear colour below it.
TEST(Offscreen, ReadsColourAndDepthBackTopDownInRgba) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no X display (run under xvfb-run -a)";
    const int W = 64, H = 48;
    auto renderer = OffscreenRenderer::create(W, H);
    ASSERT_TRUE(renderer.isOk()) << renderer.status().message();
    Camera cam;
    cam.width = W;
    cam.height = H;
    cam.eye = glm::dvec3(0, 0, 2);  // heading 0: looking north (+y), level
    osg::ref_ptr<osg::Geometry> quad = new osg::Geometry;
    osg::ref_ptr<osg::Vec3Array> v = new osg::Vec3Array;
    for (const auto& p : {osg::Vec3(-50, 10, 2), osg::Vec3(50, 10, 2), osg::Vec3(50, 10, 60), osg::Vec3(-50, 10, 60)})
        v->push_back(p);
    quad->setVertexArray(v.get());
    osg::ref_ptr<osg::Vec4Array> c = new osg::Vec4Array;
    c->push_back(osg::Vec4(200 / 255.0f, 30 / 255.0f, 10 / 255.0f, 1.0f));
    quad->setColorArray(c.get(), osg::Array::BIND_OVERALL);
    quad->addPrimitiveSet(new osg::DrawArrays(GL_QUADS, 0, 4));
    quad->getOrCreateStateSet()->setMode(GL_LIGHTING, osg::StateAttribute::OFF);
    quad->getOrCreateStateSet()->setMode(GL_CULL_FACE, osg::StateAttribute::OFF);
    osg::ref_ptr<osg::Geode> geode = new osg::Geode;
    geode->addDrawable(quad.get());
    Image color;
    std::vector<float> depth;
    FrameStats stats;
    ASSERT_TRUE((*renderer)->render(geode.get(), cam, 0.0, &color, &depth, stats, /*skyLayer=*/false).isOk());
    ASSERT_EQ(color.width, W);
    ASSERT_EQ(color.height, H);
    ASSERT_EQ(depth.size(), size_t(W) * size_t(H));
    for (int y : {0, H / 2 - 2}) {
        for (int x : {0, W / 2, W - 1}) {
            const glm::u8vec4 p = color.at(x, y);
            EXPECT_NEAR(p[0], 200, 1) << x << "," << y;
            EXPECT_NEAR(p[1], 30, 1) << x << "," << y;
            EXPECT_NEAR(p[2], 10, 1) << x << "," << y;
            EXPECT_LT(depth[size_t(y) * W + size_t(x)], 1.0f);
        }
    }
    for (int y : {H / 2 + 1, H - 1}) {
        for (int x : {0, W / 2, W - 1}) {
            const glm::u8vec4 p = color.at(x, y);
            EXPECT_EQ(int(p[0]) + int(p[1]) + int(p[2]), 0) << x << "," << y;  // the clear colour: black
            EXPECT_EQ(int(p[3]), 255);
            EXPECT_EQ(depth[size_t(y) * W + size_t(x)], 1.0f);
        }
    }
}

// flushDeletedGLObjectsEvery: the GL buffers of a dropped node stay with the
// context until the next flush frame, and are released then; the scene view
// flushes on every `frames`-th frame only (OSG's default is every frame,
// which walks every buffer set: render/offscreen.h).
TEST(Offscreen, ReleasesTheBuffersOfDroppedNodesEveryFlushPeriod) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no X display (run under xvfb-run -a)";
    osg::ref_ptr<osg::GraphicsContext::Traits> traits = new osg::GraphicsContext::Traits;
    traits->readDISPLAY();
    traits->setUndefinedScreenDetailsToDefaultScreen();
    traits->width = 32;
    traits->height = 24;
    traits->windowDecoration = false;
    traits->doubleBuffer = true;
    osg::ref_ptr<osg::GraphicsContext> gc;
    for (int attempt = 0; attempt < 20 && !(gc && gc->valid()); ++attempt) {  // a busy Xvfb refuses now and then
        if (attempt) std::this_thread::sleep_for(std::chrono::milliseconds(50 + 50 * attempt));
        gc = osg::GraphicsContext::createGraphicsContext(traits.get());
    }
    ASSERT_TRUE(gc && gc->valid()) << "no GL window on display " << display;
    constexpr unsigned kFrames = 4;
    osg::ref_ptr<osgViewer::Viewer> viewer = new osgViewer::Viewer;
    viewer->setThreadingModel(osgViewer::ViewerBase::SingleThreaded);
    viewer->setUseConfigureAffinity(false);
    osg::Camera* cam = viewer->getCamera();
    cam->setGraphicsContext(gc.get());
    cam->setViewport(new osg::Viewport(0, 0, 32, 24));
    flushDeletedGLObjectsEvery(*cam, kFrames);
    osg::ref_ptr<osg::Group> root = new osg::Group;
    {
        osg::ref_ptr<osg::Geometry> tri = new osg::Geometry;
        osg::ref_ptr<osg::Vec3Array> v = new osg::Vec3Array;
        v->push_back({-1, 5, -1});
        v->push_back({1, 5, -1});
        v->push_back({0, 5, 1});
        tri->setVertexArray(v.get());
        tri->addPrimitiveSet(new osg::DrawArrays(GL_TRIANGLES, 0, 3));
        tri->setUseDisplayList(false);
        tri->setUseVertexBufferObjects(true);
        osg::ref_ptr<osg::Geode> geode = new osg::Geode;
        geode->addDrawable(tri.get());
        root->addChild(geode.get());
    }
    viewer->setSceneData(root.get());
    viewer->realize();
    ASSERT_TRUE(viewer->isRealized());
    auto* renderer = dynamic_cast<osgViewer::Renderer*>(cam->getRenderer());
    ASSERT_NE(renderer, nullptr);
    osgUtil::SceneView* sv = renderer->getSceneView(0);  // single-threaded: cull and draw use view 0
    ASSERT_NE(sv, nullptr);
    viewer->frame();  // frame 1: the triangle's buffer is created
    osg::GLBufferObjectManager* bom = osg::get<osg::GLBufferObjectManager>(gc->getState()->getContextID());
    ASSERT_NE(bom, nullptr);
    const unsigned active = bom->getNumberActiveGLBufferObjects();
    ASSERT_GE(active, 1u);
    root->removeChildren(0, root->getNumChildren());  // the triangle is destroyed: its buffer is orphaned
    // Frames 2 .. kFrames: no flush (the flag set in frame kFrames makes frame kFrames + 1 flush).
    for (unsigned f = 2; f <= kFrames; ++f) {
        viewer->frame();
        EXPECT_EQ(sv->getAutomaticFlush(), f % kFrames == 0) << "frame " << f;
        EXPECT_EQ(bom->getNumberActiveGLBufferObjects(), active) << "released before the flush frame, frame " << f;
    }
    viewer->frame();  // frame kFrames + 1 flushes
    EXPECT_FALSE(sv->getAutomaticFlush());
    EXPECT_LT(bom->getNumberActiveGLBufferObjects(), active) << "the dropped triangle's buffer was not released";
    viewer->setSceneData(nullptr);
}
