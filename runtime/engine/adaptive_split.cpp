// Near/far split selection and the adaptive near distance (see adaptive_split.h).
#include "runtime/engine/adaptive_split.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <thread>
#include <tuple>

#include "foundation/status.h"
#include "foundation/timing.h"
#include "runtime/engine/far_field_rays.h"
#include "runtime/engine/ray_scene.h"

namespace vista {
namespace {

// Slope of y = c + slope * x over the samples, robust to outliers (a frame
// slowed down by another process on the machine): the Theil-Sen estimator,
// the median of the slopes between pairs whose x differ by more than 5 % of
// the mean x. nullopt unless there are 5 or more samples, x varies by more
// than 10 % of its mean and 5 or more pairs qualify.
std::optional<double> fitSlope(const std::vector<std::pair<double, double>>& samples) {
    const double n = double(samples.size());
    if (n < 5) return std::nullopt;
    double sx = 0, sxx = 0;
    for (const auto& [x, y] : samples) {
        sx += x;
        sxx += x * x;
    }
    const double var = sxx / n - (sx / n) * (sx / n), mean = sx / n;
    if (!(var > 0) || std::sqrt(var) <= 0.1 * std::max(mean, 1.0)) return std::nullopt;
    const double minDx = 0.05 * std::max(mean, 1.0);
    std::vector<double> slopes;
    slopes.reserve(samples.size() * (samples.size() - 1) / 2);
    for (size_t i = 0; i < samples.size(); ++i)
        for (size_t j = i + 1; j < samples.size(); ++j) {
            const double dx = samples[j].first - samples[i].first;
            if (std::abs(dx) > minDx) slopes.push_back((samples[j].second - samples[i].second) / dx);
        }
    if (slopes.size() < 5) return std::nullopt;
    const auto mid = slopes.begin() + long(slopes.size() / 2);
    std::nth_element(slopes.begin(), mid, slopes.end());
    return *mid;
}

// The four side planes of a camera's view (through the eye, normals inward): a box
// wholly outside one of them is culled by the renderer and costs no raster time.
struct ViewSides {
    explicit ViewSides(const Camera& c) : eye(c.eye) {
        const double ty = std::tan(0.5 * c.fovY), tx = ty * double(c.width) / double(std::max(1, c.height));
        const glm::dvec3 f = c.forward(), r = c.right(), u = c.up();
        n[0] = tx * f - r;
        n[1] = tx * f + r;
        n[2] = ty * f - u;
        n[3] = ty * f + u;
    }
    bool sees(const SplitObject& o) const {
        for (const glm::dvec3& m : n) {
            // The box corner farthest along m.
            const glm::dvec3 c(m.x > 0 ? o.hi.x : o.lo.x, m.y > 0 ? o.hi.y : o.lo.y, m.z > 0 ? o.hi.z : o.lo.z);
            if (glm::dot(m, c - eye) < 0) return false;
        }
        return true;
    }
    glm::dvec3 eye;
    glm::dvec3 n[4];
};

// Objects up to this count are tested against the view for the price of
// rasterising everything (at each probe); beyond it, every triangle counts.
constexpr size_t kEverythingViewTestObjects = 200000;

// A kind of choice never run is tried from this frame on, when its price is within this factor of
// the best (AdaptiveSplit::choose).
constexpr int kFirstTryFrame = 3;
constexpr double kFirstTryRatio = 1.5;

// The probe's far-ray timing casts at most this many of its rays again.
constexpr size_t kProbeFarTimed = 500;
// The probe's share of a frame's time (its rays fewer on cheap frames), and its fewest rays.
constexpr double kProbeFrameShare = 0.025;
constexpr double kProbeMinRays = 300;

// Frames of a kind its correction is the lower quartile over: enough that frames slowed by other
// work on the machine do not move it, few enough that it follows the path.
constexpr size_t kKindWindow = 8;

// Read once: std::thread::hardware_concurrency() reads a file of the system on every call
// (about 6 us here), and the split prices ray casting with it several times a frame.
double coreCount() {
    static const double n = double(std::max(1u, std::thread::hardware_concurrency()));
    return n;
}

void pushWindow(std::vector<std::pair<double, double>>& w, std::pair<double, double> s, int window) {
    w.push_back(s);
    if (int(w.size()) > std::max(2, window)) w.erase(w.begin());
}

// A middle candidate is corrected by the frames that drew and traced about what it does: those
// of the middle's last counted frames nearest to its triangles in view and far pixels (the
// larger of the two log ratios, within a factor 1.1 of the nearest; a distance that ran finds
// its own frames). One offset for every middle distance (the lower quartile of frames at
// several distances) would price the distance the model favours most below what any middle
// frame costs wherever the model's slope over the distance is wrong (far rays that do not fall
// with the near distance as the probe predicts on a fly-over, a raster that costs by the
// fragment as much as by the triangle): that distance would keep winning at a cost above ray
// casting's.
// `frames` are the middle kind's last counted frames; `price(frame)` is the model's price of one.
template <class Frames, class Price>
double nearestFramesCorrection(const Frames& frames, uint64_t tris, double rays, Price price) {
    if (frames.empty()) return 0.0;
    auto gap = [&](const auto& k) {
        return std::max(std::abs(std::log((k.tris + 1.0) / (double(tris) + 1.0))),
                        std::abs(std::log((k.rays + 1.0) / (rays + 1.0))));
    };
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& k : frames) nearest = std::min(nearest, gap(k));
    std::vector<double> r;
    for (const auto& k : frames)
        if (gap(k) <= nearest + std::log(1.1)) r.push_back(k.frameMs - price(k));
    const size_t q = (r.size() - 1) / 4;
    std::nth_element(r.begin(), r.begin() + long(q), r.end());
    return r[q];
}
}  // namespace

double boxDistance(const SplitObject& o, const glm::dvec3& p) {
    glm::dvec3 d = glm::max(glm::max(o.lo - p, p - o.hi), glm::dvec3(0.0));
    return glm::length(d);
}

int AdaptiveSplit::kindOf(double d) const {
    if (d <= 0) return 0;
    if (std::isinf(d)) return 2;
    return _o.fixedDistance > 0 && d == _o.fixedDistance ? 3 : 1;
}

std::vector<uint32_t> selectNearField(const std::vector<SplitObject>& objects, const glm::dvec3& eye,
                                      double nearDistance) {
    std::vector<uint32_t> out;
    for (uint32_t i = 0; i < objects.size(); ++i)
        if (boxDistance(objects[i], eye) <= nearDistance) out.push_back(i);
    return out;
}

std::shared_ptr<const SplitIndex::Block> SplitIndex::makeBlock(const SplitObject* objects, size_t count, double cell) {
    auto out = std::make_shared<Block>();
    Block& b = *out;
    b.cell = cell > 0 ? cell : 64.0;
    b.count = uint32_t(count);
    double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
    b.lo = glm::dvec2(x0);
    b.hi = glm::dvec2(-x0);
    for (size_t i = 0; i < count; ++i) {
        const SplitObject& o = objects[i];
        b.triangles += o.triangles;
        x0 = std::min(x0, o.lo.x);
        y0 = std::min(y0, o.lo.y);
        x1 = std::max(x1, o.lo.x);
        y1 = std::max(y1, o.lo.y);
        b.lo = glm::min(b.lo, glm::dvec2(o.lo));
        b.hi = glm::max(b.hi, glm::dvec2(o.hi));
    }
    if (count == 0 || !std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) || !std::isfinite(y1)) {
        for (uint32_t i = 0; i < count; ++i) b.wide.push_back(i);
        b.lo = glm::dvec2(-std::numeric_limits<double>::infinity());  // visited by every query
        b.hi = glm::dvec2(std::numeric_limits<double>::infinity());
        return out;
    }
    b.x0 = x0;
    b.y0 = y0;
    // At most 4096 cells a side (a 262 km city at 64 m); beyond, cells grow.
    b.cell = std::max(b.cell, std::max(x1 - x0, y1 - y0) / 4095.0);
    b.nx = int((x1 - x0) / b.cell) + 1;
    b.ny = int((y1 - y0) / b.cell) + 1;
    std::vector<int64_t> cellOf(count, -1);
    b.start.assign(size_t(b.nx) * size_t(b.ny) + 1, 0);
    for (uint32_t i = 0; i < count; ++i) {
        const SplitObject& o = objects[i];
        if (!(o.hi.x - o.lo.x <= b.cell) || !(o.hi.y - o.lo.y <= b.cell)) {
            b.wide.push_back(i);
            continue;
        }
        const int cx = std::clamp(int((o.lo.x - b.x0) / b.cell), 0, b.nx - 1),
                  cy = std::clamp(int((o.lo.y - b.y0) / b.cell), 0, b.ny - 1);
        cellOf[i] = int64_t(cy) * b.nx + cx;
        ++b.start[size_t(cellOf[i]) + 1];
    }
    for (size_t c = 1; c < b.start.size(); ++c) b.start[c] += b.start[c - 1];
    b.items.resize(b.start.back());
    std::vector<uint32_t> fill(b.start.begin(), b.start.end() - 1);
    for (uint32_t i = 0; i < count; ++i)
        if (cellOf[i] >= 0) b.items[fill[size_t(cellOf[i])]++] = i;  // ascending within a cell
    return out;
}

SplitIndex::SplitIndex(const std::vector<SplitObject>& objects, double cell) : _objects(objects) {
    auto b = makeBlock(objects.data(), objects.size(), cell);
    _total = b->triangles;
    _count = b->count;
    _blocks[0] = {0, std::move(b)};
}

SplitIndex::SplitIndex(const std::vector<SplitObject>& objects, double blockCell, std::nullptr_t)
    : _objects(objects), _blockCell(blockCell) {
    VISTA_CHECK(blockCell > 0 && std::isfinite(blockCell));
}

namespace {

// One key per (cx, cy) block cell (wraps only beyond 2^31 cells a side).
int64_t cellKey(int64_t cx, int64_t cy) { return int64_t((uint64_t(cy) << 32) ^ uint64_t(uint32_t(cx))); }

}  // namespace

int64_t SplitIndex::blockCellOf(const Block& b) const {
    if (!std::isfinite(b.lo.x) || !std::isfinite(b.lo.y)) return std::numeric_limits<int64_t>::min();
    const int64_t cx = int64_t(std::floor(b.lo.x / _blockCell)), cy = int64_t(std::floor(b.lo.y / _blockCell));
    return cellKey(cx, cy);
}

void SplitIndex::addBlock(uint64_t key, uint32_t first, std::shared_ptr<const Block> block) {
    VISTA_CHECK(_blockCell > 0 && block && _blocks.count(key) == 0);
    VISTA_CHECK(size_t(first) + block->count <= _objects.size());
    _total += block->triangles;
    _count += block->count;
    if (std::isfinite(block->lo.x) && std::isfinite(block->hi.x) && block->hi.x >= block->lo.x)
        _maxExtent = std::max({_maxExtent, block->hi.x - block->lo.x, block->hi.y - block->lo.y});
    _blockCells[blockCellOf(*block)].push_back(key);
    _blocks[key] = {first, std::move(block)};
}

void SplitIndex::removeBlock(uint64_t key) {
    auto it = _blocks.find(key);
    if (it == _blocks.end()) return;
    const Block& b = *it->second.block;
    _total -= b.triangles;
    _count -= b.count;
    if (_blockCell > 0) {
        auto cell = _blockCells.find(blockCellOf(b));
        if (cell != _blockCells.end()) {
            auto& keys = cell->second;
            keys.erase(std::remove(keys.begin(), keys.end(), key), keys.end());
            if (keys.empty()) _blockCells.erase(cell);
        }
    }
    _blocks.erase(it);
}

template <class F>
void SplitIndex::visit(const glm::dvec3& p, double d, F&& f, VisitCost* cost) const {
    const bool everything = !(d < 1e15) || !std::isfinite(p.x) || !std::isfinite(p.y);
    auto visitBlock = [&](uint64_t key, const Entry& e) {
        const Block& b = *e.block;
        if (cost) ++cost->blocks;
        // The block's boxes all lie farther than d (2D distance to its bounds): nothing to visit.
        if (!everything) {
            const double dx = std::max({b.lo.x - p.x, 0.0, p.x - b.hi.x}),
                         dy = std::max({b.lo.y - p.y, 0.0, p.y - b.hi.y});
            if (dx * dx + dy * dy > d * d) return;
        }
        const uint32_t base = e.first;
        auto g = [&](uint32_t local) {
            if (cost) ++cost->objects;
            f(key, base + local);
        };
        for (uint32_t i : b.wide) g(i);
        if (b.nx == 0) return;
        if (everything) {  // +inf or huge reach, or a NaN eye: every object (boxDistance decides)
            for (uint32_t i : b.items) g(i);
            return;
        }
        // A small object (extent <= cell) within d of p has its low corner in [p - d - cell, p + d].
        auto cellOf = [&](double v, int n) { return int(std::clamp(std::floor(v / b.cell), -1.0, double(n))); };
        const int cx0 = std::max(0, cellOf(p.x - d - b.cell - b.x0, b.nx)),
                  cy0 = std::max(0, cellOf(p.y - d - b.cell - b.y0, b.ny));
        const int cx1 = std::min(b.nx - 1, cellOf(p.x + d - b.x0, b.nx)),
                  cy1 = std::min(b.ny - 1, cellOf(p.y + d - b.y0, b.ny));
        for (int cy = cy0; cy <= cy1; ++cy) {
            const size_t row = size_t(cy) * size_t(b.nx);
            for (uint32_t k = b.start[row + size_t(cx0)]; cx0 <= cx1 && k < b.start[row + size_t(cx1) + 1]; ++k)
                g(b.items[k]);
        }
    };
    // A static index, a query of everything, or a reach wider than the blocks: every block.
    const double reach = everything ? 0.0 : (2.0 * d + _maxExtent) / std::max(_blockCell, 1e-9) + 2.0;
    if (_blockCell <= 0 || everything || reach * reach >= double(_blocks.size())) {
        for (const auto& [key, e] : _blocks) visitBlock(key, e);
        return;
    }
    // The blocks whose low corner lies in [p - d - widest block, p + d], and those without bounds.
    auto cellOf = [&](double v) { return int64_t(std::floor(v / _blockCell)); };
    const int64_t cx0 = cellOf(p.x - d - _maxExtent), cx1 = cellOf(p.x + d);
    const int64_t cy0 = cellOf(p.y - d - _maxExtent), cy1 = cellOf(p.y + d);
    auto visitCell = [&](int64_t c) {
        auto it = _blockCells.find(c);
        if (it == _blockCells.end()) return;
        for (uint64_t key : it->second) visitBlock(key, _blocks.at(key));
    };
    visitCell(std::numeric_limits<int64_t>::min());
    for (int64_t cy = cy0; cy <= cy1; ++cy)
        for (int64_t cx = cx0; cx <= cx1; ++cx) visitCell(cellKey(cx, cy));
}

std::vector<uint32_t> SplitIndex::within(const glm::dvec3& p, double d) const {
    std::vector<std::pair<uint64_t, uint32_t>> hits;
    visit(p, d, [&](uint64_t key, uint32_t i) {
        if (boxDistance(_objects[i], p) <= d) hits.push_back({key, i});
    });
    std::sort(hits.begin(), hits.end());
    std::vector<uint32_t> out(hits.size());
    for (size_t k = 0; k < hits.size(); ++k) out[k] = hits[k].second;
    return out;
}

void SplitIndex::distances(const glm::dvec3& p, double d, std::vector<std::pair<double, uint64_t>>& out) const {
    out.clear();
    visit(p, d, [&](uint64_t, uint32_t i) {
        const double t = boxDistance(_objects[i], p);
        if (t <= d) out.push_back({t, _objects[i].triangles});
    });
}

SplitIndex::VisitCost SplitIndex::cost(const glm::dvec3& p, double d) const {
    VisitCost c;
    visit(
        p, d, [](uint64_t, uint32_t) {}, &c);
    return c;
}

std::vector<uint32_t> selectNearField(const SplitIndex& index, const glm::dvec3& eye, double nearDistance) {
    return index.within(eye, nearDistance);
}

std::vector<uint32_t> selectNearFieldByBudget(const std::vector<SplitObject>& objects, const glm::dvec3& eye,
                                              uint64_t budget) {
    std::vector<std::pair<double, uint32_t>> byDist;
    byDist.reserve(objects.size());
    for (uint32_t i = 0; i < objects.size(); ++i) byDist.push_back({boxDistance(objects[i], eye), i});
    std::sort(byDist.begin(), byDist.end());
    std::vector<uint32_t> out;
    uint64_t sum = 0;
    for (const auto& [d, i] : byDist) {
        if (!out.empty() && sum + objects[i].triangles > budget) break;
        sum += objects[i].triangles;
        out.push_back(i);
    }
    std::sort(out.begin(), out.end());
    return out;
}

std::vector<uint32_t> selectNearFieldByBudget(const SplitIndex& index, const glm::dvec3& eye, uint64_t budget) {
    // (distance, block key, index) of every object within the reach; the reach doubles until
    // the objects in it hold more than the budget (then the nearest ones within it are exactly
    // the nearest ones of all) or it holds every object.
    std::vector<std::tuple<double, uint64_t, uint32_t>> byDist;
    for (double reach = 64.0;; reach *= 2.0) {
        if (reach > 1e14) reach = std::numeric_limits<double>::infinity();
        byDist.clear();
        uint64_t sum = 0;
        index.visitKeyed(eye, reach, [&](uint64_t key, uint32_t i, double t) {
            byDist.push_back({t, key, i});
            sum += index.objects()[i].triangles;
        });
        if (sum > budget || byDist.size() >= index.size() || std::isinf(reach)) break;
    }
    std::sort(byDist.begin(), byDist.end(), [](const auto& a, const auto& b) {
        return std::get<0>(a) != std::get<0>(b) ? std::get<0>(a) < std::get<0>(b) : std::get<2>(a) < std::get<2>(b);
    });
    std::vector<std::pair<uint64_t, uint32_t>> picked;
    uint64_t sum = 0;
    for (const auto& [t, key, i] : byDist) {
        const uint64_t tris = index.objects()[i].triangles;
        if (!picked.empty() && sum + tris > budget) break;
        sum += tris;
        picked.push_back({key, i});
    }
    std::sort(picked.begin(), picked.end());
    std::vector<uint32_t> out(picked.size());
    for (size_t k = 0; k < picked.size(); ++k) out[k] = picked[k].second;
    return out;
}

AdaptiveSplit::AdaptiveSplit(const std::vector<SplitObject>& objects, const RayScene* rays,
                             const AdaptiveSplitOptions& o)
    : _objects(objects),
      _ownIndex(std::make_unique<SplitIndex>(objects)),
      _index(*_ownIndex),
      _rays(rays),
      _o(o),
      _current(o.initialDistance) {}

AdaptiveSplit::AdaptiveSplit(const SplitIndex& index, const RayScene* rays, const AdaptiveSplitOptions& o)
    : _objects(index.objects()), _index(index), _rays(rays), _o(o), _current(o.initialDistance) {}

uint64_t AdaptiveSplit::predictedTriangles(const glm::dvec3& eye, double d) const {
    if (std::isinf(d)) return _index.totalTriangles();
    std::vector<std::pair<double, uint64_t>> near;
    _index.distances(eye, d, near);
    uint64_t n = 0;
    for (const auto& [t, tris] : near) n += tris;
    return n;
}

double AdaptiveSplit::predictedRays(double d) const {
    // Beyond the near field, or a miss (t = inf): _probeT is sorted ascending.
    const auto first = std::upper_bound(_probeT.begin(), _probeT.end(), float(d));
    return double(_probeT.end() - first) * _probeScale;
}

void AdaptiveSplit::probe(const Camera& camera) {
    Stopwatch whole;
    // Everything's triangles in view (within the haze, where nothing beyond is drawn).
    if (_objects.size() <= kEverythingViewTestObjects) {
        const ViewSides view(camera);
        const double reach = _hazeFar > 0 ? _hazeFar / minForwardCosine(camera) : 0.0;
        _everythingTris = 0;
        for (const SplitObject& o : _objects)
            if (view.sees(o) && (reach <= 0 || boxDistance(o, camera.eye) <= reach)) _everythingTris += o.triangles;
    } else {
        _everythingTris = _index.totalTriangles();
    }
    _probeT.clear();
    _probeEye = camera.eye;
    _probeHeading = camera.heading;
    _probePitch = camera.pitch;
    if (!_rays) return;
    // Every probeStride-th pixel, or sparser on a large image: about probeRays rays.
    // The probe's own cost stays a small share of the frames it prices: on frames of a few ms
    // (a small city drawn whole) it casts fewer rays, down to kProbeMinRays.
    double rays = double(std::max(1, _o.probeRays));
    if (_o.timeProbe && _probeMsPerRay > 0 && _frameMs > 0)
        rays = std::clamp(kProbeFrameShare * _frameMs / _probeMsPerRay, std::min(rays, kProbeMinRays), rays);
    const double fromCount = std::sqrt(double(camera.width) * camera.height / rays);
    const int s = std::max({1, _o.probeStride, int(std::lround(fromCount))});
    const glm::vec3 org(camera.eye - _rays->frameOrigin());
    std::vector<glm::vec3> orgs, dirs;
    for (int y = s / 2; y < camera.height; y += s)
        for (int x = s / 2; x < camera.width; x += s) {
            orgs.push_back(org);
            dirs.push_back(glm::vec3(camera.rayDirection(x + 0.5, y + 0.5)));
        }
    std::vector<RayHit> hits(dirs.size());
    // With haze nothing beyond its depth is traced: the probe stops there too.
    const glm::dvec3 fwd = camera.forward();
    const float tfar = _hazeFar > 0 ? float(_hazeFar / minForwardCosine(camera)) : 1e30f;
    if (!dirs.empty()) {
        Stopwatch sw;
        _rays->intersectMany(orgs.data(), dirs.data(), int(dirs.size()), hits.data(), tfar);
        if (_o.timeProbe) {
            // The ray-casting end point's price: every pixel's ray from the eye, one thread.
            const double all = sw.ms() / double(dirs.size());
            _probeAllMs = _probeAllMs > 0 ? (1 - _o.smoothing) * _probeAllMs + _o.smoothing * all : all;
        }
    }
    if (_hazeFar > 0)
        for (size_t i = 0; i < hits.size(); ++i)
            if (hits[i].hit && double(hits[i].t) * glm::dot(glm::dvec3(dirs[i]), fwd) > _hazeFar) hits[i].hit = false;
    if (_o.timeProbe) {
        // Bulk ms per far ray on one thread, independent of how many rays the split let
        // through: the probe rays that need the far field at the current near distance
        // (hit beyond it, or miss below the horizon), cast again from that distance as
        // the far field casts them. Timing every probe ray instead priced far rays at
        // the cost of the short ones into nearby facades (most of a street view).
        const float start = float(std::isfinite(_current) ? std::max(_current, _o.minDistance) : _o.minDistance);
        std::vector<glm::vec3> farDirs;
        for (size_t i = 0; i < hits.size(); ++i)
            if (hits[i].hit ? hits[i].t > start : dirs[i].z < 0) farDirs.push_back(dirs[i]);
        // A spread sample is timed: the rate, not the count, is what the split needs.
        if (farDirs.size() > kProbeFarTimed) {
            const size_t step = (farDirs.size() + kProbeFarTimed - 1) / kProbeFarTimed;
            size_t m = 0;
            for (size_t i = 0; i < farDirs.size(); i += step) farDirs[m++] = farDirs[i];
            farDirs.resize(m);
        }
        if (farDirs.size() >= 100) {
            std::vector<RayHit> farHits(farDirs.size());
            Stopwatch sw;
            _rays->intersectMany(orgs.data(), farDirs.data(), int(farDirs.size()), farHits.data(), tfar, nullptr,
                                 start);
            const double b = sw.ms() / double(farDirs.size());
            _bProbe = _bProbe > 0 ? (1 - _o.smoothing) * _bProbe + _o.smoothing * b : b;
        }
    }
    _probeT.resize(hits.size());
    size_t misses = 0;
    for (size_t i = 0; i < hits.size(); ++i) {
        // A miss pointing up is sky the horizon culls; one pointing down is a ray cast in vain.
        if (hits[i].hit) {
            _probeT[i] = hits[i].t;
        } else {
            _probeT[i] = dirs[i].z < 0 ? std::numeric_limits<float>::infinity() : 0.0f;
            ++misses;
        }
    }
    std::sort(_probeT.begin(), _probeT.end());  // predictedRays() counts by binary search
    if (!dirs.empty()) _probeMsPerRay = whole.ms() / double(dirs.size());
    _probeScale = dirs.empty() ? 0.0 : double(camera.width) * camera.height / double(dirs.size());
}

namespace {

// The index of the candidate `current` when its cost is within (1 + margin) of the best's, else best.
int keptWithinMargin(const std::vector<double>& cand, const std::vector<double>& cost, int best, double current,
                     double margin) {
    for (size_t i = 0; i < cand.size(); ++i)
        if (cand[i] == current && int(i) != best && cost[i] <= (1.0 + margin) * cost[size_t(best)]) return int(i);
    return best;
}

}  // namespace

double AdaptiveSplit::choose(const Camera& camera, int64_t pixelBudget) {
    (void)pixelBudget;  // see the header: the model aims at full accuracy
    // Probe every probeInterval frames, and at once when the view jumped (a
    // walkthrough restart, the runs of `--sampling runs:K`): a stale probe
    // predicts the rays of another place.
    const bool jumped = !_probeT.empty() && (glm::length(camera.eye - _probeEye) > _o.minDistance ||
                                             std::abs(std::remainder(camera.heading - _probeHeading, 2 * M_PI)) > 0.1 ||
                                             std::abs(camera.pitch - _probePitch) > 0.1);
    if (_frame % std::max(1, _o.probeInterval) == 0 || _probeT.empty() || jumped) probe(camera);
    const int frame = _frame++;
    if (_probeT.empty()) return _current;
    const int g = std::max(2, _o.candidates);
    std::vector<double> cand;
    // The ends are priced on measurements: ray casting once the probe is timed (its rate) or
    // the far cost measured; everything once the raster cost is measured. Before that
    // everything is offered only to be tried (kFirstTryFrame, kFirstTryRatio), never chosen
    // as the best on the priors alone (on a 3 M-triangle city the prior once chose it for
    // the first frames at 250 ms each): one tried frame measures it.
    const bool measured = _haveA && _haveB;
    const bool rayPriced = measured || _probeAllMs > 0;
    if (_o.rayCastOnly && rayPriced) cand.push_back(0.0);
    for (int i = 0; i < g; ++i)
        cand.push_back(_o.minDistance * std::pow(_o.maxDistance / _o.minDistance, double(i) / (g - 1)));
    // The fixed mode's near distance, a kind of its own: its frames measure its correction, so
    // the split can always fall back to the fixed choice when the model's middle does not pay.
    if (_o.fixedDistance > 0 && std::isfinite(_o.fixedDistance))
        cand.insert(std::upper_bound(cand.begin(), cand.end(), _o.fixedDistance), _o.fixedDistance);
    const bool everythingPriced = measured || !_kindFrames[2].empty();
    if (_o.everythingNear && (everythingPriced || rayPriced)) cand.push_back(std::numeric_limits<double>::infinity());
    const int n = int(cand.size());
    // The triangles the view sees within the largest finite candidate, filed by the first
    // candidate (ascending) whose distance reaches them: one visit, no sort; the sweep below adds
    // them up. Triangles outside the view are culled by the renderer and cost no raster time,
    // so prices (and the raster fit, chosenTriangles()) count only the triangles in view.
    const ViewSides view(camera);
    std::vector<uint64_t> reached(cand.size() + 1, 0);
    _index.visitWithin(camera.eye, _o.maxDistance, [&](uint32_t i, double t) {
        if (view.sees(_objects[i]))
            reached[size_t(std::lower_bound(cand.begin(), cand.end(), t) - cand.begin())] += _objects[i].triangles;
    });
    _pixels = int64_t(camera.width) * int64_t(camera.height);
    // The model's price of each candidate (see the header), then the learned correction of its kind.
    double corr[kSplitKinds];
    for (int kind = 0; kind < kSplitKinds; ++kind) corr[kind] = correctionMs(kind);
    std::vector<double> price(cand.size()), cost(cand.size()), candRays(cand.size());
    std::vector<uint64_t> candTris(cand.size());
    uint64_t tris = 0;
    int bestI = -1;
    for (int i = 0; i < n; ++i) {
        const double d = cand[size_t(i)];
        if (std::isinf(d)) {
            tris = _everythingTris;
        } else {
            tris += reached[size_t(i)];
        }
        const int kind = kindOf(d);
        candTris[size_t(i)] = kind == 0 ? 0 : tris;
        candRays[size_t(i)] = kind == 2 ? 0.0 : predictedRays(kind == 0 ? 0.0 : d);
        price[size_t(i)] = priceOf(kind, double(candTris[size_t(i)]), candRays[size_t(i)], double(_pixels));
        // A middle distance, and the fixed distance before its own frames ran (it is a middle distance all
        // the same: pricing it by the model alone, against middle distances corrected by their frames, kept the
        // split from it where the model's middle does not pay), are corrected by the middle frames like them.
        const bool byMiddle = kind == 1 || (kind == 3 && _kindFrames[3].empty());
        cost[size_t(i)] = std::max(
            0.0, price[size_t(i)] + (byMiddle ? nearestFramesCorrection(
                                                    _kindFrames[1], candTris[size_t(i)], candRays[size_t(i)],
                                                    [&](const auto& k) { return priceOf(1, k.tris, k.rays, k.pixels); })
                                              : corr[kind]));
        if (kind == 3) {
            _fixedTris = candTris[size_t(i)];
            _fixedRays = candRays[size_t(i)];
        }
        const bool tryOnly = kind == 2 && !everythingPriced;
        if (!tryOnly && (bestI < 0 || cost[size_t(i)] < cost[size_t(bestI)])) bestI = i;
    }
    // Hysteresis: the last choice is kept unless another is cheaper by more than switchMargin. A
    // change of the near distance costs the frames after it what no price holds (the band between
    // the two distances is in neither the cache nor the last frame's traced pixels; the near
    // field's new chunks): measured, a frame at the near default right after a change cost 1.11
    // times `hybrid-fixed`'s same frame, one after a frame at the same distance 1.02 times.
    if (!(kindOf(_current) == 2 && !everythingPriced))
        bestI = keptWithinMargin(cand, cost, bestI, _current, _o.switchMargin);
    const double best = cost[size_t(bestI)];
    // Exploration feeds the fits varied triangle counts and far pixels; once both fits are well
    // conditioned the walk's own views vary them, and each exploration is two changes of distance.
    const bool fitted = _haveA && _bFitted;
    if (!fitted && _o.exploreEvery > 0 && frame % _o.exploreEvery == _o.exploreEvery - 1) {
        const int slot = frame / _o.exploreEvery;
        const int j = std::clamp(bestI + (slot % 2 ? 1 : -1), 0, n - 1);
        if (cost[size_t(j)] <= _o.exploreRatio * best || slot % 4 == 3) bestI = j;
    }
    // A kind of choice (ray casting, the middle, everything) not run for a while is tried, its
    // cheapest candidate, when its price is near the best: its correction is then measured, not
    // assumed (a price resting on one frame's one-time costs would otherwise keep the split away).
    if (_o.endTryEvery > 0 && _o.endTryRatio > 0) {
        const int bestKind = kindOf(cand[size_t(bestI)]);
        for (int kind = 0; kind < kSplitKinds; ++kind) {
            // A kind never run is tried early (from frame kFirstTryFrame, within kFirstTryRatio of
            // the best): its price then stops resting on the model alone.
            const bool never = _kindFrames[kind].empty();
            if (kind == bestKind || !(frame - _lastKindFrame[kind] >= (never ? kFirstTryFrame : _o.endTryEvery)))
                continue;
            int cheapest = -1;
            for (int i = 0; i < n; ++i)
                if (kindOf(cand[size_t(i)]) == kind && (cheapest < 0 || cost[size_t(i)] < cost[size_t(cheapest)]))
                    cheapest = i;
            if (cheapest >= 0 &&
                cost[size_t(cheapest)] <= (never ? std::max(kFirstTryRatio, _o.endTryRatio) : _o.endTryRatio) * best) {
                bestI = cheapest;
                break;
            }
        }
    }
    _current = cand[size_t(bestI)];
    _chosenTris = candTris[size_t(bestI)];
    _chosenRays = candRays[size_t(bestI)];
    _lastKindFrame[kindOf(_current)] = frame;
    return _current;
}

void AdaptiveSplit::recordFrame(double nearD, double frameMs) {
    const int kind = kindOf(nearD);
    // An end point or the fixed distance drawn instead of the choice (a guard's hold or
    // measurement) is a frame of that kind all the same: what it drew and traced is the kind's own
    // (no triangles and every pixel for ray casting; everything's triangles in view at the last
    // probe; the fixed distance's triangles in view and far pixels at the last choice).
    const bool chosen = nearD == _current;
    const bool reference = !chosen && (nearD == 0.0 || (std::isinf(nearD) && nearD > 0) ||
                                       (_o.fixedDistance > 0 && nearD == _o.fixedDistance));
    if (!(chosen || reference) || !(frameMs >= 0)) return;
    _frameMs = _frameMs > 0 ? (1 - _o.smoothing) * _frameMs + _o.smoothing * frameMs : frameMs;
    if (reference) _lastKindFrame[kind] = _frame - 1;  // it ran: no try needed to measure it
    // A kind's first frame pays one-time costs (the first draw of the chunks, the far field's
    // first frame): not counted. Ray casting draws nothing, and once a frame has run its casters'
    // threads are warm: its first frame counts, so that a price resting on the probe's one-thread
    // rate (which overprices the coherent rows of a ray-cast frame) is corrected by one try. The
    // middle and the fixed distance share the far field: the first frame of the two is not
    // counted, the other's first frame is (one try then prices the fixed distance).
    const bool farFieldRan = (kind == 1 && _kindSeen[3]) || (kind == 3 && _kindSeen[1]);
    const bool oneTimeCosts = (kind != 0 || _frame <= 1) && !farFieldRan;
    if (!_kindSeen[kind] && oneTimeCosts) {
        _kindSeen[kind] = true;
        return;
    }
    _kindSeen[kind] = true;
    std::vector<KindFrame>& w = _kindFrames[kind];
    if (chosen) w.push_back({double(_chosenTris), _chosenRays, double(_pixels), frameMs});
    else if (kind == 0) w.push_back({0.0, predictedRays(0.0), double(_pixels), frameMs});
    else if (kind == 3) w.push_back({double(_fixedTris), _fixedRays, double(_pixels), frameMs});
    else w.push_back({double(_everythingTris), 0.0, double(_pixels), frameMs});
    if (w.size() > kKindWindow) w.erase(w.begin());
}

double AdaptiveSplit::priceOf(int kind, double tris, double rays, double pixels) const {
    if (kind == 0) return _probeAllMs > 0 ? _probeAllMs * pixels / coreCount() : msPerRay() * rays;
    // Nothing to draw -> no GL pass: the raster's fixed cost only where triangles are drawn.
    const double raster = tris > 0 ? _c + _a * tris : 0.0;
    return kind == 2 ? raster : raster + msPerRay() * rays + _f;
}

double AdaptiveSplit::correctionMs(int kind) const {
    // Re-priced with the current model at every call: a residual taken against the first
    // frames' priors would otherwise outlive them (measured: a correction of -22 ms, set when
    // the prior priced far pixels 20 times too high, held a kind's price down for 60 frames).
    const std::vector<KindFrame>& w = _kindFrames[kind];
    if (w.empty()) return 0.0;
    std::vector<double> r;
    r.reserve(w.size());
    for (const KindFrame& k : w) r.push_back(k.frameMs - priceOf(kind, k.tris, k.rays, k.pixels));
    // The lower quartile: other work on the machine only ever slows a frame, so a kind whose
    // frames were hit by it is not priced out of reach (it is tried again only when near the best).
    const size_t q = (r.size() - 1) / 4;
    std::nth_element(r.begin(), r.begin() + long(q), r.end());
    return r[q];
}

double AdaptiveSplit::msPerRay() const {
    // A well-conditioned fit of the frames is the in-frame price (the probe's one-thread
    // rate, cast sparsely between frames, has measured 3x below it on a 1280x720 street
    // view); the probe caps only the fallback to the mean, which counts fixed costs.
    if (_bFitted) return _b;
    if (_bProbe > 0) return _haveB ? std::min(_b, _bProbe) : _bProbe;
    return _b;
}

void AdaptiveSplit::record(uint64_t triangles, double rasterMs, uint64_t farPixels, double farMs, double fixedMs) {
    const double w = _o.smoothing;
    if (rasterMs > 0) {
        pushWindow(_rasterSamples, {double(triangles), rasterMs}, _o.window);
        if (auto a = fitSlope(_rasterSamples); a && *a > 0) {  // keep the prior until the counts vary enough
            _a = *a;
            _haveA = true;
            // The raster's fixed cost (clear, read-back): the median residual of the slope.
            std::vector<double> rest;
            rest.reserve(_rasterSamples.size());
            for (const auto& [x, y] : _rasterSamples) rest.push_back(y - _a * x);
            const auto mid = rest.begin() + long(rest.size() / 2);
            std::nth_element(rest.begin(), mid, rest.end());
            _c = std::max(0.0, *mid);
        }
    }
    // The far field's first frame pays one-time costs (the panorama's pages, the first horizon
    // trace): counted neither in b nor in F, or the price of every middle candidate rests on them.
    const bool farFrame = farPixels > 0 || fixedMs > 0;
    const bool firstFar = farFrame && _farFrames++ == 0;
    if (farPixels > 100 && farMs > 0 && !firstFar) {
        pushWindow(_farSamples, {double(farPixels), farMs}, _o.window);
        double sx = 0, sy = 0;
        for (const auto& [x, y] : _farSamples) {
            sx += x;
            sy += y;
        }
        const double mean = sy / sx;  // ms per far pixel, fixed costs included: an upper bound
        const auto b = fitSlope(_farSamples);
        _b = b ? std::clamp(*b, mean / 5, mean) : mean;
        _bFitted = b.has_value();
        _haveB = true;
    }
    if (farFrame && !firstFar) {
        _f = _haveF ? (1 - w) * _f + w * fixedMs : fixedMs;
        _haveF = true;
    }
}

}  // namespace vista
