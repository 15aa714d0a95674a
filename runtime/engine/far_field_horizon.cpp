// Horizon stage (far_field_stages.h): pending pixels above the horizon row of
// their column become sky without a ray.
#include <algorithm>

#include <tbb/task_arena.h>

#include "foundation/timing.h"
#include "runtime/engine/far_field_stages.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

double culledRaysMs(const FarFrame& f, const RayScene& rays, const FarFieldOptions& o, uint64_t culled, size_t sample) {
    if (culled == 0 || sample == 0) return 0.0;
    const uint64_t step = std::max<uint64_t>(1, culled / sample);
    const uint32_t W = uint32_t(f.width);
    const glm::vec3 org(f.camera.eye - rays.frameOrigin());
    const glm::dvec3 fwd = f.camera.forward();
    const double zMax = o.effects.haze ? o.effects.hazeFar() : 0.0;
    std::vector<glm::vec3> orgs, dirs;
    std::vector<float> tfars;
    uint64_t k = 0;
    for (size_t i = 0; i < f.pixelCount && dirs.size() < sample; ++i)
        if (f.cls[i] == kFarHorizon && k++ % step == 0) {
            const glm::dvec3 d = f.rays.dir(int(i % W), int(i / W));
            orgs.push_back(org);
            dirs.push_back(glm::vec3(d));
            tfars.push_back(zMax > 0 ? hazeTfar(dirs.back(), glm::vec3(fwd), float(zMax)) : 1e30f);
        }
    std::vector<RayHit> hits(dirs.size());
    Stopwatch sw;
    rays.intersectMany(orgs.data(), dirs.data(), int(dirs.size()), hits.data(), 1e30f, tfars.data(), farRayStart(o));
    const double perRay = sw.ms() / double(dirs.size());
    const int workers = o.threads > 0 ? o.threads : std::max(1, tbb::this_task_arena::max_concurrency());
    return perRay * double(culled) / double(workers);
}

HorizonOptions horizonOptions(const FarFieldOptions& o, bool moving) {
    HorizonOptions ho;
    ho.nearDistance = o.nearIsDistance ? o.nearDistance : 0.0;
    ho.lift = o.movingHeight;
    ho.subsample = moving ? std::max(1, o.horizonSubsampleMoving) : 1;
    if (o.effects.haze) ho.maxEyeDepth = o.effects.hazeFar();  // nothing beyond is traced
    return ho;
}

uint64_t horizonStage(FarFrame& f, const HeightGrid* grid, const FarFieldOptions& o, FrameStats& stats,
                      std::future<HorizonResult>* early) {
    if (!grid) {
        stats.notes.push_back("horizon off: no height grid");
        return 0;
    }
    Stopwatch sw;
    HorizonResult hr;
    if (early && early->valid()) {
        hr = early->get();  // traced while the near field was drawn; the stage time is the wait
        stats.notes.push_back("horizon overlapped with the near field");
    } else {
        HorizonOptions ho = horizonOptions(o, f.moving);
        ho.columnNeeded = &f.columnNeeded;
        hr = traceHorizon(*grid, f.camera, ho);
    }
    if (!hr.active) {
        stats.notes.push_back(hr.reason);
        return 0;
    }
    // Row by row (contiguous in memory): pixel (x, y) is above the horizon when y < row[x]; it
    // gets the sky colour here, so no later pass over the frame is needed.
    const size_t W = size_t(f.width);
    std::vector<int> rows(W);
    int top = 0;
    for (size_t x = 0; x < W; ++x) {
        rows[x] = std::min(hr.row[x], f.height);
        top = std::max(top, rows[x]);
    }
    uint64_t culled = 0;
    for (int y = 0; y < top; ++y) {
        uint8_t* c = &f.cls[size_t(y) * W];
        uint8_t* px = &f.out.rgba[size_t(y) * W * 4];
        const uint8_t* sky = &f.sky->rgba[size_t(y) * W * 4];
        for (size_t x = 0; x < W; ++x)
            if (y < rows[x] && c[x] == kFarPending) {
                c[x] = kFarHorizon;
                std::copy_n(sky + x * 4, 4, px + x * 4);
                ++culled;
            }
    }
    stats.pixels.horizonCulled += culled;
    stats.stages.add(Stage::Horizon, sw.ms());
    return culled;
}

void cullAllPending(FarFrame& f, FrameStats& stats) {
    uint64_t sky = 0;
    for (size_t i = 0; i < f.pixelCount; ++i)
        if (f.cls[i] == kFarPending) {
            f.cls[i] = kFarHorizon;
            std::copy_n(&f.sky->rgba[i * 4], 4, &f.out.rgba[i * 4]);
            ++sky;
        }
    stats.pixels.horizonCulled += sky;
}

}  // namespace vista
