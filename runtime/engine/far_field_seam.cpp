// Seam-check stage (far_field_stages.h): covered pixels beyond the near
// distance re-cast against the far geometry the rasteriser never drew.
#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "foundation/timing.h"
#include "runtime/engine/far_field_stages.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

bool seamCheckApplies(const FarFrame& f, const RayScene& rays, const FarFieldOptions& o) {
    return f.depth && o.verifySeam && o.nearIsDistance && o.nearDistance > 0 && std::isfinite(o.nearDistance) &&
           rays.triangleCount() > 0;
}

float seamListDepth(const FarFrame& f, const FarFieldOptions& o) {
    // A pixel's distance is its eye depth times sqrt(1 + sx^2 + sy^2) <= kMax
    // (the corner pixels'), so no surface with eye depth <= nearDistance / kMax
    // reaches beyond the near distance. Its window depth (minus a margin for
    // float rounding) is one compare per pixel.
    const double n = f.camera.zNear, zf = o.depthZFar;
    const double sx = std::max(std::abs(f.rays.screenX(0)), std::abs(f.rays.screenX(f.width - 1)));
    const double sy = std::max(std::abs(f.rays.screenY(0)), std::abs(f.rays.screenY(f.height - 1)));
    const double kMax = std::sqrt(1.0 + sx * sx + sy * sy);
    const double zMin = o.nearDistance / kMax;
    if (zMin <= n) return -1.0f;
    // Window depth of eye depth z (inverse of eyeDepthOfWindowDepth).
    const double dMin = zf > 0 ? (zf / (zf - n)) * (1.0 - n / zMin) : 1.0 - n / zMin;
    return float(dMin - 1e-6);
}

void seamStage(FarFrame& f, const RayScene& rays, const FarFieldOptions& o, FrameStats& stats) {
    Stopwatch sw;
    const double n = f.camera.zNear, zf = o.depthZFar;
    const uint32_t W = uint32_t(f.width);
    // Covered pixels whose surface (window depth -> eye z -> distance along
    // the pixel's ray) lies beyond the near distance; tfar just before it.
    // The opacity stage listed the candidates (window depth >= seamListDepth).
    std::vector<uint32_t> check;
    std::vector<float> dist;
    std::vector<double> sx2(W), sy2(size_t(f.height));
    for (uint32_t x = 0; x < W; ++x) sx2[x] = f.rays.screenX(int(x)) * f.rays.screenX(int(x));
    for (int y = 0; y < f.height; ++y) sy2[size_t(y)] = f.rays.screenY(y) * f.rays.screenY(y);
    for (const uint32_t i : f.seamCandidates) {
        const uint32_t x = i % W, y = i / W;
        const double ze = eyeDepthOfWindowDepth(double(f.depth[i]), n, zf);
        const double t = ze * std::sqrt(1.0 + sx2[x] + sy2[y]);
        if (t > o.nearDistance) {
            check.push_back(i);
            dist.push_back(float(t * (1.0 - 1e-3)));
        }
    }
    if (!check.empty()) {
        const glm::vec3 org(f.camera.eye - rays.frameOrigin());
        // Nothing the near field left out lies nearer than the near distance: start there.
        const float tnear = farRayStart(o);
        // In fixed chunks of consecutive candidates (rows: coherent), cast in packets of 8 from
        // each chunk's start, so the packets never depend on the thread count.
        constexpr size_t kChunk = 256;
        std::vector<RayHit> res(check.size());
        const size_t chunks = (check.size() + kChunk - 1) / kChunk;
        inArena(o.threads, [&] {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks), [&](const tbb::blocked_range<size_t>& br) {
                std::vector<glm::vec3> orgs(kChunk, org), dirs(kChunk);
                for (size_t c = br.begin(); c != br.end(); ++c) {
                    const size_t b = c * kChunk, m = std::min(kChunk, check.size() - b);
                    for (size_t k = 0; k < m; ++k) {
                        const uint32_t i = check[b + k];
                        dirs[k] = glm::vec3(f.rays.dir(int(i % W), int(i / W)));
                    }
                    rays.intersectMany(orgs.data(), dirs.data(), int(m), &res[b], 1e30f, &dist[b], tnear);
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
            f.seamHits.emplace_back(i,
                                    f.fx->applyHaze(res[k].color, double(res[k].t) * glm::dot(d, f.camera.forward())));
            ++replaced;
        }
        f.covered -= replaced;
        stats.pixels.rayHit += replaced;
        stats.raysCast += check.size();
    }
    stats.stages.add(Stage::Seam, sw.ms());
}

void writeSeamHits(FarFrame& f) {
    const uint32_t W = uint32_t(f.width);
    for (const auto& [i, c] : f.seamHits) f.out.set(int(i % W), int(i / W), c);
    f.seamHits.clear();
}

}  // namespace vista
