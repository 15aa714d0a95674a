// far_precision: how much of the far field's quality depends on where in a
// large city the camera is. The same city and path are drawn with their
// geometry at the frame origin (a paged city's centre) and moved by a list of
// offsets (the corners of a 64 km paged city), in `full`, `raycast` and
// `hybrid` (fixed near distance), with two ray-scene layouts:
//   flat:    one scene with float vertices around the frame origin (the city
//            centre), ray origins relative to it;
//   regions: region scenes with region-local vertices and the frame origin
//            moved next to the camera before each frame (RayScene::placeFrameNear,
//            as vista bench and render do).
// Prints a Markdown table: median luma PSNR against `full` of the same
// placement, and of each mode against itself at the centre.
//
// Usage: far_precision CITY.osgb [--frames N] [--size WxH] [--seed S] [--near M]
// (needs a display: xvfb-run -a).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "foundation/statistics.h"
#include "runtime/engine/metrics.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/paths.h"
#include "runtime/scene/scene_graph.h"
#include "nodes/render/offscreen.h"
#include "nodes/render/render_mode.h"
#include "tests/nodes/render/move_geometry.h"

using namespace vista;

namespace {

int fail(const std::string& m) {
    std::fprintf(stderr, "far_precision: %s\n", m.c_str());
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) return fail("usage: far_precision CITY.osgb [--frames N] [--size WxH] [--seed S] [--near M]");
    const std::string cityFile = argv[1];
    int frames = 12, width = 640, height = 480;
    uint64_t seed = 5;
    double nearM = 100;
    for (int i = 2; i + 1 < argc; i += 2) {
        const std::string k = argv[i];
        if (k == "--frames") frames = std::atoi(argv[i + 1]);
        else if (k == "--size") {
            if (std::sscanf(argv[i + 1], "%dx%d", &width, &height) != 2) return fail("--size: expected WxH");
        } else if (k == "--seed") seed = std::strtoull(argv[i + 1], nullptr, 10);
        else if (k == "--near") nearM = std::atof(argv[i + 1]);
        else return fail("unknown option " + k);
    }
    if (frames < 1 || width < 16 || height < 16 || !(nearM > 0)) return fail("bad --frames, --size or --near");
    auto renderer = OffscreenRenderer::create(width, height);
    if (!renderer) return fail(renderer.status().message());

    struct Placement {
        const char* name;
        glm::dvec3 d;
    };
    const Placement placements[] = {{"centre", glm::dvec3(0.0)},
                                    {"(+12.6, +12.7) km", glm::dvec3(12600, 12700, 0)},
                                    {"(+32, +32) km", glm::dvec3(32000, 32000, 0)},
                                    {"(-32, -32) km", glm::dvec3(-32000, -32000, 0)}};
    const char* layouts[] = {"flat", "regions"};
    const char* modes[] = {"full", "raycast", "hybrid"};
    // images[placement][layout][mode][frame]
    std::vector<std::vector<std::vector<std::vector<Image>>>> images;
    for (const Placement& pl : placements) {
        images.emplace_back();
        for (int layout = 0; layout < 2; ++layout) {
            auto city = loadCityFile(cityFile);
            if (!city) return fail(city.status().message());
            if (!test::moveGeometry(*city, pl.d)) return fail("the city root has a child that is not a tile");
            PathOptions po;
            po.seed = seed;
            po.kind = PathKind::Car;
            auto path = generatePath(city->streets, city->params, po);
            if (!path) return fail(path.status().message());
            RaySceneOptions ro;
            ro.regionSizeM = layout == 0 ? 0.0 : RaySceneOptions().regionSizeM;
            auto rays = RayScene::build(*city, ro);
            if (!rays) return fail(rays.status().message());
            ModeContext ctx;
            ctx.city = &*city;
            ctx.scene = sceneRoot(*city);
            ctx.renderer = renderer->get();
            ctx.rays = rays->get();
            ctx.options.nearDistance = nearM;
            Camera base;
            base.width = width;
            base.height = height;
            const std::vector<size_t> idx = path->spread(size_t(frames));
            images.back().emplace_back();
            for (const char* name : modes) {
                auto mode = createRenderMode(name, ctx);
                if (!mode) return fail(mode.status().message());
                images.back().back().emplace_back();
                for (size_t f : idx) {
                    Camera c = path->camera(f, base);
                    c.eye += pl.d;
                    if (layout == 1) {
                        Status st = (*rays)->placeFrameNear(c.eye);
                        if (!st) return fail(st.message());
                    }
                    Image img;
                    FrameStats fs;
                    Status st = (*mode)->renderFrame(c, img, fs);
                    if (!st) return fail(std::string(name) + ": " + st.message());
                    images.back().back().back().push_back(std::move(img));
                }
            }
            std::fprintf(stderr, "far_precision: %s, %s done\n", pl.name, layouts[layout]);
        }
    }
    std::printf(
        "| geometry moved by | ray scene | raycast vs full (dB) | hybrid vs full (dB) | full vs full at the "
        "centre (dB) | raycast vs raycast at the centre (dB) | hybrid vs hybrid at the centre (dB) |\n");
    std::printf("|---|---|---|---|---|---|---|\n");
    for (size_t p = 0; p < images.size(); ++p)
        for (int layout = 0; layout < 2; ++layout) {
            const auto& im = images[p][size_t(layout)];
            const auto& c0 = images[0][size_t(layout)];
            std::vector<double> rf, hf, ff, rr, hh;
            for (size_t f = 0; f < im[0].size(); ++f) {
                rf.push_back(lumaPsnr(im[1][f], im[0][f]));
                hf.push_back(lumaPsnr(im[2][f], im[0][f]));
                ff.push_back(lumaPsnr(im[0][f], c0[0][f]));
                rr.push_back(lumaPsnr(im[1][f], c0[1][f]));
                hh.push_back(lumaPsnr(im[2][f], c0[2][f]));
            }
            std::printf("| %s | %s | %.1f | %.1f | %.1f | %.1f | %.1f |\n", placements[p].name, layouts[layout],
                        median(rf), median(hf), median(ff), median(rr), median(hh));
        }
    return 0;
}
