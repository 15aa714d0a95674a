// Per-pixel ray directions of a camera model (camera_ray_table.h).
#include "runtime/engine/camera_ray_table.h"

#include <tbb/parallel_for.h>

#include "runtime/engine/far_field_stages.h"

namespace vista {

CameraRayTable::CameraRayTable(const CameraModel& model, int threads) : _model(model) {
    const size_t w = size_t(model.width), h = size_t(model.height);
    _dir.assign(w * h, glm::dvec3(0.0));
    _inside.assign(w * h, 0);
    inArena(threads, [&] {
        tbb::parallel_for(size_t(0), h, [&](size_t v) {
            for (size_t u = 0; u < w; ++u) {
                glm::dvec3 d(0.0);
                const bool in = _model.pixelRay(double(u), double(v), d);
                _dir[v * w + u] = in ? d : glm::dvec3(0.0);
                _inside[v * w + u] = in ? 1 : 0;
            }
        });
    });
}

bool CameraRayTable::matches(const CameraModel& m) const {
    return !_dir.empty() && m.kind == _model.kind && m.width == _model.width && m.height == _model.height &&
           m.fx == _model.fx && m.fy == _model.fy && m.cx == _model.cx && m.cy == _model.cy &&
           (!m.fisheye() || m.maxFovDeg == _model.maxFovDeg);
}

}  // namespace vista
