// The panoramic cache and moving objects: a naive cache serves a moving
// object's old pixels (it shows where the object was and hides where it is);
// with FarFieldOptions::cacheMovers the cached frame equals an uncached trace
// of the same frame.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "foundation/units.h"
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

// Still objects (RayScene::placeMovers' `still` list, a traffic run's lamp
// overlays): the cache serves their pixels while they do not change, and
// traces them on the very frame they change (on screen), or forgets their
// cells (off screen) so that the change shows when they come into view.
namespace {

SceneMesh lampBox(glm::u8vec4 colour) {
    SceneMesh m;
    addBox(m, {-1.0f, -1.0f, 0}, {1.0f, 1.0f, 3.0f}, colour);
    return m;
}

std::vector<StillPlacement> lampAt(uint32_t prototype, glm::dvec3 p) {
    StillPlacement s;
    s.object = at(p.x, p.y, p.z);
    s.object.prototype = prototype;
    s.object.id = 77;
    return {s};
}

// Places the still object alone (slot 0).
bool placeLamp(TestCity& t, uint32_t prototype, glm::dvec3 p) {
    const std::vector<StillPlacement> lamp = lampAt(prototype, p);
    return bool(t.rays->placeMovers({}, &lamp));
}

// Pixels of a frame that show the still object: an uncached trace with it and one without it differ there.
std::vector<size_t> footprint(TestCity& t, const Camera& c, const std::vector<StillPlacement>& lamp) {
    FarField plain(*t.rays, &t.grid, options(false, true));
    Image with(c.width, c.height), without(c.width, c.height);
    FrameStats s;
    EXPECT_TRUE(t.rays->placeMovers({}, &lamp));
    plain.render(c, nullptr, with, s);
    const std::vector<StillPlacement> none;
    EXPECT_TRUE(t.rays->placeMovers({}, &none));
    plain.render(c, nullptr, without, s);
    std::vector<size_t> out;
    for (size_t i = 0; i < size_t(c.width) * size_t(c.height); ++i)
        if (channelDiff(with, without, i) > 1) out.push_back(i);
    return out;
}

Image uncached(TestCity& t, const Camera& c) {
    FarField plain(*t.rays, &t.grid, options(false, true));
    Image img(c.width, c.height);
    FrameStats s;
    plain.render(c, nullptr, img, s);
    return img;
}

}  // namespace

TEST(FarFieldStill, TheCacheServesAStillObjectUntilItChangesAndTracesItOnThatFrame) {
    TestCity t = testCity(7, 50);
    ASSERT_TRUE(t.rays);
    const glm::u8vec4 red{230, 20, 20, 255}, green{20, 230, 60, 255};
    ASSERT_TRUE(t.rays->setMoverPrototypes({lampBox(red), lampBox(green)}));
    const Camera view = cam(glm::dvec3(0, -190, 1.7), 0.0, -0.05, 240, 160);
    const glm::dvec3 p(-4, -165, 0);
    const std::vector<size_t> head = footprint(t, view, lampAt(0, p));
    ASSERT_GT(head.size(), 30u);

    FarField cached(*t.rays, &t.grid, options(true, true));
    Image img(view.width, view.height);
    const uint64_t serial0 = t.rays->stillSerial();
    ASSERT_TRUE(placeLamp(t, 0, p));  // red
    EXPECT_GT(t.rays->stillSerial(), serial0);
    EXPECT_TRUE(t.rays->moverSpheres().empty());  // a still object is no mover
    FrameStats s1;
    cached.render(view, nullptr, img, s1);
    // Frames without a change (the same placement passed again, or none passed): served from the cache.
    const uint64_t serial1 = t.rays->stillSerial();
    ASSERT_TRUE(placeLamp(t, 0, p));
    ASSERT_TRUE(t.rays->placeMovers({}));
    EXPECT_EQ(t.rays->stillSerial(), serial1);
    for (int frame = 0; frame < 2; ++frame) {
        FrameStats s;
        cached.render(view, nullptr, img, s);
        size_t fromCache = 0;
        for (size_t i : head) fromCache += cached.classification()[i] == kFarCache ? 1 : 0;
        EXPECT_EQ(fromCache, head.size()) << "frame " << frame;
        for (size_t i : head)
            ASSERT_EQ(glm::u8vec4(img.rgba[4 * i], img.rgba[4 * i + 1], img.rgba[4 * i + 2], 255), red);
    }
    // The lamp turns green: on this frame every pixel of the head is traced and shows green,
    // and the frame equals an uncached trace.
    ASSERT_TRUE(placeLamp(t, 1, p));
    const std::vector<StillState>& st = t.rays->stillObjects();
    ASSERT_EQ(st.size(), 1u);
    EXPECT_EQ(st[0].version, t.rays->stillSerial());
    FrameStats s2;
    cached.render(view, nullptr, img, s2);
    for (size_t i : head) {
        EXPECT_TRUE(cached.classification()[i] == kFarRayHit) << "pixel " << i;
        ASSERT_EQ(glm::u8vec4(img.rgba[4 * i], img.rgba[4 * i + 1], img.rgba[4 * i + 2], 255), green);
    }
    EXPECT_EQ(differing(img, uncached(t, view)), 0u);
    // The next frame serves the green head from the cache again.
    FrameStats s3;
    cached.render(view, nullptr, img, s3);
    size_t fromCache = 0;
    for (size_t i : head) fromCache += cached.classification()[i] == kFarCache ? 1 : 0;
    EXPECT_EQ(fromCache, head.size());
    EXPECT_EQ(differing(img, uncached(t, view)), 0u);

    // Off screen: the camera looks away while the lamp turns red and is hidden and shown; when
    // it looks back, the head shows its lamp now (no cached colour of before).
    Camera away = view;
    away.heading += kPi;
    for (uint32_t proto : {0u, 1u, 0u}) {
        ASSERT_TRUE(placeLamp(t, proto, p));
        FrameStats s;
        cached.render(away, nullptr, img, s);
    }
    FrameStats s4;
    cached.render(view, nullptr, img, s4);
    for (size_t i : head)
        ASSERT_EQ(glm::u8vec4(img.rgba[4 * i], img.rgba[4 * i + 1], img.rgba[4 * i + 2], 255), red) << "pixel " << i;
    EXPECT_EQ(differing(img, uncached(t, view)), 0u);
    // Hidden while looked away: the city behind it shows again (its cells were forgotten).
    const std::vector<StillPlacement> none;
    ASSERT_TRUE(t.rays->placeMovers({}, &none));
    cached.render(away, nullptr, img, s4);
    cached.render(view, nullptr, img, s4);
    EXPECT_EQ(differing(img, uncached(t, view)), 0u);
}

TEST(FarFieldStill, ATurningCameraReusesTheStillObjectsPixels) {
    TestCity t = testCity(7, 50);
    ASSERT_TRUE(t.rays);
    ASSERT_TRUE(t.rays->setMoverPrototypes({lampBox({230, 20, 20, 255})}));
    const Camera view = cam(glm::dvec3(0, -190, 1.7), 0.0, -0.05, 240, 160);
    const glm::dvec3 p(-4, -165, 0);
    Camera turned = view;
    turned.heading += 0.03;
    const std::vector<size_t> head = footprint(t, turned, lampAt(0, p));
    ASSERT_GT(head.size(), 30u);
    ASSERT_TRUE(placeLamp(t, 0, p));
    FarField cached(*t.rays, &t.grid, options(true, true));
    Image img(view.width, view.height);
    FrameStats s1, s2;
    cached.render(view, nullptr, img, s1);
    cached.render(turned, nullptr, img, s2);
    size_t fromCache = 0;
    for (size_t i : head) fromCache += cached.classification()[i] == kFarCache ? 1 : 0;
    // Cells are world directions: the head's are reused within the cache's error bound, as the
    // static city's are (a moving object's would all be traced).
    EXPECT_GT(fromCache, head.size() / 2);
    const size_t withHead = differing(img, uncached(t, turned));
    // The static scene's own resampling error on the same turn, the head hidden.
    const std::vector<StillPlacement> none;
    ASSERT_TRUE(t.rays->placeMovers({}, &none));
    FarField bare(*t.rays, &t.grid, options(true, true));
    bare.render(view, nullptr, img, s1);
    bare.render(turned, nullptr, img, s2);
    const size_t staticTurning = differing(img, uncached(t, turned));
    EXPECT_LE(withHead, staticTurning + 3 + head.size() / 10);
}
