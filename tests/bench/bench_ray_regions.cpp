// bench_ray_regions: the ray scene's two layouts side by side in one run:
// one flat scene against region scenes instanced into a top level
// (RaySceneOptions::regionSizeM). Per repetition (interleaved, flat first
// then regions, alternating): the build time, the primary rays of every
// pixel of N frames of a car path on one thread (castFrame, as the `raycast`
// mode casts them; Mrays/s), and adding then removing one region of the city
// (RayScene::addRegion + commit, removeRegion + commit) on the region layout.
// Prints medians over the repetitions and checks that both layouts hit the
// same number of pixels.
//
// Usage: bench_ray_regions CITY.osgb [--frames N] [--size WxH] [--reps R] [--seed S]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "foundation/statistics.h"
#include "foundation/timing.h"
#include "runtime/engine/frame_raycast.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/paths.h"

using namespace vista;

namespace {

int fail(const std::string& m) {
    std::fprintf(stderr, "bench_ray_regions: %s\n", m.c_str());
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) return fail("usage: bench_ray_regions CITY.osgb [--frames N] [--size WxH] [--reps R] [--seed S]");
    int frames = 8, width = 640, height = 480, reps = 5;
    uint64_t seed = 11;
    for (int i = 2; i + 1 < argc; i += 2) {
        const std::string k = argv[i];
        if (k == "--frames") frames = std::atoi(argv[i + 1]);
        else if (k == "--reps") reps = std::atoi(argv[i + 1]);
        else if (k == "--seed") seed = std::strtoull(argv[i + 1], nullptr, 10);
        else if (k == "--size") {
            if (std::sscanf(argv[i + 1], "%dx%d", &width, &height) != 2) return fail("--size: expected WxH");
        } else return fail("unknown option " + k);
    }
    if (frames < 1 || reps < 1 || width < 16 || height < 16) return fail("bad --frames, --reps or --size");
    auto city = loadCityFile(argv[1]);
    if (!city) return fail(city.status().message());
    PathOptions po;
    po.seed = seed;
    auto path = generatePath(city->streets, city->params, po);
    if (!path) return fail(path.status().message());
    Camera base;
    base.width = width;
    base.height = height;
    const std::vector<size_t> idx = path->spread(size_t(frames));
    // The region added and removed: the tiles within 500 m of the path's first eye.
    std::vector<uint32_t> tiles;
    const glm::dvec3 eye0 = path->camera(idx[0], base).eye;
    for (size_t t = 0; t < city->tiles.size(); ++t) {
        const SceneTile& tile = city->tiles[t];
        const double dx = std::max({tile.lo.x - eye0.x, 0.0, eye0.x - tile.hi.x});
        const double dy = std::max({tile.lo.y - eye0.y, 0.0, eye0.y - tile.hi.y});
        if (dx * dx + dy * dy < 500.0 * 500.0) tiles.push_back(uint32_t(t));
    }

    const char* names[] = {"flat", "regions"};
    std::vector<double> buildMs[2], mrays[2], addMs, removeMs;
    uint64_t hits[2] = {0, 0}, rays = 0;
    size_t triangles = 0;
    int regions = 0;
    for (int r = 0; r < reps; ++r)
        for (int k = 0; k < 2; ++k) {
            const int layout = (r % 2) ? 1 - k : k;  // alternate which layout goes first
            RaySceneOptions o;
            o.regionSizeM = layout == 0 ? 0.0 : RaySceneOptions().regionSizeM;
            Stopwatch sw;
            auto scene = RayScene::build(*city, o);
            if (!scene) return fail(scene.status().message());
            buildMs[layout].push_back(sw.ms());
            triangles = (*scene)->triangleCount();
            if (layout == 1) regions = (*scene)->regionCount();
            RayCounts counts;
            double castMs = 0;
            for (size_t f : idx) {
                const Camera c = path->camera(f, base);
                if (layout == 1) {
                    Status st = (*scene)->placeFrameNear(c.eye);
                    if (!st) return fail(st.message());
                }
                Image img;
                sw.restart();
                castFrame(**scene, c, img, counts, 1);
                castMs += sw.ms();
            }
            mrays[layout].push_back(double(counts.rays) / castMs / 1000.0);
            hits[layout] = counts.hits;
            rays = counts.rays;
            if (layout == 1 && !tiles.empty()) {
                sw.restart();
                auto id = (*scene)->addRegion(*city, tiles);
                if (!id) return fail(id.status().message());
                Status st = (*scene)->commit();
                if (!st) return fail(st.message());
                addMs.push_back(sw.ms());
                sw.restart();
                st = (*scene)->removeRegion(*id);
                if (st) st = (*scene)->commit();
                if (!st) return fail(st.message());
                removeMs.push_back(sw.ms());
            }
        }
    std::printf("city %s: %zu triangles, %d regions of %.0f m; %d frames of %dx%d (%llu rays a pass), %d reps\n",
                argv[1], triangles, regions, RaySceneOptions().regionSizeM, frames, width, height,
                (unsigned long long)rays, reps);
    std::printf("| layout | build (ms) | primary rays, one thread (Mrays/s) | pixels hit |\n|---|---|---|---|\n");
    for (int l = 0; l < 2; ++l)
        std::printf("| %s | %.0f | %.2f | %llu |\n", names[l], median(buildMs[l]), median(mrays[l]),
                    (unsigned long long)hits[l]);
    std::printf("add a region of %zu tiles + commit: %.1f ms; remove it + commit: %.1f ms (medians)\n", tiles.size(),
                median(addMs), median(removeMs));
    return 0;
}
