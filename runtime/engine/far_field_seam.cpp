// Seam-check stage (far_field_stages.h): covered pixels beyond the near
// distance re-cast against the far geometry the rasteriser never drew.
#include <cmath>

#include <tbb/parallel_for.h>

#include "foundation/timing.h"
#include "runtime/engine/far_field_stages.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

bool seamCheckApplies(const FarFrame& f, const RayScene& rays, const FarFieldOptions& o) {
    return f.depth && f.covered > 0 && o.verifySeam && o.nearIsDistance && o.nearDistance > 0 && rays.triangleCount() > 0;
}

void seamStage(FarFrame& f, const RayScene& rays, const FarFieldOptions& o, FrameStats& stats) {
    Stopwatch sw;
    const double n = f.camera.zNear, zf = o.depthZFar;
    const uint32_t W = uint32_t(f.width);
    // Covered pixels whose surface (window depth -> eye z -> distance along
    // the pixel's ray) lies beyond the near distance; tfar just before it.
    std::vector<uint32_t> check;
    std::vector<float> dist;
    for (size_t i = 0; i < f.pixelCount; ++i) {
        if (f.cls[i] != kFarCovered) continue;
        const double ze = eyeDepthOfWindowDepth(double(f.depth[i]), n, zf);
        const double sx = f.rays.screenX(int(i % W)), sy = f.rays.screenY(int(i / W));
        const double t = ze * std::sqrt(1.0 + sx * sx + sy * sy);
        if (t > o.nearDistance) {
            check.push_back(uint32_t(i));
            dist.push_back(float(t * (1.0 - 1e-3)));
        }
    }
    if (!check.empty()) {
        const glm::vec3 org(f.camera.eye - rays.frameOrigin());
        std::vector<RayHit> res(check.size());
        inArena(o.threads, [&] {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, check.size(), 256), [&](const tbb::blocked_range<size_t>& br) {
                for (size_t k = br.begin(); k != br.end(); ++k) {
                    const uint32_t i = check[k];
                    res[k] = rays.intersect(org, glm::vec3(f.rays.dir(int(i % W), int(i / W))), 0.0f, dist[k]);
                }
            });
        });
        uint64_t replaced = 0;
        for (size_t k = 0; k < check.size(); ++k) {
            if (!res[k].hit) continue;
            const uint32_t i = check[k];
            f.cls[i] = kFarRayHit;
            // Eye-plane depth of the hit for haze (the seam lies within the near distance).
            const glm::dvec3 d = f.rays.dir(int(i % W), int(i / W));
            f.out.set(int(i % W), int(i / W), f.fx->applyHaze(res[k].color, double(res[k].t) * glm::dot(d, f.camera.forward())));
            ++replaced;
        }
        f.covered -= replaced;
        stats.pixels.rayHit += replaced;
        stats.raysCast += check.size();
    }
    stats.stages.add(Stage::Seam, sw.ms());
}

}  // namespace vista
