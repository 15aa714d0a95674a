// The offscreen renderer leaves its caller's thread on every core it had:
// osgViewer pins a single-threaded viewer's main thread to core 0 unless told
// not to, and every thread started afterwards (TBB's ray casting, the far
// field's overlap thread) then shares that one core (render/offscreen.cpp).
#include <sched.h>

#include <cstdlib>
#include <thread>

#include <gtest/gtest.h>
#include <osg/Group>
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
