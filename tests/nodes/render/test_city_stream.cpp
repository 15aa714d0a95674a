// A streamed paged city in the hybrid mode (nodes/render/city_stream.h,
// streamed_near_field.h): when regions leave, the mode told of it
// (RenderMode::sceneChanged with the advance's boxes, as the bench does after
// every advance that changed the resident set) draws the frame a mode made
// after the change draws: the far pixels whose rays pass through a dropped
// region are traced again, the others still come from the panoramic cache; a
// mode not told serves the dropped regions from its cache.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "nodes/render/city_stream.h"
#include "nodes/render/offscreen.h"
#include "nodes/render/render_mode.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/paged_load.h"
#include "tests/common/small_paged_city.h"
#include "tests/nodes/render/render_fixtures.h"

using namespace vista;

namespace {

struct Frame {
    Image image;
    FrameStats stats;
};

Frame draw(RenderMode& mode, RayScene& rays, const Camera& c) {
    Frame f;
    EXPECT_TRUE(rays.placeFrameNear(c.eye).isOk());
    const Status s = mode.renderFrame(c, f.image, f.stats);
    EXPECT_TRUE(s.isOk()) << s.message();
    return f;
}

size_t differing(const Image& a, const Image& b) {
    size_t n = 0;
    for (size_t k = 0; k + 3 < a.rgba.size() && k + 3 < b.rgba.size(); k += 4)
        n += a.rgba[k] != b.rgba[k] || a.rgba[k + 1] != b.rgba[k + 1] || a.rgba[k + 2] != b.rgba[k + 2] ? 1 : 0;
    return n + (a.rgba.size() != b.rgba.size() ? 1 : 0);
}

}  // namespace

TEST(CityStream, HybridTracesADroppedRegionsPixelsAgain) {
    REQUIRE_DISPLAY();
    // The shared 1.5 km city in 500 m regions (3 x 3), read in place.
    auto m = readPagedManifest(test::smallPagedCity().dir);
    ASSERT_TRUE(m.isOk()) << m.status().message();
    RegionPagerOptions po;
    po.radius = 600;
    po.far = 0;
    po.prefetchS = 0;
    po.wait = true;
    auto stream = CityStream::create(*m, po, /*rays=*/true);
    ASSERT_TRUE(stream.isOk()) << stream.status().message();
    CityStream& s = **stream;
    s.enableNearField(0);
    auto renderer = OffscreenRenderer::create(128, 96);
    ASSERT_TRUE(renderer.isOk()) << renderer.status().message();
    ModeContext ctx;
    ctx.renderer = renderer->get();
    ctx.streamedCity = s.graph();
    ctx.scene = s.graph();
    ctx.stream = &s;
    ctx.rays = s.rays();
    ctx.paged = &*m;
    ctx.options.nearDistance = 100;
    ctx.options.cacheAdaptive = false;  // the cache never pauses: frames that do not follow timings

    // Every region resident (the pager's eye at the centre); the camera in the south row looks north.
    const glm::dvec3 o(m->params.origin_x, m->params.origin_y, 0.0);
    auto a = s.advance(o, glm::dvec3(0.0));
    ASSERT_TRUE(a.isOk()) << a.status().message();
    EXPECT_EQ(a->arrived, 9);
    Camera cam;
    cam.eye = o + glm::dvec3(13.0, -600.0, 6.0);
    cam.heading = 0.0;
    cam.pitch = -0.03;
    cam.fovY = 1.0;
    cam.width = 128;
    cam.height = 96;
    auto told = createRenderMode("hybrid-fixed", ctx), stale = createRenderMode("hybrid-fixed", ctx);
    ASSERT_TRUE(told.isOk() && stale.isOk());
    for (RenderMode* mode : {told->get(), stale->get()}) mode->sceneChanged(a->changed);  // the regions arrived
    for (RenderMode* mode : {told->get(), stale->get()}) {
        (void)draw(*mode, *s.rays(), cam);
        const Frame again = draw(*mode, *s.rays(), cam);
        EXPECT_GT(again.stats.pixels.cache, 0u) << "a still camera: far pixels from the cache";
    }
    // The pager's eye moves south: the two northern rows leave (the camera's own row stays).
    const uint64_t generation = s.generation();
    auto b = s.advance(o + glm::dvec3(0.0, -900.0, 0.0), glm::dvec3(0.0));
    ASSERT_TRUE(b.isOk()) << b.status().message();
    EXPECT_EQ(b->dropped, 6);
    EXPECT_EQ(b->arrived, 0);
    EXPECT_GT(s.generation(), generation);
    EXPECT_EQ(s.nearField()->levels(), 3u);
    EXPECT_EQ(b->changed.size(), 6u);
    (*told)->sceneChanged(b->changed);
    auto fresh = createRenderMode("hybrid-fixed", ctx);
    ASSERT_TRUE(fresh.isOk());
    const Frame want = draw(**fresh, *s.rays(), cam), got = draw(**told, *s.rays(), cam),
                old = draw(**stale, *s.rays(), cam);
    EXPECT_GT(got.stats.pixels.cache, 0u) << "the cells whose rays miss the dropped regions are kept";
    EXPECT_GT(got.stats.raysCast, 0u) << "the dropped regions' pixels are traced again";
    EXPECT_EQ(differing(got.image, want.image), 0u);
    EXPECT_GT(differing(old.image, want.image), 0u) << "a cache that is kept serves the dropped regions";
}
