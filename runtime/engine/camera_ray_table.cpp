// Per-pixel ray directions of a camera model (camera_ray_table.h).
#include "runtime/engine/camera_ray_table.h"

#include <algorithm>
#include <cmath>

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
        _tilesX = (int(w) + kTile - 1) / kTile, _tilesY = (int(h) + kTile - 1) / kTile;
        _tiles.assign(size_t(_tilesX) * size_t(_tilesY), TileCap{});
        tbb::parallel_for(0, _tilesY, [&](int ty) {
            for (int tx = 0; tx < _tilesX; ++tx) {
                const size_t u0 = size_t(tx * kTile), v0 = size_t(ty * kTile);
                const size_t u1 = std::min(w, u0 + kTile), v1 = std::min(h, v0 + kTile);
                glm::dvec3 sum(0.0);
                bool any = false;
                for (size_t v = v0; v < v1; ++v)
                    for (size_t u = u0; u < u1; ++u)
                        if (_inside[v * w + u]) sum += glm::normalize(_dir[v * w + u]), any = true;
                TileCap& t = _tiles[size_t(ty) * size_t(_tilesX) + size_t(tx)];
                t.anyInside = any;
                const double ls = glm::length(sum);
                if (!any || !(ls > 0.0)) continue;
                t.axis = sum / ls;
                double cosMin = 1.0;
                for (size_t v = v0; v < v1; ++v)
                    for (size_t u = u0; u < u1; ++u)
                        if (_inside[v * w + u])
                            cosMin = std::min(cosMin, glm::dot(t.axis, glm::normalize(_dir[v * w + u])));
                const double r = std::acos(std::clamp(cosMin, -1.0, 1.0)) + 1e-7;
                if (!(r < 1.5)) continue;
                t.cosR = std::cos(r), t.sinR = std::sin(r), t.hasCap = true;
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
