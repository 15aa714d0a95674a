// Headless render of a generated city (xvfb-run + llvmpipe here): the picture
// must be sensible — sky at the top, city below, not blank — from a street
// view and from above.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "citygen/generate.h"
#include "citygen/lighting.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"
#include "nodes/render/offscreen.h"
#include "nodes/near_far_split.h"
#include "nodes/render/render_mode.h"
#include "runtime/engine/metrics.h"
#include "runtime/scene/paths.h"

using namespace vista;

namespace {

// A pixel is sky when it equals the sky background of its own ray (the sky is
// drawn from skyColor by every renderer), within 2 levels per channel.
bool isSky(const glm::u8vec4& c, const glm::u8vec4& sky) {
    return std::abs(int(c.x) - int(sky.x)) <= 2 && std::abs(int(c.y) - int(sky.y)) <= 2 &&
           std::abs(int(c.z) - int(sky.z)) <= 2;
}

struct Fractions {
    double skyTop = 0, skyBottom = 0;
    int distinctColours = 0;
};

Fractions analyse(const Image& img, const Camera& cam) {
    Fractions f;
    Image skyImg(cam.width, cam.height);
    renderSky(cam, skyImg);
    int top = 0, bottom = 0, nTop = 0, nBottom = 0;
    std::vector<uint32_t> seen;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            auto c = img.at(x, y);
            bool sky = isSky(c, skyImg.at(x, y));
            if (y < img.height / 2) {
                ++nTop;
                top += sky;
            }
            if (y >= img.height * 3 / 4) {
                ++nBottom;
                bottom += sky;
            }
            uint32_t key = (uint32_t(c.x) >> 3) << 10 | (uint32_t(c.y) >> 3) << 5 | (uint32_t(c.z) >> 3);
            seen.push_back(key);
        }
    std::sort(seen.begin(), seen.end());
    f.distinctColours = int(std::unique(seen.begin(), seen.end()) - seen.begin());
    f.skyTop = double(top) / nTop;
    f.skyBottom = double(bottom) / nBottom;
    return f;
}

}  // namespace

TEST(RenderCity, DefaultStyleCityMakesASensiblePicture) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no DISPLAY: run the tests under xvfb-run -a";
    CityParams p;  // default parameters, smaller area to keep the test quick
    p.size_m = 800;
    p.seed = 1;
    auto city = generateCity(p);
    ASSERT_TRUE(city.isOk()) << city.status().message();
    ASSERT_GT(city->buildings.size(), 20u);
    osg::ref_ptr<osg::Node> scene = buildCityScene(*city);
    ASSERT_TRUE(scene.valid());

    auto rr = OffscreenRenderer::create(320, 240);
    ASSERT_TRUE(rr.isOk()) << rr.status().message();
    auto& renderer = *rr.value();

    // Street view: the start of a deterministic drive, looking along a street.
    PathOptions po;
    po.seed = 2;
    po.runUp = 0;  // the very start of the drive: a street view by construction
    po.duration = 2;
    auto path = generatePath(city->streets, p, po);
    ASSERT_TRUE(path.isOk()) << path.status().message();
    Camera base;
    base.width = 320;
    base.height = 240;
    base.fovY = glm::radians(60.0);
    Camera cam = path->camera(0, base);
    cam.pitch = glm::radians(8.0);  // tilt up a little so the sky is surely in view
    Image img;
    FrameStats st;
    ASSERT_TRUE(renderer.render(scene.get(), cam, 0.0, &img, nullptr, st).isOk());
    ASSERT_TRUE(img.valid());
    Fractions f = analyse(img, cam);
    EXPECT_GT(f.skyTop, 0.04) << "the upper half of a street view shows some sky";
    EXPECT_LT(f.skyTop, 0.9) << "the upper half of a street view shows buildings or trees";
    EXPECT_EQ(f.skyBottom, 0.0) << "the bottom of a street view shows the street, not sky";
    EXPECT_GT(f.distinctColours, 12) << "a city picture has many colours (walls, windows, road, trees)";
    EXPECT_GT(st.triangles, 1000u);
    if (const char* dir = std::getenv("VISTA_TEST_OUTPUT")) writePng(img, std::string(dir) + "/render_city_street.png");

    // From above, looking down at the centre: no sky at all, plenty of geometry.
    Camera top = base;
    top.eye = glm::dvec3(p.origin_x, p.origin_y, 500.0);
    top.pitch = glm::radians(-89.0);
    ASSERT_TRUE(renderer.render(scene.get(), top, 0.0, &img, nullptr, st).isOk());
    Fractions g = analyse(img, top);
    EXPECT_EQ(g.skyTop, 0.0);
    EXPECT_EQ(g.skyBottom, 0.0);
    EXPECT_GT(g.distinctColours, 12);
    if (const char* dir = std::getenv("VISTA_TEST_OUTPUT")) writePng(img, std::string(dir) + "/render_city_top.png");

    // `full` draws the city re-chunked into hybrid's 40 m near-field chunks:
    // the same triangles and vertex floats, so the picture of the city graph
    // as loaded (up to depth ties of far coplanar surfaces, whose winner the
    // draw order decides: a few pixels from 500 m above), with fewer
    // triangles submitted after culling. From 500 m a pixel spans metres and
    // the 15 cm lane markings (centre lines, stop lines, zebra stripes) are
    // sub-pixel: whether one covers a pixel centre flips with the float
    // rounding of the chunk transform (about 20 of 76,800 pixels, road grey
    // vs marking white: ~44 dB), hence 40 dB there.
    ModeContext ctx;
    ctx.scene = scene.get();
    ctx.renderer = &renderer;
    auto full = createRenderMode("full", ctx);
    ASSERT_TRUE(full.isOk()) << full.status().message();
    EXPECT_EQ(ctx.nearField().triangles, countTriangles(scene.get()));
    std::vector<uint32_t> order = ctx.nearField().drawOrder;
    std::sort(order.begin(), order.end());
    ASSERT_EQ(order.size(), ctx.nearField().chunks.size());
    for (uint32_t i = 0; i < order.size(); ++i) ASSERT_EQ(order[i], i) << "drawOrder lists every chunk once";
    const std::pair<Camera, double> views[] = {{cam, 60.0}, {top, 40.0}};
    for (const auto& [c, minPsnr] : views) {
        Image tiles, chunks;
        FrameStats ts, cs;
        ASSERT_TRUE(renderer.render(scene.get(), c, 0.0, &tiles, nullptr, ts).isOk());
        ASSERT_TRUE(full.value()->renderFrame(c, chunks, cs).isOk());
        const double psnr = lumaPsnr(chunks, tiles);
        EXPECT_GE(psnr, minPsnr) << "chunked full vs the loaded graph";
        EXPECT_LE(cs.triangles, ts.triangles);
        std::printf("full chunked vs tiles: %.2f dB, triangles %llu vs %llu\n", psnr, (unsigned long long)cs.triangles,
                    (unsigned long long)ts.triangles);
    }
}
