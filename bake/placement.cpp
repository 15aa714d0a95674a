// Impostor placement by cost (placement.h).
#include "bake/placement.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace vista {

TileLookup TileLookup::build(const SceneModel& city, const std::vector<SceneTile>& tiles) {
    TileLookup t;
    t.meshTile.assign(city.meshes.size(), -1);
    t.instanceTile.assign(city.instances.size(), -1);
    for (const SceneTile& tile : tiles) {
        for (uint32_t m : tile.meshes)
            if (m < t.meshTile.size()) t.meshTile[m] = int32_t(tile.child);
        for (uint32_t i : tile.instances)
            if (i < t.instanceTile.size()) t.instanceTile[i] = int32_t(tile.child);
    }
    return t;
}

int32_t TileLookup::tileOf(const HitSource& s) const {
    if (s.mesh >= 0 && size_t(s.mesh) < meshTile.size()) return meshTile[size_t(s.mesh)];
    if (s.instance >= 0 && size_t(s.instance) < instanceTile.size()) return instanceTile[size_t(s.instance)];
    return -1;
}

std::string PlacementEstimate::describe() const {
    char buf[160];
    std::snprintf(buf, sizeof buf, "saves %.1f ms, costs %.1f ms (%.0f far pixels, %lld of %lld rays)", savedMs, costMs, farPixels,
                  (long long)farHits, (long long)rays);
    return buf;
}

PlacementEstimate estimatePlacement(const RayScene& cityRays, const TileLookup& tiles, const ViewCell& cell, const FarSet& fs,
                                    const SamplingParams& sampling, const PlacementParams& p) {
    PlacementEstimate e;
    const ImpostorFrame& f = fs.frame;
    glm::dvec3 lo(1e300), hi(-1e300);
    for (uint32_t idx : fs.soup.indices) {
        lo = glm::min(lo, glm::dvec3(fs.soup.positions[idx]));
        hi = glm::max(hi, glm::dvec3(fs.soup.positions[idx]));
    }
    e.savedMs = double(fs.soup.triangleCount()) * p.triangleNs * 1e-6;
    if (!(lo.x <= hi.x)) {
        e.place = false;
        return e;
    }
    const double pixelAngle = outputPixelAngle(sampling);
    const glm::dvec3 sceneOrigin = cityRays.frameOrigin();
    const ViewCellBox& b = cell.box;
    const int na = std::max(1, p.samplesAlong), nc = std::max(1, p.samplesAcross);
    double sumPixels = 0;
    for (int ia = 0; ia < na; ++ia) {
        for (int ic = 0; ic < nc; ++ic) {
            const double a = na == 1 ? 0.0 : (2.0 * (ia + 0.5) / na - 1.0) * b.halfLength;
            const double c = nc == 1 ? 0.0 : (2.0 * (ic + 0.5) / nc - 1.0) * b.halfWidth;
            const glm::dvec2 s2 = glm::dvec2(b.center) + b.axis * a + b.side() * c;
            const glm::dvec3 world(s2.x, s2.y, b.center.z);
            const glm::dvec3 s = f.toLocal(world);
            // Angular box of the far field's bounding box seen from s.
            double y0 = 1e300, y1 = -1e300, p0 = 1e300, p1 = -1e300;
            for (int k = 0; k < 8; ++k) {
                const glm::dvec3 q((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
                const glm::dvec3 d = q - s;
                const double dx = std::max(d.x, 1e-3);
                const double yaw = std::atan2(d.y, dx), pitch = std::atan2(d.z, std::hypot(dx, d.y));
                y0 = std::min(y0, yaw);
                y1 = std::max(y1, yaw);
                p0 = std::min(p0, pitch);
                p1 = std::max(p1, pitch);
            }
            double step = std::max(p.rayStepPx, 0.1) * pixelAngle;
            double ny = std::ceil((y1 - y0) / step), np = std::ceil((p1 - p0) / step);
            const double maxRays = std::max(p.maxRaysPerSample, 16);
            if (ny * np > maxRays) {
                const double grow = std::sqrt(ny * np / maxRays);
                step *= grow;
                ny = std::ceil((y1 - y0) / step);
                np = std::ceil((p1 - p0) / step);
            }
            const int iy = std::max(1, int(ny)), ip = std::max(1, int(np));
            const double sy = (y1 - y0) / iy, sp = (p1 - p0) / ip;
            const glm::vec3 org(world - sceneOrigin);
            double pixels = 0;
            for (int j = 0; j < ip; ++j) {
                const double pitch = p0 + (j + 0.5) * sp;
                for (int i = 0; i < iy; ++i) {
                    const double yaw = y0 + (i + 0.5) * sy;
                    const glm::dvec3 dl(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw), std::sin(pitch));
                    const glm::dvec3 dw = f.toWorld(dl) - f.origin;
                    const RayHit h = cityRays.intersect(org, glm::vec3(dw));
                    ++e.rays;
                    if (!h.hit) continue;
                    const int32_t t = tiles.tileOf(cityRays.source(h));
                    if (t < 0 || !std::binary_search(fs.tiles.begin(), fs.tiles.end(), uint32_t(t))) continue;
                    ++e.farHits;
                    pixels += std::cos(pitch) * sy * sp / (pixelAngle * pixelAngle);
                }
            }
            sumPixels += pixels;
            e.maxFarPixels = std::max(e.maxFarPixels, pixels);
        }
    }
    e.farPixels = sumPixels / double(na * nc);
    e.costMs = p.pointsPerFarPixel * e.farPixels * p.pointNs * 1e-6;
    e.place = e.savedMs > e.costMs;
    return e;
}

std::vector<uint8_t> visibleFromCell(const RayScene& cityRays, const ViewCell& cell, const ImpostorFrame& f,
                                     const std::vector<glm::vec3>& points, const PlacementParams& p) {
    std::vector<uint8_t> vis(points.size(), 0);
    const ViewCellBox& b = cell.box;
    const glm::dvec3 sceneOrigin = cityRays.frameOrigin();
    std::vector<glm::dvec3> views;  // scene-local
    const int na = std::max(1, p.visAlong), nc = std::max(1, p.visAcross), nh = std::max(1, p.visHeights);
    for (int ia = 0; ia < na; ++ia)
        for (int ic = 0; ic < nc; ++ic)
            for (int ih = 0; ih < nh; ++ih) {
                const double a = na == 1 ? 0.0 : (2.0 * ia / (na - 1) - 1.0) * b.halfLength * 0.98;
                const double c = nc == 1 ? 0.0 : (2.0 * ic / (nc - 1) - 1.0) * b.halfWidth * 0.98;
                const double h = nh == 1 ? 0.0 : (2.0 * ih / (nh - 1) - 1.0) * b.halfHeight * 0.98;
                const glm::dvec2 s2 = glm::dvec2(b.center) + b.axis * a + b.side() * c;
                views.push_back(glm::dvec3(s2.x, s2.y, b.center.z + h) - sceneOrigin);
            }
    // The centre first: most visible points are found by the first rays.
    std::stable_sort(views.begin(), views.end(), [&](const glm::dvec3& x, const glm::dvec3& y) {
        const glm::dvec3 c = b.center - sceneOrigin;
        return glm::length(x - c) < glm::length(y - c);
    });
    // Per viewpoint, the points not seen yet, in coherent packets (same
    // origin, neighbouring points): a miss before the point = visible.
    std::vector<glm::vec3> local(points.size());
    std::vector<uint32_t> todo(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
        local[i] = glm::vec3(f.toWorld(glm::dvec3(points[i])) - sceneOrigin);
        todo[i] = uint32_t(i);
    }
    for (const glm::dvec3& vd : views) {
        if (todo.empty()) break;
        const glm::vec3 v(vd);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, todo.size(), 512), [&](const tbb::blocked_range<size_t>& r) {
            const int n = int(r.end() - r.begin());
            const size_t count = size_t(n);
            std::vector<glm::vec3> org(count, v), dir(count);
            std::vector<float> tfar(count);
            std::vector<uint8_t> blocked(count);
            for (int k = 0; k < n; ++k) {
                const glm::dvec3 d = glm::dvec3(local[todo[r.begin() + size_t(k)]]) - vd;
                const double len = glm::length(d);
                dir[size_t(k)] = len > 1e-6 ? glm::vec3(d / len) : glm::vec3(0, 0, 1);
                tfar[size_t(k)] = float(len * (1.0 - 2e-3) - 0.1);  // < 0 for a point next to the viewpoint: a miss
            }
            cityRays.occludedMany(org.data(), dir.data(), n, tfar.data(), blocked.data(), 0.0f);
            for (int k = 0; k < n; ++k)
                if (!blocked[size_t(k)]) vis[todo[r.begin() + size_t(k)]] = 1;
        });
        std::vector<uint32_t> next;
        for (uint32_t i : todo)
            if (!vis[i]) next.push_back(i);
        todo.swap(next);
    }
    return vis;
}

}  // namespace vista
