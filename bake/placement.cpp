// Impostor placement by cost (placement.h).
#include "bake/placement.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

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
    std::snprintf(buf, sizeof buf, "saves %.1f ms, costs %.1f ms (%.0f far pixels, %lld of %lld rays)", savedMs, costMs,
                  farPixels, (long long)farHits, (long long)rays);
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
    auto it = std::lower_bound(
        ends.begin(), ends.end(), std::make_pair(cell, end),
        [](const PlannedEnd& e, const std::pair<uint32_t, int>& k) { return std::make_pair(e.cell, int(e.end)) < k; });
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

PlacementEstimate estimatePlacement(const RayScene& cityRays, const TileLookup& tiles, const ViewCell& cell,
                                    const FarSet& fs, const SamplingParams& sampling, const PlacementParams& p) {
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
                    const glm::dvec3 dl(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw),
                                        std::sin(pitch));
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

constexpr double kVisClusterM = 4.0;  // grid of the point clusters of the image test (metres)

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

// The points grouped by a grid of `size` metres (scene-local): cluster c
// holds order[start[c] .. start[c + 1]) inside the box lo[c] .. hi[c].
struct PointClusters {
    std::vector<uint32_t> order, start;
    std::vector<glm::dvec3> lo, hi;
};

PointClusters clusterPoints(const std::vector<glm::vec3>& local, double size) {
    PointClusters pc;
    if (local.empty()) {
        pc.start.push_back(0);
        return pc;
    }
    glm::dvec3 mn(1e300);
    for (const glm::vec3& q : local) mn = glm::min(mn, glm::dvec3(q));
    std::vector<std::pair<uint64_t, uint32_t>> keyed(local.size());
    tbb::parallel_for(size_t(0), local.size(), [&](size_t i) {
        const glm::dvec3 g = glm::floor((glm::dvec3(local[i]) - mn) / size);
        const uint64_t x = uint64_t(std::min(g.x, 2097151.0)), y = uint64_t(std::min(g.y, 2097151.0)),
                       z = uint64_t(std::min(g.z, 2097151.0));
        keyed[i] = {(x << 42) | (y << 21) | z, uint32_t(i)};
    });
    tbb::parallel_sort(keyed.begin(), keyed.end());  // keys and indices unique together: one order
    pc.order.resize(keyed.size());
    for (size_t i = 0; i < keyed.size(); ++i) {
        pc.order[i] = keyed[i].second;
        if (i == 0 || keyed[i].first != keyed[i - 1].first) {
            pc.start.push_back(uint32_t(i));
            pc.lo.push_back(glm::dvec3(1e300));
            pc.hi.push_back(glm::dvec3(-1e300));
        }
        pc.lo.back() = glm::min(pc.lo.back(), glm::dvec3(local[keyed[i].second]));
        pc.hi.back() = glm::max(pc.hi.back(), glm::dvec3(local[keyed[i].second]));
    }
    pc.start.push_back(uint32_t(keyed.size()));
    return pc;
}

// A depth image with a pyramid of 2x2 maxima, for "the farthest first hit
// over a block of nodes" in a few lookups (conservative: a larger block).
struct MaxPyramid {
    std::vector<std::vector<float>> level;
    std::vector<int> w, h;
    explicit MaxPyramid(std::vector<float> base, int w0, int h0) {
        level.push_back(std::move(base));
        w.push_back(w0);
        h.push_back(h0);
        while (w.back() > 2 || h.back() > 2) {
            const int pw = w.back(), ph = h.back(), nw = (pw + 1) / 2, nh = (ph + 1) / 2;
            const std::vector<float>& src = level.back();
            std::vector<float> dst(size_t(nw) * size_t(nh));
            for (int j = 0; j < nh; ++j)
                for (int i = 0; i < nw; ++i) {
                    float m = -std::numeric_limits<float>::infinity();
                    for (int dj = 0; dj < 2; ++dj)
                        for (int di = 0; di < 2; ++di) {
                            const int x = std::min(2 * i + di, pw - 1), y = std::min(2 * j + dj, ph - 1);
                            m = std::max(m, src[size_t(y) * size_t(pw) + size_t(x)]);
                        }
                    dst[size_t(j) * size_t(nw) + size_t(i)] = m;
                }
            level.push_back(std::move(dst));
            w.push_back(nw);
            h.push_back(nh);
        }
    }
    float at(int i, int j) const { return level[0][size_t(j) * size_t(w[0]) + size_t(i)]; }
    // Max over nodes [i0, i1] x [j0, j1] of level 0 (or over a block containing them).
    float maxOver(int i0, int i1, int j0, int j1) const {
        size_t l = 0;
        while (l + 1 < level.size() && ((i1 >> l) - (i0 >> l) > 1 || (j1 >> l) - (j0 >> l) > 1)) ++l;
        float m = -std::numeric_limits<float>::infinity();
        for (int j = j0 >> l; j <= (j1 >> l); ++j)
            for (int i = i0 >> l; i <= (i1 >> l); ++i) m = std::max(m, level[l][size_t(j) * size_t(w[l]) + size_t(i)]);
        return m;
    }
};

// Depth-image prefilter from viewpoint v, looking at `target`: a planar
// depth image (first hits of the city, one ray per image node, `step`
// tangent units apart) over the clusters that still hold points not seen
// (todoOf[c] > 0). A point is a candidate (isCand = 1) when the farthest of
// the 4 nodes around its projection reaches it (openUntil): a point that the
// image says hidden is hidden at the image's pixel scale. A cluster whose
// nodes all end before its nearest point is skipped whole (the same verdict
// for each of its points, found at once). Clusters next to the viewpoint or
// more than maxTan off the axis make all their points candidates.
void imageCandidates(const RayScene& cityRays, const glm::dvec3& vd, const glm::dvec3& target,
                     const std::vector<glm::vec3>& local, const PointClusters& pc, const std::vector<uint32_t>& todoOf,
                     const std::vector<uint8_t>& vis, double step, int64_t maxRays, double maxTan,
                     std::vector<uint8_t>& isCand) {
    const glm::dvec3 axis = target - vd;
    const double al = glm::length(axis);
    const glm::dvec3 fwd = al > 1e-9 ? axis / al : glm::dvec3(1, 0, 0);
    const glm::dvec3 up0 = std::abs(fwd.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0);
    const glm::dvec3 right = glm::normalize(glm::cross(fwd, up0)), up = glm::cross(right, fwd);
    const size_t nc = pc.lo.size();
    // Per cluster: 0 = nothing to do, 1 = in the image, 2 = all candidates.
    std::vector<uint8_t> kind(nc, 0);
    std::vector<glm::dvec4> rect(nc);  // tangent-space bounds x0, x1, y0, y1
    std::vector<float> nearUntil(nc);
    struct Box {
        double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    };
    const Box box = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, nc, 256), Box(),
        [&](const tbb::blocked_range<size_t>& r, Box b) {
            for (size_t c = r.begin(); c < r.end(); ++c) {
                if (!todoOf[c]) continue;
                nearUntil[c] = openUntil(glm::length(glm::clamp(vd, pc.lo[c], pc.hi[c]) - vd));
                glm::dvec4 q(1e300, -1e300, 1e300, -1e300);
                bool ok = nearUntil[c] > 0.0f;
                for (int k = 0; k < 8 && ok; ++k) {
                    const glm::dvec3 corner((k & 1) ? pc.hi[c].x : pc.lo[c].x, (k & 2) ? pc.hi[c].y : pc.lo[c].y,
                                            (k & 4) ? pc.hi[c].z : pc.lo[c].z);
                    const glm::dvec3 d = corner - vd;
                    const double z = glm::dot(d, fwd);
                    if (!(z > 1e-3)) {
                        ok = false;
                        break;
                    }
                    const double x = glm::dot(d, right) / z, y = glm::dot(d, up) / z;
                    ok = std::abs(x) <= maxTan && std::abs(y) <= maxTan;
                    q = glm::dvec4(std::min(q.x, x), std::max(q.y, x), std::min(q.z, y), std::max(q.w, y));
                }
                kind[c] = ok ? 1 : 2;
                if (!ok) continue;
                rect[c] = q;
                b.x0 = std::min(b.x0, q.x);
                b.x1 = std::max(b.x1, q.y);
                b.y0 = std::min(b.y0, q.z);
                b.y1 = std::max(b.y1, q.w);
            }
            return b;
        },
        [](Box a, const Box& b) {
            a.x0 = std::min(a.x0, b.x0);
            a.x1 = std::max(a.x1, b.x1);
            a.y0 = std::min(a.y0, b.y0);
            a.y1 = std::max(a.y1, b.y1);
            return a;
        });
    if (!(box.x0 <= box.x1)) {  // no cluster in the image
        for (size_t c = 0; c < nc; ++c)
            if (kind[c] == 2)
                for (uint32_t k = pc.start[c]; k < pc.start[c + 1]; ++k) isCand[pc.order[k]] = !vis[pc.order[k]];
        return;
    }
    double w = std::floor((box.x1 - box.x0) / step) + 2,
           h = std::floor((box.y1 - box.y0) / step) + 2;  // nodes per axis
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
            depth[size_t(j) * m + size_t(i)] =
                hits[size_t(i)].hit ? hits[size_t(i)].t : std::numeric_limits<float>::infinity();
    });
    const MaxPyramid img(std::move(depth), nw, nh);
    auto node = [&](double t, double o, int n) { return std::clamp(int((t - o) / step), 0, n - 2); };
    tbb::parallel_for(size_t(0), nc, [&](size_t c) {
        if (!kind[c]) return;
        const uint32_t b = pc.start[c], e = pc.start[c + 1];
        if (kind[c] == 2) {
            for (uint32_t k = b; k < e; ++k) isCand[pc.order[k]] = !vis[pc.order[k]];
            return;
        }
        const int i0 = node(rect[c].x, box.x0, nw), i1 = node(rect[c].y, box.x0, nw) + 1;
        const int j0 = node(rect[c].z, box.y0, nh), j1 = node(rect[c].w, box.y0, nh) + 1;
        if (img.maxOver(i0, i1, j0, j1) < nearUntil[c]) return;  // every point of the cluster is hidden
        for (uint32_t k = b; k < e; ++k) {
            const uint32_t pi = pc.order[k];
            if (vis[pi]) continue;
            const glm::dvec3 d = glm::dvec3(local[pi]) - vd;
            const double z = glm::dot(d, fwd);
            const int i = node(glm::dot(d, right) / z, box.x0, nw), j = node(glm::dot(d, up) / z, box.y0, nh);
            const float reach =
                std::max(std::max(img.at(i, j), img.at(i + 1, j)), std::max(img.at(i, j + 1), img.at(i + 1, j + 1)));
            isCand[pi] = reach >= openUntil(glm::length(d)) ? 1 : 0;
        }
    });
}

}  // namespace

std::vector<uint8_t> visibleFromCell(const RayScene& cityRays, const ViewCell& cell, const ImpostorFrame& f,
                                     const std::vector<glm::vec3>& points, double pixelAngle,
                                     const PlacementParams& p) {
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
    PointClusters pc;
    std::vector<uint32_t> todoOf, clusterOf;  // per cluster: points not seen yet; per point: its cluster
    if (p.visByImage) {
        pc = clusterPoints(local, kVisClusterM);
        todoOf.resize(pc.lo.size());
        clusterOf.resize(points.size());
        for (size_t c = 0; c < todoOf.size(); ++c) {
            todoOf[c] = pc.start[c + 1] - pc.start[c];
            for (uint32_t k = pc.start[c]; k < pc.start[c + 1]; ++k) clusterOf[pc.order[k]] = uint32_t(c);
        }
    }
    std::vector<uint8_t> isCand(p.visByImage ? points.size() : 0, 0);
    // Per viewpoint, the points not seen yet.
    for (const glm::dvec3& vd : views) {
        if (todo.empty()) break;
        if (p.visByImage) {
            std::fill(isCand.begin(), isCand.end(), uint8_t(0));
            imageCandidates(cityRays, vd, centroid, local, pc, todoOf, vis, std::max(p.visStepPx, 0.05) * pixelAngle,
                            p.maxVisRaysPerView, p.visMaxTan, isCand);
            std::vector<uint32_t> cand;
            for (uint32_t i : todo)
                if (isCand[i]) cand.push_back(i);
            visibleByRays(cityRays, vd, local, cand, vis);
            for (uint32_t i : cand)
                if (vis[i]) --todoOf[clusterOf[i]];
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
