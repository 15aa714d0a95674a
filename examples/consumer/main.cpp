// vista_consumer: generates a small city with vista's citygen, writes it as a
// city file, loads it back as a SceneModel and casts rays into it with the
// engine's Embree ray scene: straight down over a grid (roofs, trees, ground)
// and horizontally at eye height from the city centre. Prints the counts;
// exits 1 when no ray hits anything, 2 on a library error.
//
// Usage: vista_consumer [size_m (default 300)] [seed (default 7)]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

#include "citygen/generate.h"
#include "citygen/params.h"
#include "foundation/units.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/city_file.h"

namespace {

int fail(const char* what, const vista::Status& s) {
    std::fprintf(stderr, "vista_consumer: %s: %s\n", what, s.message().c_str());
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    vista::CityParams params;
    params.size_m = argc > 1 ? std::atof(argv[1]) : 300.0;
    params.seed = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 7;
    params.detail = 1;
    if (vista::Status s = vista::validateParams(params); !s) return fail("params", s);
    if (vista::Status s = vista::checkSingleFileSize(params); !s) return fail("params", s);

    auto city = vista::generateCity(params);
    if (!city) return fail("generateCity", city.status());
    const vista::CityCounts counts = vista::countCity(*city);
    std::printf("city: %.0f m, seed %llu: %zu buildings, %zu trees, %zu tiles, %zu triangles\n", params.size_m,
                static_cast<unsigned long long>(params.seed), counts.buildings, counts.trees, city->tiles.size(),
                counts.triangles);

    const std::filesystem::path file =
        std::filesystem::temp_directory_path() / ("vista_consumer_" + std::to_string(getpid()) + ".osgb");
    if (vista::Status s = vista::writeCityFile(*city, file.string()); !s) return fail("writeCityFile", s);
    auto model = vista::loadCityFile(file.string());
    std::filesystem::remove(file);
    if (!model) return fail("loadCityFile", model.status());

    auto built = vista::RayScene::build(*model);
    if (!built) return fail("RayScene::build", built.status());
    const vista::RayScene& scene = *built.value();
    std::printf("ray scene: %zu triangles\n", scene.triangleCount());

    // Straight down from 1 km over a grid covering the inner half of the city
    // (scene-local frame: the origin is the city centre, z up).
    const int n = 16;
    const float half = static_cast<float>(params.size_m) * 0.25f;
    std::vector<glm::vec3> org, dir;
    for (int iy = 0; iy < n; ++iy)
        for (int ix = 0; ix < n; ++ix) {
            org.emplace_back(-half + 2 * half * (ix + 0.5f) / n, -half + 2 * half * (iy + 0.5f) / n, 1000.0f);
            dir.emplace_back(0.0f, 0.0f, -1.0f);
        }
    std::vector<vista::RayHit> hits(org.size());
    scene.intersectMany(org.data(), dir.data(), static_cast<int>(org.size()), hits.data());
    int downHits = 0;
    float highest = -1e30f;
    for (const vista::RayHit& h : hits)
        if (h.hit) {
            ++downHits;
            highest = std::max(highest, 1000.0f - h.t);
        }
    std::printf("down rays: %d of %zu hit (highest surface %.1f m)\n", downHits, hits.size(),
                downHits ? highest : 0.0f);

    // Horizontally at eye height (1.7 m over the surface below the centre), all around.
    int aroundHits = 0;
    const int around = 72;
    const vista::RayHit below = scene.intersect({0.0f, 0.0f, 1000.0f}, {0.0f, 0.0f, -1.0f});
    if (below.hit) {
        const glm::vec3 eye(0.0f, 0.0f, 1000.0f - below.t + 1.7f);
        double sum = 0;
        for (int i = 0; i < around; ++i) {
            const float a = static_cast<float>(vista::kTwoPi * i / around);
            const vista::RayHit h = scene.intersect(eye, {std::cos(a), std::sin(a), 0.0f});
            if (h.hit) {
                ++aroundHits;
                sum += h.t;
            }
        }
        std::printf("eye-height rays: %d of %d hit (mean distance %.1f m)\n", aroundHits, around,
                    aroundHits ? sum / aroundHits : 0.0);
    }

    if (downHits + aroundHits == 0) {
        std::fprintf(stderr, "vista_consumer: no ray hit the city\n");
        return 1;
    }
    return 0;
}
