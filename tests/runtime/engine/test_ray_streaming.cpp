// The streamed ray scene of a paged city (runtime/engine/ray_streaming.h),
// fed by a region pager the way CityStream feeds it (the pager's prepare hook
// builds each region's Embree scene on the worker, apply() instances it): in
// wait mode every frame is the frame of a scene built at once from the
// regions within reach of its camera (RayScene::build of the merged model),
// to the byte, while regions arrive and leave along the walk.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "runtime/engine/frame_raycast.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/engine/ray_streaming.h"
#include "runtime/scene/paged_load.h"
#include "tests/common/run_vista.h"
#include "tests/common/small_paged_city.h"
#include "tests/common/temp_dir.h"

using vista::test::CliRun;
using vista::test::runVista;
using vista::test::TempDir;

namespace {

// A walk across the 1.5 km city of 500 m regions, south-west to north-east, looking ahead.
std::vector<vista::Camera> walk(const vista::PagedManifest& m, int steps) {
    std::vector<vista::Camera> out;
    const glm::dvec3 o(m.params.origin_x, m.params.origin_y, 0.0);
    for (int k = 0; k < steps; ++k) {
        vista::Camera c;
        const double s = -600.0 + 1200.0 * k / (steps - 1);
        c.eye = o + glm::dvec3(s, 0.8 * s + 17.0, 1.7);
        c.heading = std::atan2(1.0, 0.8);  // clockwise from +y, towards (1, 0.8)
        c.pitch = -0.05;
        c.fovY = 1.0;
        c.width = 96;
        c.height = 72;
        out.push_back(c);
    }
    return out;
}

vista::Image frameOf(const vista::RayScene& rays, const vista::Camera& c) {
    vista::Image img;
    vista::FrameStats stats;
    vista::raycastFrame(rays, c, img, stats, 2, vista::FrameEffects());
    return img;
}

}  // namespace

TEST(RayStreaming, WaitingFramesAreTheFramesOfTheRegionsWithinReach) {
    // The shared 1.5 km city in 500 m regions (3 x 3), read in place.
    auto m = vista::readPagedManifest(vista::test::smallPagedCity().dir);
    ASSERT_TRUE(m.isOk()) << m.status().message();

    vista::RegionPagerOptions o;
    o.radius = 150;
    o.far = 450;
    o.prefetchS = 0;  // the desired set is that of the eye alone
    o.wait = true;
    o.workers = 2;
    auto s = vista::StreamedRayScene::follower(*m);
    ASSERT_TRUE(s.isOk()) << s.status().message();
    const vista::StreamedRayScene* scene = s->get();
    o.prepare = [scene](vista::SceneModel& model, const vista::RegionLoad&) -> std::shared_ptr<void> {
        return scene->prepare(model);
    };
    // Declared after the scene: stopped (its workers joined) before the scene goes.
    vista::RegionPager pager(*m, o);
    int arrived = 0, dropped = 0;
    for (const vista::Camera& c : walk(*m, 7)) {
        pager.update(c.eye, glm::dvec3(8.0, 6.4, 0.0));
        vista::RegionPagerDelta d = pager.collect();
        std::vector<std::shared_ptr<vista::RayScene::PreparedRegion>> prepared;
        for (const vista::RegionArrival& a : d.arrived)
            prepared.push_back(std::static_pointer_cast<vista::RayScene::PreparedRegion>(a.prepared));
        auto f = (*s)->apply(d, prepared);
        ASSERT_TRUE(f.isOk()) << f.status().message();
        EXPECT_TRUE(f->damaged.empty());
        arrived += f->arrived;
        dropped += f->dropped;
        ASSERT_TRUE((*s)->rays().placeFrameNear(c.eye).isOk());
        // The same reach loaded at once and built in one go.
        const std::vector<glm::dvec2> eye = {glm::dvec2(c.eye)};
        const std::vector<int> full = vista::selectPagedRegions(*m, eye, o.radius);
        const std::vector<int> coarse = vista::selectCoarseRegions(*m, eye, o.far, full);
        auto merged = vista::loadPagedCity(*m, full, o.radius, nullptr, coarse);
        ASSERT_TRUE(merged.isOk()) << merged.status().message();
        ASSERT_EQ(merged->regions.size(), full.size() + coarse.size());
        auto built = vista::RayScene::build(*merged);
        ASSERT_TRUE(built.isOk()) << built.status().message();
        ASSERT_TRUE((*built)->placeFrameNear(c.eye).isOk());
        EXPECT_EQ((*s)->rays().regionCount(), int(merged->regions.size()));
        EXPECT_EQ((*s)->rays().triangleCount(), (*built)->triangleCount());
        const vista::Image a = frameOf((*s)->rays(), c), b = frameOf(**built, c);
        ASSERT_EQ(a.rgba.size(), b.rgba.size());
        size_t differ = 0;
        for (size_t k = 0; k < a.rgba.size(); ++k) differ += a.rgba[k] != b.rgba[k] ? 1 : 0;
        EXPECT_EQ(differ, 0u) << "eye " << c.eye.x << ", " << c.eye.y;
    }
    // The coarse levels' trees are traced (with the city's tree shapes, as in the merged model).
    int impostorHits = 0;
    const glm::dvec3 eye = walk(*m, 7).back().eye;
    const glm::vec3 org(glm::dvec3(eye.x, eye.y, 5.0) - (*s)->rays().frameOrigin());
    for (int i = 0; i < 3600; ++i) {
        const double a = 2.0 * M_PI * i / 3600.0;
        const glm::vec3 dir = glm::normalize(glm::vec3(float(std::sin(a)), float(std::cos(a)), -0.004f));
        impostorHits += (*s)->rays().source((*s)->rays().intersect(org, dir, 160.0f)).impostor >= 0 ? 1 : 0;
    }
    EXPECT_GT(impostorHits, 10);
    EXPECT_GT(arrived, 4) << "regions arrive along the walk";
    EXPECT_GT(dropped, 0) << "and leave behind it";
    const vista::RegionPagerStats st = pager.stats();
    EXPECT_EQ(st.loads, arrived);
    EXPECT_EQ(st.unloads, dropped);
}

TEST(RayStreaming, ARegionPreparedOnAnotherThreadHitsAsAnAddedOne) {
    TempDir tmp("vista_ray_prepared");
    const std::string dir = tmp.file("city.paged");
    const CliRun r = runVista("gen --size 1000 --seed 4 --detail 1 --region-size 500 -q -o " + dir);
    ASSERT_EQ(r.code, 0) << r.err;
    auto m = vista::readPagedManifest(dir);
    ASSERT_TRUE(m.isOk()) << m.status().message();
    auto first = vista::loadPagedRegion(*m, 0, false), second = vista::loadPagedRegion(*m, 3, false);
    ASSERT_TRUE(first.isOk() && second.isOk());
    const glm::dvec3 origin(m->params.origin_x, m->params.origin_y, 0.0);
    auto a = vista::RayScene::empty(origin), b = vista::RayScene::empty(origin);
    ASSERT_TRUE(a.isOk() && b.isOk());
    ASSERT_TRUE((*a)->addRegion(*first).isOk());
    ASSERT_TRUE((*a)->commit().isOk());
    ASSERT_TRUE((*b)->addRegion(*first).isOk());
    ASSERT_TRUE((*b)->addRegion(*second).isOk());
    ASSERT_TRUE((*b)->commit().isOk());
    const vista::Camera cam = walk(*m, 3)[1];
    // Scene a is queried while another thread prepares the second region for it.
    std::shared_ptr<vista::RayScene::PreparedRegion> prepared;
    std::string error;
    std::thread worker([&] {
        auto p = (*a)->prepareRegion(*second);
        if (p) prepared = *p;
        else error = p.status().message();
    });
    for (int k = 0; k < 3; ++k) (void)frameOf(**a, cam);
    worker.join();
    ASSERT_TRUE(prepared) << error;
    auto id = (*a)->addPrepared(prepared);
    ASSERT_TRUE(id.isOk()) << id.status().message();
    EXPECT_FALSE((*a)->addPrepared(prepared).isOk()) << "added once";
    EXPECT_FALSE((*b)->addPrepared(prepared).isOk()) << "another scene's region";
    ASSERT_TRUE((*a)->commit().isOk());
    EXPECT_EQ((*a)->triangleCount(), (*b)->triangleCount());
    EXPECT_TRUE(frameOf(**a, cam).rgba == frameOf(**b, cam).rgba);
}
