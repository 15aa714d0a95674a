// Soak: a long `hybrid` walkthrough (default 100,000 frames at 64x48) with the
// resident set size sampled every 1,000 frames, to show that memory does not
// grow with the number of frames (docs/measurements/reliability.md). A measurement driver,
// not a test: it asserts nothing; it prints CSV (frame, rss_mb, ms_per_frame
// over the last interval) and a last line with the growth (MB and percent of
// the first sample, taken after frame 1).
//   usage: soak CITY.osgb [FRAMES] [WIDTHxHEIGHT]   (needs an X display: xvfb-run -a)
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "foundation/process_memory.h"
#include "foundation/timing.h"
#include "nodes/render/offscreen.h"
#include "nodes/render/render_mode.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/paths.h"
#include "runtime/scene/scene_graph.h"

namespace {

double rssMb() { return double(vista::residentSetBytes()) / (1024.0 * 1024.0); }

}  // namespace

int main(int argc, char** argv) {
    using namespace vista;
    if (argc < 2) {
        std::fprintf(stderr, "usage: soak CITY.osgb [FRAMES] [WIDTHxHEIGHT]\n");
        return 2;
    }
    const long frames = argc > 2 ? std::atol(argv[2]) : 100000;
    int w = 64, h = 48;
    if (argc > 3 && std::sscanf(argv[3], "%dx%d", &w, &h) != 2) return 2;
    auto city = loadCityFile(argv[1]);
    if (!city) {
        std::fprintf(stderr, "soak: %s\n", city.status().message().c_str());
        return 2;
    }
    PathOptions po;
    po.duration = 120.0;
    auto path = generatePath(city->streets, city->params, po);
    if (!path || path->samples.empty()) return 2;
    auto renderer = OffscreenRenderer::create(w, h);
    if (!renderer) {
        std::fprintf(stderr, "soak: %s\n", renderer.status().message().c_str());
        return 1;
    }
    auto rays = RayScene::build(*city);
    if (!rays) return 1;
    ModeContext ctx;
    ctx.city = &*city;
    ctx.scene = sceneRoot(*city);
    ctx.renderer = renderer->get();
    ctx.rays = rays->get();
    ctx.options.effects = FrameEffects::fromScene(city->params.effects);
    auto mode = createRenderMode("hybrid", ctx);
    if (!mode) {
        std::fprintf(stderr, "soak: %s\n", mode.status().message().c_str());
        return 1;
    }
    Camera base;
    base.width = w;
    base.height = h;
    std::printf("frame,rss_mb,ms_per_frame\n");
    Image img;
    Stopwatch sw;
    double first = -1, last = 0;
    for (long f = 0; f < frames; ++f) {
        // Back and forth along the path, so the walk never jumps.
        const size_t n = path->samples.size(), k = size_t(f) % (2 * n - 2);
        const Camera cam = path->camera(k < n ? k : 2 * n - 2 - k, base);
        FrameStats st;
        if (Status s = (*mode)->renderFrame(cam, img, st); !s) {
            std::fprintf(stderr, "soak: frame %ld: %s\n", f, s.message().c_str());
            return 1;
        }
        if ((f + 1) % 1000 == 0 || f == 0) {
            last = rssMb();
            if (first < 0) first = last;
            std::printf("%ld,%.1f,%.3f\n", f + 1, last, f == 0 ? 0.0 : sw.lap() / 1000.0);
            std::fflush(stdout);
        }
    }
    std::printf("# rss first %.1f MB, last %.1f MB, growth %.1f MB (%.2f %%) over %ld frames\n", first, last,
                last - first, 100.0 * (last - first) / first, frames);
    return 0;
}
