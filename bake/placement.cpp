// Impostor placement by cost (placement.h).
#include "bake/placement.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

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

double predictedMb(const PlacementEstimate& e, const PlacementParams& p) {
    return p.pointsPerFarPixel * e.farPixels * p.bytesPerPoint / (1024.0 * 1024.0);
}

std::string PlannedEnd::describe() const {
    char buf[120];
    if (!estimate.place) return "not placed: " + estimate.describe();
    std::snprintf(buf, sizeof buf, "; %.2f MB predicted, budget rank %d", predictedMb, rank + 1);
    return (inBudget ? "placed: " : "not placed (over the storage budget): ") + estimate.describe() + buf;
}

const PlannedEnd* PlacementPlan::find(uint32_t cell, int end) const {
    auto it = std::lower_bound(ends.begin(), ends.end(), std::make_pair(cell, end),
                               [](const PlannedEnd& e, const std::pair<uint32_t, int>& k) {
                                   return std::make_pair(e.cell, int(e.end)) < k;
                               });
    return it != ends.end() && it->cell == cell && int(it->end) == end ? &*it : nullptr;
}

PlacementPlan rankPlacement(std::vector<PlannedEnd> ends, double budgetMb) {
    PlacementPlan plan;
    plan.budgetMb = budgetMb;
    std::vector<size_t> order;
    for (size_t i = 0; i < ends.size(); ++i) {
        ends[i].rank = -1;
        ends[i].inBudget = false;
        if (ends[i].estimate.place) order.push_back(i);
    }
    auto value = [&](size_t i) {
        return (ends[i].estimate.savedMs - ends[i].estimate.costMs) / std::max(ends[i].predictedMb, 1e-6);
    };
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        const double va = value(a), vb = value(b);
        if (va != vb) return va > vb;
        return std::make_pair(ends[a].cell, ends[a].end) < std::make_pair(ends[b].cell, ends[b].end);
    });
    for (size_t r = 0; r < order.size(); ++r) {
        PlannedEnd& e = ends[order[r]];
        e.rank = int(r);
        plan.payingMb += e.predictedMb;
        if (plan.chosenMb + e.predictedMb <= budgetMb) {
            e.inBudget = true;
            plan.chosenMb += e.predictedMb;
            ++plan.chosen;
        }
    }
    plan.paying = order.size();
    std::sort(ends.begin(), ends.end(), [](const PlannedEnd& a, const PlannedEnd& b) {
        return std::make_pair(a.cell, a.end) < std::make_pair(b.cell, b.end);
    });
    plan.ends = std::move(ends);
    return plan;
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
            // One row of rays per pitch, cast as coherent packets.
            const size_t row = size_t(iy);
            std::vector<glm::vec3> orgs(row, org), dirs(row);
            std::vector<RayHit> hits(row);
            for (int j = 0; j < ip; ++j) {
                const double pitch = p0 + (j + 0.5) * sp;
                for (int i = 0; i < iy; ++i) {
                    const double yaw = y0 + (i + 0.5) * sy;
                    const glm::dvec3 dl(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw), std::sin(pitch));
                    dirs[size_t(i)] = glm::vec3(f.toWorld(dl) - f.origin);
                }
                cityRays.intersectMany(orgs.data(), dirs.data(), iy, hits.data());
                e.rays += iy;
                for (int i = 0; i < iy; ++i) {
                    const RayHit& h = hits[size_t(i)];
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

namespace {

// The viewpoints of visibleFromCell (scene-local), nearest to the cell centre first.
std::vector<glm::dvec3> cellViewpoints(const ViewCell& cell, const glm::dvec3& sceneOrigin, const PlacementParams& p) {
    const ViewCellBox& b = cell.box;
    std::vector<glm::dvec3> views;
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
    const glm::dvec3 c = b.center - sceneOrigin;
    std::stable_sort(views.begin(), views.end(),
                     [&](const glm::dvec3& x, const glm::dvec3& y) { return glm::length(x - c) < glm::length(y - c); });
    return views;
}

// Where the occlusion test ends: 0.1 m + 0.2 % short of a point at distance
// `len`, so that the point's own surface does not count (< 0: next to the viewpoint).
float openUntil(double len) { return float(len * (1.0 - 2e-3) - 0.1); }

// Exact test of the points `idx` from viewpoint v: one occlusion ray each
// (packets of 8); sets vis for those seen.
void visibleByRays(const RayScene& cityRays, const glm::dvec3& vd, const std::vector<glm::vec3>& local,
                   const std::vector<uint32_t>& idx, std::vector<uint8_t>& vis) {
    const glm::vec3 v(vd);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, idx.size(), 512), [&](const tbb::blocked_range<size_t>& r) {
        const int n = int(r.end() - r.begin());
        const size_t count = size_t(n);
        std::vector<glm::vec3> org(count, v), dir(count);
        std::vector<float> tfar(count);
        std::vector<uint8_t> blocked(count);
        for (int k = 0; k < n; ++k) {
            const glm::dvec3 d = glm::dvec3(local[idx[r.begin() + size_t(k)]]) - vd;
            const double len = glm::length(d);
            dir[size_t(k)] = len > 1e-6 ? glm::vec3(d / len) : glm::vec3(0, 0, 1);
            tfar[size_t(k)] = openUntil(len);
        }
        cityRays.occludedMany(org.data(), dir.data(), n, tfar.data(), blocked.data(), 0.0f);
        for (int k = 0; k < n; ++k)
            if (!blocked[size_t(k)]) vis[idx[r.begin() + size_t(k)]] = 1;
    });
}

// Depth-image prefilter of the points `idx` from viewpoint v, looking at
// `target`: a planar depth image (first hits of the city, one ray per image
// node, `step` tangent units apart) over the points' projections. A point is
// a candidate (appended to `cand`, in idx order) when the farthest of the 4
// nodes around its projection reaches it (openUntil): a point that the image
// says hidden is hidden at the image's pixel scale. Points more than maxTan
// off the axis, or within reach of the viewpoint, are candidates too.
void imageCandidates(const RayScene& cityRays, const glm::dvec3& vd, const glm::dvec3& target, const std::vector<glm::vec3>& local,
                     const std::vector<uint32_t>& idx, double step, int64_t maxRays, double maxTan, std::vector<uint32_t>& cand) {
    const glm::dvec3 axis = target - vd;
    const double al = glm::length(axis);
    const glm::dvec3 fwd = al > 1e-9 ? axis / al : glm::dvec3(1, 0, 0);
    const glm::dvec3 up0 = std::abs(fwd.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0);
    const glm::dvec3 right = glm::normalize(glm::cross(fwd, up0)), up = glm::cross(right, fwd);
    const size_t n = idx.size();
    std::vector<glm::vec2> tan(n);
    std::vector<float> until(n);
    std::vector<uint8_t> kind(n);  // 0: in the image, 1: candidate without the image
    struct Box {
        double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
        void join(const Box& o) { x0 = std::min(x0, o.x0); x1 = std::max(x1, o.x1); y0 = std::min(y0, o.y0); y1 = std::max(y1, o.y1); }
    };
    const Box box = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, n, 4096), Box(),
        [&](const tbb::blocked_range<size_t>& r, Box b) {
            for (size_t k = r.begin(); k < r.end(); ++k) {
                const glm::dvec3 d = glm::dvec3(local[idx[k]]) - vd;
                const double z = glm::dot(d, fwd);
                until[k] = openUntil(glm::length(d));
                const glm::dvec2 t = z > 0 ? glm::dvec2(glm::dot(d, right), glm::dot(d, up)) / z : glm::dvec2(1e300);
                kind[k] = until[k] <= 0.0f || !(std::abs(t.x) <= maxTan && std::abs(t.y) <= maxTan) ? 1 : 0;
                if (kind[k]) continue;
                tan[k] = glm::vec2(t);
                b.x0 = std::min(b.x0, double(tan[k].x)); b.x1 = std::max(b.x1, double(tan[k].x));
                b.y0 = std::min(b.y0, double(tan[k].y)); b.y1 = std::max(b.y1, double(tan[k].y));
            }
            return b;
        },
        [](Box a, const Box& b) { a.join(b); return a; });
    std::vector<uint8_t> keep(kind);
    if (box.x0 <= box.x1) {
        double w = std::floor((box.x1 - box.x0) / step) + 2, h = std::floor((box.y1 - box.y0) / step) + 2;  // nodes per axis
        const double cap = double(std::max<int64_t>(maxRays, 16));
        if (w * h > cap) {
            step *= std::sqrt(w * h / cap);
            w = std::floor((box.x1 - box.x0) / step) + 2;
            h = std::floor((box.y1 - box.y0) / step) + 2;
        }
        const int nw = int(w), nh = int(h);
        std::vector<float> depth(size_t(nw) * size_t(nh));
        const glm::vec3 v(vd);
        tbb::parallel_for(0, nh, [&](int j) {
            const size_t m = size_t(nw);
            std::vector<glm::vec3> org(m, v), dir(m);
            std::vector<RayHit> hits(m);
            for (int i = 0; i < nw; ++i)
                dir[size_t(i)] = glm::vec3(glm::normalize(fwd + (box.x0 + i * step) * right + (box.y0 + j * step) * up));
            cityRays.intersectMany(org.data(), dir.data(), nw, hits.data());
            for (int i = 0; i < nw; ++i)
                depth[size_t(j) * m + size_t(i)] = hits[size_t(i)].hit ? hits[size_t(i)].t : std::numeric_limits<float>::infinity();
        });
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t k = r.begin(); k < r.end(); ++k) {
                if (kind[k]) continue;
                const int i = std::clamp(int((double(tan[k].x) - box.x0) / step), 0, nw - 2);
                const int j = std::clamp(int((double(tan[k].y) - box.y0) / step), 0, nh - 2);
                const size_t a = size_t(j) * size_t(nw) + size_t(i), b = a + size_t(nw);
                const float reach = std::max(std::max(depth[a], depth[a + 1]), std::max(depth[b], depth[b + 1]));
                keep[k] = reach >= until[k] ? 1 : 0;
            }
        });
    }
    for (size_t k = 0; k < n; ++k)
        if (keep[k]) cand.push_back(idx[k]);
}

}  // namespace

std::vector<uint8_t> visibleFromCell(const RayScene& cityRays, const ViewCell& cell, const ImpostorFrame& f,
                                     const std::vector<glm::vec3>& points, double pixelAngle, const PlacementParams& p) {
    std::vector<uint8_t> vis(points.size(), 0);
    const glm::dvec3 sceneOrigin = cityRays.frameOrigin();
    const std::vector<glm::dvec3> views = cellViewpoints(cell, sceneOrigin, p);
    std::vector<glm::vec3> local(points.size());
    std::vector<uint32_t> todo(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
        local[i] = glm::vec3(f.toWorld(glm::dvec3(points[i])) - sceneOrigin);
        todo[i] = uint32_t(i);
    }
    // The image axis: from each viewpoint to the points' centroid.
    glm::dvec3 centroid(0.0);
    for (const glm::vec3& q : local) centroid += glm::dvec3(q);
    if (!local.empty()) centroid /= double(local.size());
    // Per viewpoint, the points not seen yet.
    for (const glm::dvec3& vd : views) {
        if (todo.empty()) break;
        if (p.visByImage) {
            std::vector<uint32_t> cand;
            imageCandidates(cityRays, vd, centroid, local, todo, std::max(p.visStepPx, 0.05) * pixelAngle, p.maxVisRaysPerView,
                            p.visMaxTan, cand);
            visibleByRays(cityRays, vd, local, cand, vis);
        } else {
            visibleByRays(cityRays, vd, local, todo, vis);
        }
        std::vector<uint32_t> next;
        for (uint32_t i : todo)
            if (!vis[i]) next.push_back(i);
        todo.swap(next);
    }
    return vis;
}

}  // namespace vista
