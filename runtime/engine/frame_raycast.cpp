// The whole-frame raycast (frame_raycast.h).
#include "runtime/engine/frame_raycast.h"

#include <vector>

#include "foundation/status.h"

namespace vista {

void castFrame(const RayScene& scene, const Camera& camera, Image& out, RayCounts& counts, int threads,
               const RayShading& shading) {
    VISTA_CHECK(camera.width >= 1 && camera.height >= 1);
    if (out.width != camera.width || out.height != camera.height || !out.valid())
        out = Image(camera.width, camera.height);
    std::vector<size_t> runs(size_t(camera.height) + 1);
    for (size_t y = 0; y < runs.size(); ++y) runs[y] = y * size_t(camera.width);
    castPixelRuns(scene, camera, nullptr, runs, out, counts, threads, nullptr, shading);
}

}  // namespace vista
