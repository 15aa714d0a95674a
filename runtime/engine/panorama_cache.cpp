// Panoramic image cache with confidence records (see panorama_cache.h).
#include "runtime/engine/panorama_cache.h"
#include "foundation/units.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "foundation/status.h"

namespace vista {

namespace {
constexpr uint32_t kMaxRecords = 1u << 16;  // compaction threshold
}  // namespace

PanoramaCache::PanoramaCache(int width, int height, double vMax)
    : _width(std::max(1, width)), _height(std::max(1, height)), _vMax(vMax > 0 ? vMax : 1.0) {
    VISTA_CHECK(int64_t(_width) * int64_t(_height) <= kMaxCells);
    clear();
}

PanoramaCache PanoramaCache::forCamera(const Camera& camera, double oversample) {
    oversample = std::max(0.25, oversample);
    double t = std::tan(0.5 * camera.fovY);
    double aspect = double(camera.width) / double(std::max(1, camera.height));
    double dx = 2.0 * t * aspect / std::max(1, camera.width);  // radians per pixel at the centre
    double dy = 2.0 * t / std::max(1, camera.height);
    double vMax = std::tan(std::min(0.5 * camera.fovY + 0.1745329, 1.40));  // +10 degrees of pitch
    double w = kTwoPi / (dx / oversample), h = 2.0 * vMax / (dy / oversample);
    double cells = w * h;
    if (cells > double(kMaxCells)) {
        double f = std::sqrt(double(kMaxCells) / cells);
        w *= f;
        h *= f;
    }
    int W = std::max(8, int(std::floor(w))), H = std::max(2, int(std::floor(h)));
    while (int64_t(W) * H > kMaxCells) --H;
    return PanoramaCache(W, H, vMax);
}

glm::dvec2 PanoramaCache::mapCoord(const glm::dvec3& d) const {
    double h = std::sqrt(d.x * d.x + d.y * d.y);
    double az = std::atan2(d.x, d.y);  // clockwise from +y
    if (az < 0) az += kTwoPi;
    double u = az / kTwoPi * _width;
    double v = h > 0 ? d.z / h : (d.z > 0 ? 1e30 : -1e30);
    double row = (_vMax - v) / (2.0 * _vMax) * _height;  // row 0 at the top (v = vMax)
    return {u, row};
}

int64_t PanoramaCache::index(const glm::dvec3& d) const {
    if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z)) return -1;
    if (d.x == 0 && d.y == 0) return -1;
    glm::dvec2 c = mapCoord(d);
    if (!(c.y >= 0 && c.y < _height)) return -1;
    int64_t col = int64_t(std::floor(c.x));
    col %= _width;  // az == 2 pi after rounding wraps to 0
    if (col < 0) col += _width;
    int64_t row = std::min<int64_t>(_height - 1, int64_t(std::floor(c.y)));
    return row * _width + col;
}

void PanoramaCache::clear() {
    size_t n = size_t(_width) * size_t(_height);
    _color.assign(n, glm::u8vec4(0));
    _record.assign(n, 0);
    _records.assign(1, Record{});
    _current = 0;
}

void PanoramaCache::beginFrame(const Camera& c) {
    ++_frame;
    if (_current != 0) {
        const Record& r = _records[_current];
        if (r.eye == c.eye && r.heading == c.heading && r.pitch == c.pitch && r.roll == c.roll && r.fovY == c.fovY &&
            r.width == c.width && r.height == c.height)
            return;  // same camera: same record
    }
    if (_records.size() >= kMaxRecords) compact();
    Record r;
    r.eye = c.eye;
    r.heading = c.heading;
    r.pitch = c.pitch;
    r.roll = c.roll;
    r.fovY = c.fovY;
    r.width = c.width;
    r.height = c.height;
    _records.push_back(r);
    _current = uint32_t(_records.size() - 1);
}

void PanoramaCache::compact() {
    // Keep only records still referenced by a cell (and the current one).
    std::vector<uint32_t> remap(_records.size(), 0);
    std::vector<uint8_t> used(_records.size(), 0);
    for (uint32_t r : _record) used[r] = 1;
    if (_current) used[_current] = 1;
    std::vector<Record> kept(1);
    for (size_t i = 1; i < _records.size(); ++i)
        if (used[i]) {
            remap[i] = uint32_t(kept.size());
            kept.push_back(_records[i]);
        }
    // Still too many distinct records: fold the oldest into "never traced".
    if (kept.size() >= kMaxRecords / 2) {
        size_t drop = kept.size() - kMaxRecords / 4;
        for (auto& m : remap) m = m <= drop ? 0 : uint32_t(m - drop);
        kept.erase(kept.begin() + 1, kept.begin() + 1 + long(drop));
    }
    for (auto& r : _record) r = remap[r];
    _current = remap[_current];
    _records = std::move(kept);
}

int64_t PanoramaCache::selectForTracing(const std::vector<CacheCandidate>& cand, int64_t budget,
                                        std::vector<uint8_t>& trace) {
    trace.assign(cand.size(), 0);
    const size_t R = _records.size();
    const Record& cur = _records[_current];
    // Per record: distance to the current observer; exact = this very camera.
    auto exact = [&](uint32_t r) { return r != 0 && r == _current; };
    _count.assign(R, 0);
    int64_t marked = 0;
    for (size_t i = 0; i < cand.size(); ++i) {
        if (cand[i].cell < 0) {  // not cacheable: always traced
            trace[i] = 1;
            ++marked;
            continue;
        }
        ++_count[_record[size_t(cand[i].cell)]];
    }
    int64_t left = budget < 0 ? INT64_MAX : std::max<int64_t>(0, budget - marked);
    // Records in use, worst first: record 0 (never traced), then by distance,
    // then same position with another orientation (distance 0) last.
    std::vector<uint32_t> order;
    for (uint32_t r = 0; r < R; ++r)
        if (_count[r] > 0 && !exact(r)) order.push_back(r);
    std::vector<double> dist(R, 0.0);
    for (uint32_t r : order) dist[r] = r == 0 ? INFINITY : glm::length(_records[r].eye - cur.eye);
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return dist[a] > dist[b]; });
    // Decide per record: all, every n-th, or none.
    std::vector<uint32_t> nth(R, 0);  // 0 = none, 1 = all, n = every n-th
    for (uint32_t r : order) {
        if (left <= 0) break;
        if (int64_t(_count[r]) <= left) {
            nth[r] = 1;
            left -= _count[r];
        } else {
            nth[r] = uint32_t((int64_t(_count[r]) + left - 1) / left);
            left = 0;
        }
    }
    std::vector<uint32_t> seen(R, 0);
    const uint64_t phase = _frame;
    for (size_t i = 0; i < cand.size(); ++i) {
        if (cand[i].cell < 0) continue;
        uint32_t r = _record[size_t(cand[i].cell)];
        uint32_t n = nth[r];
        if (n == 0) continue;
        uint32_t k = seen[r]++;
        if (n == 1 || (k + phase) % n == 0) {
            trace[i] = 1;
            ++marked;
        }
    }
    return marked;
}

void PanoramaCache::store(const std::vector<int64_t>& cells, const std::vector<glm::u8vec4>& colors) {
    VISTA_CHECK(cells.size() == colors.size());
    std::vector<int64_t> dup;
    for (size_t i = 0; i < cells.size(); ++i) {
        int64_t c = cells[i];
        if (c < 0) continue;
        _color[size_t(c)] = colors[i];
        _record[size_t(c)] = _current;
    }
    // Cells hit by two pixels this frame hold only one of them: not exact.
    std::vector<int64_t> sorted;
    sorted.reserve(cells.size());
    for (int64_t c : cells)
        if (c >= 0) sorted.push_back(c);
    std::sort(sorted.begin(), sorted.end());
    for (size_t i = 1; i < sorted.size(); ++i)
        if (sorted[i] == sorted[i - 1]) _record[size_t(sorted[i])] = 0;
}

}  // namespace vista
