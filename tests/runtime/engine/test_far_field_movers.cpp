// The panoramic cache and moving objects: a naive cache serves a moving
// object's old pixels (it shows where the object was and hides where it is);
// with FarFieldOptions::cacheMovers the cached frame equals an uncached trace
// of the same frame.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "tests/runtime/engine/far_field_fixtures.h"

namespace {

SceneMesh carBox() {
    SceneMesh m;
    addBox(m, {-2.5f, -1.2f, 0}, {2.5f, 1.2f, 2.0f}, {200, 30, 30, 255});
    return m;
}

MoverPlacement at(double x, double y, double z) {
    MoverPlacement p;
    p.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(x, y, z));
    p.id = 1;
    p.cls = 15;
    return p;
}

FarFieldOptions options(bool cache, bool cacheMovers) {
    FarFieldOptions o;
    o.nearDistance = 5.0;
    o.cache = cache;
    o.cacheMovers = cacheMovers;
    o.cacheAdaptive = false;
    o.horizonAdaptive = false;
    o.movingHeight = 2.0;
    return o;
}

// Pixels of `a` and `b` that differ by more than one level in a channel.
size_t differing(const Image& a, const Image& b) {
    size_t n = 0;
    for (size_t i = 0; i < size_t(a.width) * size_t(a.height); ++i) n += channelDiff(a, b, i) > 1 ? 1 : 0;
    return n;
}

// The second frame of a cached pipeline (the object moved from `from` to `to`
// between the frames) and an uncached trace of that frame, differing pixels.
size_t cacheError(TestCity& t, const Camera& c1, const Camera& c2, glm::dvec3 from, glm::dvec3 to, bool fix) {
    EXPECT_TRUE(t.rays->placeMovers({at(from.x, from.y, from.z)}));
    FarField cached(*t.rays, &t.grid, options(true, fix));
    Image img(c1.width, c1.height), ref(c2.width, c2.height);
    FrameStats s;
    cached.render(c1, nullptr, img, s);
    EXPECT_TRUE(t.rays->placeMovers({at(to.x, to.y, to.z)}));
    FrameStats s2;
    cached.render(c2, nullptr, img, s2);
    EXPECT_GT(s2.pixels.cache, 0u);  // the cache served pixels
    FarField plain(*t.rays, &t.grid, options(false, fix));
    FrameStats s3;
    plain.render(c2, nullptr, ref, s3);
    return differing(img, ref);
}

}  // namespace

TEST(FarFieldMovers, TheCacheNeverServesAMovingObjectsPixels) {
    TestCity t = testCity(7, 50);
    ASSERT_TRUE(t.rays);
    ASSERT_TRUE(t.rays->setMoverPrototypes({carBox()}));
    const Camera still = cam(glm::dvec3(0, -190, 1.7), 0.0, -0.05, 240, 160);
    const glm::dvec3 a(-4, -165, 0), b(4, -165, 0);
    // The object is seen: an uncached frame with it differs from one without it.
    {
        FarField plain(*t.rays, &t.grid, options(false, true));
        Image with(still.width, still.height), without(still.width, still.height);
        FrameStats s;
        ASSERT_TRUE(t.rays->placeMovers({at(a.x, a.y, a.z)}));
        plain.render(still, nullptr, with, s);
        ASSERT_TRUE(t.rays->placeMovers({}));
        plain.render(still, nullptr, without, s);
        ASSERT_GT(differing(with, without), 50u);
    }
    // A still camera (every cell exact): the naive cache shows the object where it was.
    const size_t naiveStill = cacheError(t, still, still, a, b, false);
    const size_t fixedStill = cacheError(t, still, still, a, b, true);
    // A turning camera (cells are world directions: reused within the 0.25 px error bound).
    Camera moved = still;
    moved.heading += 0.03;
    const size_t naiveMoving = cacheError(t, still, moved, a, b, false);
    const size_t fixedMoving = cacheError(t, still, moved, a, b, true);
    // The same turn with the object out of sight (behind the camera): the static scene's own
    // resampling error within the bound.
    const glm::dvec3 behind(0, -400, 0);
    const size_t staticTurning = cacheError(t, still, moved, behind, behind, true);
    std::printf(
        "cache error on a moving object (pixels differing from an uncached trace, of %d): "
        "still camera naive %zu, fixed %zu; turning camera naive %zu, fixed %zu (static scene alone %zu)\n",
        still.width * still.height, naiveStill, fixedStill, naiveMoving, fixedMoving, staticTurning);
    EXPECT_GT(naiveStill, 50u);
    EXPECT_EQ(fixedStill, 0u);
    EXPECT_GT(naiveMoving, 50u);
    // Turning, the cache reuses static pixels within its error bound (0.25 px): colours may
    // differ at static edges as they do without any object, and nowhere else.
    EXPECT_LE(fixedMoving, staticTurning + 3);
}
