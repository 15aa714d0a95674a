// The same street geometry at the centre of a city frame and 32 km from it
// (a corner of a 64 km paged city, whose frame origin is the city centre):
// `full`, `raycast` and `hybrid` draw the same picture there (needs an X
// display: run under xvfb-run -a).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <unistd.h>

#include "citygen/generate.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"
#include "nodes/render/offscreen.h"
#include "nodes/render/render_mode.h"
#include "tests/nodes/render/move_geometry.h"

using namespace vista;
using namespace vista::test;

namespace {

struct Worst {
    int level = 0;      // largest channel difference
    size_t pixels = 0;  // pixels with a channel differing by more than 1
};
Worst compare(const Image& a, const Image& b) {
    Worst w;
    for (size_t i = 0; i + 3 < a.rgba.size(); i += 4) {
        int d = 0;
        for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(int(a.rgba[i + size_t(k)]) - int(b.rgba[i + size_t(k)])));
        w.level = std::max(w.level, d);
        w.pixels += d > 1 ? 1 : 0;
    }
    return w;
}

}  // namespace

TEST(FarPrecision, SameImageAtTheCentreAndThirtyTwoKilometresAway) {
    const char* disp = std::getenv("DISPLAY");
    if (!disp || !*disp) GTEST_SKIP() << "no X display: run the rendering tests under xvfb-run -a";
    CityParams p;
    p.size_m = 500;
    p.seed = 4;
    auto gen = generateCity(p);
    ASSERT_TRUE(gen.isOk()) << gen.status().message();
    const std::string path =
        std::filesystem::temp_directory_path() / ("vista_far_precision_" + std::to_string(getpid()) + ".osgb");
    ASSERT_TRUE(writeCityFile(*gen, path).isOk());
    const int W = 200, H = 150;
    auto renderer = OffscreenRenderer::create(W, H);
    ASSERT_TRUE(renderer.isOk()) << renderer.status().message();

    const char* modes[] = {"full", "raycast", "hybrid"};
    // Per placement: the images of each mode for two cameras (street level, elevated).
    auto renderAll = [&](const glm::dvec3& d, std::vector<Image>& out) {
        auto city = loadCityFile(path);
        ASSERT_TRUE(city.isOk()) << city.status().message();
        ASSERT_TRUE(moveGeometry(*city, d));
        auto rays = RayScene::build(*city);
        ASSERT_TRUE(rays.isOk()) << rays.status().message();
        ModeContext ctx;
        ctx.city = &*city;
        ctx.scene = sceneRoot(*city);
        ctx.renderer = renderer->get();
        ctx.rays = rays->get();
        ctx.options.nearDistance = 100;
        ctx.options.cache = false;
        const auto& g = city->streets;
        ASSERT_FALSE(g.nodes.empty());
        for (const char* name : modes) {
            auto mode = createRenderMode(name, ctx);
            ASSERT_TRUE(mode.isOk()) << name << ": " << mode.status().message();
            for (int k = 0; k < 2; ++k) {
                const auto& n = g.nodes[size_t(3 + 11 * k) % g.nodes.size()];
                Camera c;
                c.eye = d + glm::dvec3(p.origin_x + n.x + 0.37, p.origin_y + n.y - 0.21, k == 0 ? 1.7 : 30.0);
                c.heading = 0.3 + 1.9 * k;
                c.pitch = k == 0 ? 0.01 : -0.2;
                c.width = W;
                c.height = H;
                c.fovY = 1.0;
                ASSERT_TRUE((*rays)->placeFrameNear(c.eye).isOk());  // as vista bench and render do
                Image img;
                FrameStats st;
                ASSERT_TRUE((*mode)->renderFrame(c, img, st).isOk()) << name;
                out.push_back(std::move(img));
            }
        }
    };
    std::vector<Image> centre;
    renderAll(glm::dvec3(0.0), centre);
    ASSERT_EQ(centre.size(), 6u);
    for (const glm::dvec3 d : {glm::dvec3(32000, 32000, 0), glm::dvec3(-32000, 32000, 0), glm::dvec3(32000, -32000, 0),
                               glm::dvec3(-32000, -32000, 0)}) {
        std::vector<Image> far;
        renderAll(d, far);
        ASSERT_EQ(far.size(), centre.size());
        for (size_t i = 0; i < far.size(); ++i) {
            const Worst w = compare(far[i], centre[i]);
            std::printf("%-8s camera %zu at (%+.0f, %+.0f) km: largest difference %d levels, %zu pixels above 1\n",
                        modes[i / 2], i % 2, d.x / 1000, d.y / 1000, w.level, w.pixels);
            EXPECT_LE(w.level, 1) << modes[i / 2] << ", camera " << i % 2 << ", geometry moved by (" << d.x << ", "
                                  << d.y << "): " << w.pixels << " pixels differ by more than 1 level";
        }
    }
    std::filesystem::remove(path);
}
