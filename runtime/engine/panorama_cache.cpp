// Panoramic image cache with confidence records (see panorama_cache.h).
#include "runtime/engine/panorama_cache.h"
#include "foundation/units.h"

#include <algorithm>
#include <cstring>
#include <cmath>
#include <numeric>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

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

int64_t PanoramaCache::index(const glm::dvec3& d, glm::u8vec2* sub) const {
    if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z)) return -1;
    if (d.x == 0 && d.y == 0) return -1;
    glm::dvec2 c = mapCoord(d);
    if (!(c.y >= 0 && c.y < _height)) return -1;
    const double fx = std::floor(c.x), fy = std::floor(c.y);
    int64_t col = int64_t(fx);
    col %= _width;  // az == 2 pi after rounding wraps to 0
    if (col < 0) col += _width;
    int64_t row = std::min<int64_t>(_height - 1, int64_t(fy));
    if (sub)
        *sub = glm::u8vec2(uint8_t(std::min(255.0, (c.x - fx) * 256.0)), uint8_t(std::min(255.0, (c.y - fy) * 256.0)));
    return row * _width + col;
}

uint32_t PanoramaCache::encodeNear(float d) {
    uint32_t b, inf;
    const float i = INFINITY;
    std::memcpy(&b, &d, 4);
    std::memcpy(&inf, &i, 4);
    return b ^ inf;
}

float PanoramaCache::decodeNear(uint32_t v) {
    const float i = INFINITY;
    uint32_t inf;
    std::memcpy(&inf, &i, 4);
    v ^= inf;
    float d;
    std::memcpy(&d, &v, 4);
    return d;
}

void PanoramaCache::clear() {
    const size_t n = size_t(_width) * size_t(_height);
    if (_cells.size() == n) _cells.zero();  // a restart: the pages stay, so its first frames pay no page faults
    else _cells.reset(n);
    _stamp = 0;
    _records.assign(1, Record{});
    _baseline.assign(1, INFINITY);
    _current = 0;
}

double PanoramaCache::reuseReach(const CachePolicy& p) {
    return p.lowerDepth > 0 ? (p.maxErrorPx + p.windowPx) * p.radPerPixel * p.lowerDepth : 0.0;
}

uint64_t PanoramaCache::invalidateBox(const glm::dvec3& lo, const glm::dvec3& hi, double reach) {
    if (_current == 0) return 0;  // nothing traced yet
    const uint64_t all = uint64_t(_width) * uint64_t(_height);
    auto forgetAll = [&] {
        clear();
        return all;
    };
    const glm::dvec3 eye = _records[_current].eye;
    double b = 0;
    for (size_t i = 1; i < _records.size(); ++i) {
        const double d = glm::length(_records[i].eye - eye);
        if (d > reach) _records[i].forgotten = true;
        else if (!_records[i].forgotten) b = std::max(b, d);
    }
    // Horizontal distances from the eye to the box's footprint (nearest and farthest point).
    const double dx = std::max({lo.x - eye.x, 0.0, eye.x - hi.x}), dy = std::max({lo.y - eye.y, 0.0, eye.y - hi.y});
    const double hMin = std::hypot(dx, dy) - b;
    if (!(hMin > 1e-6)) return forgetAll();
    const double fx = std::max(std::abs(lo.x - eye.x), std::abs(hi.x - eye.x));
    const double fy = std::max(std::abs(lo.y - eye.y), std::abs(hi.y - eye.y));
    const double hMax = std::hypot(fx, fy) + b;
    // Elevations (v = tan) the box spans from any record's eye.
    const double zTop = hi.z - eye.z + b, zBottom = lo.z - eye.z - b;
    const double vTop = zTop / (zTop > 0 ? hMin : hMax), vBottom = zBottom / (zBottom < 0 ? hMin : hMax);
    if (vBottom > _vMax || vTop < -_vMax) return 0;
    // Rows clamped before the conversion: a box just beyond b gives tangents far outside the map.
    auto rowOf = [&](double v) {
        return int(std::clamp(std::floor((_vMax - v) / (2.0 * _vMax) * _height), -1.0, double(_height)));
    };
    const int rowFirst = std::clamp(rowOf(vTop) - 1, 0, _height - 1);
    const int rowLast = std::clamp(rowOf(vBottom) + 1, 0, _height - 1);
    // Azimuths of the corners about the centre's (the box is outside the eye's reach: its span is under pi).
    const double azC = std::atan2(0.5 * (lo.x + hi.x) - eye.x, 0.5 * (lo.y + hi.y) - eye.y);
    double aMin = 0, aMax = 0;
    for (const double x : {lo.x, hi.x})
        for (const double y : {lo.y, hi.y}) {
            double a = std::atan2(x - eye.x, y - eye.y) - azC;
            a -= kTwoPi * std::floor((a + kPi) / kTwoPi);  // into [-pi, pi)
            aMin = std::min(aMin, a);
            aMax = std::max(aMax, a);
        }
    const double margin = std::asin(std::min(1.0, b / (hMin + b)));
    const double perCell = double(_width) / kTwoPi;
    const int64_t colFirst = int64_t(std::floor((azC + aMin - margin) * perCell)) - 1;
    const int64_t colLast = int64_t(std::floor((azC + aMax + margin) * perCell)) + 1;
    if (colLast - colFirst + 1 >= _width) {
        for (int r = rowFirst; r <= rowLast; ++r)
            std::fill_n(&_cells[size_t(r) * size_t(_width)], size_t(_width), Cell{});
        return uint64_t(rowLast - rowFirst + 1) * uint64_t(_width);
    }
    for (int r = rowFirst; r <= rowLast; ++r)
        for (int64_t c = colFirst; c <= colLast; ++c) {
            const int64_t col = ((c % _width) + _width) % _width;
            _cells[size_t(r) * size_t(_width) + size_t(col)] = Cell{};
        }
    return uint64_t(rowLast - rowFirst + 1) * uint64_t(colLast - colFirst + 1);
}

void PanoramaCache::beginFrame(const Camera& c) {
    const bool same = _current != 0 && [&] {
        const Record& r = _records[_current];
        return r.eye == c.eye && r.heading == c.heading && r.pitch == c.pitch && r.roll == c.roll && r.fovY == c.fovY &&
               r.width == c.width && r.height == c.height;
    }();
    if (!same) {
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
    _baseline.resize(_records.size());
    _baseline[0] = INFINITY;
    for (size_t i = 1; i < _records.size(); ++i) _baseline[i] = glm::length(_records[i].eye - c.eye);
}

void PanoramaCache::compact() {
    // Keep only records still referenced by a cell (and the current one).
    std::vector<uint32_t> remap(_records.size(), 0);
    std::vector<uint8_t> used(_records.size(), 0);
    for (const Cell& c : _cells) used[c.record] = 1;
    if (_current) used[_current] = 1;
    std::vector<Record> kept(1);
    for (size_t i = 1; i < _records.size(); ++i)
        if (used[i] && !_records[i].forgotten) {
            remap[i] = uint32_t(kept.size());
            kept.push_back(_records[i]);
        }
    // Still too many distinct records: fold the oldest into "never traced".
    if (kept.size() >= kMaxRecords / 2) {
        size_t drop = kept.size() - kMaxRecords / 4;
        for (auto& m : remap) m = m <= drop ? 0 : uint32_t(m - drop);
        kept.erase(kept.begin() + 1, kept.begin() + 1 + long(drop));
    }
    for (Cell& c : _cells) c.record = remap[c.record];
    _current = remap[_current];
    _records = std::move(kept);
}

double PanoramaCache::error(int64_t cell, glm::u8vec2 sub, const CachePolicy& p) const {
    const Cell& c = _cells[size_t(cell)];
    const uint32_t r = c.record;
    if (r == 0 || _records[r].forgotten) return INFINITY;
    if (r == _current) return -1.0;  // traced by this very camera
    // Resampling: the angle between the cell's traced ray and this one. On the
    // cylinder a column step is 2 pi / width of azimuth (times cos elevation
    // on the sphere), a row step 2 vMax / height of tan(elevation) (times cos^2).
    const glm::u8vec2 s = c.sub ^ glm::u8vec2(kSubBias);
    const int64_t row = cell / _width;  // the cell's row (integer division on purpose)
    const double v = _vMax - (double(row) + 0.5) * 2.0 * _vMax / _height;
    const double c2 = 1.0 / (1.0 + v * v);
    const double du = (double(sub.x) - double(s.x)) / 256.0 * kTwoPi / _width * std::sqrt(c2);
    const double dv = (double(sub.y) - double(s.y)) / 256.0 * 2.0 * _vMax / _height * c2;
    const double offset = std::sqrt(du * du + dv * dv);
    const double b = _baseline[r];
    if (b == 0) return offset / p.radPerPixel;              // rotation only
    const double own = b / double(decodeNear(c.nearBits));  // 0 when the window was all sky
    const double outside = p.lowerDepth > 0 ? b / p.lowerDepth - p.windowPx * p.radPerPixel : INFINITY;
    return (std::max(own, outside) + offset) / p.radPerPixel;
}

int64_t PanoramaCache::selectForTracing(const std::vector<CacheCandidate>& cand, const CachePolicy& p,
                                        std::vector<uint8_t>& trace) {
    trace.assign(cand.size(), 0);
    // Errors in parallel (pure reads), then the selection in candidate order (deterministic).
    _error.resize(cand.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, cand.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i)
            _error[i] = cand[i].cell < 0 ? -2.0 : error(cand[i].cell, cand[i].sub, p);
    });
    int64_t forced = 0;
    // Candidates over the bound, with their errors (largest traced first under a budget).
    std::vector<std::pair<double, uint32_t>> over;
    for (size_t i = 0; i < cand.size(); ++i) {
        const double e = _error[i];
        if (e == -2.0) {  // not cacheable: always traced
            trace[i] = 1;
            ++forced;
            continue;
        }
        if (e < 0 || e < p.maxErrorPx) continue;
        over.push_back({e, uint32_t(i)});
    }
    size_t take = over.size();
    if (p.budget >= 0) take = size_t(std::min<int64_t>(int64_t(over.size()), std::max<int64_t>(0, p.budget - forced)));
    if (take < over.size()) {
        // Largest errors first; ties (e.g. never traced) by candidate order, so the choice is deterministic.
        std::nth_element(over.begin(), over.begin() + long(take), over.end(), [](const auto& a, const auto& b) {
            return a.first != b.first ? a.first > b.first : a.second < b.second;
        });
    }
    for (size_t k = 0; k < take; ++k) trace[over[k].second] = 1;
    return forced + int64_t(take);
}

void PanoramaCache::forget(const std::vector<int64_t>& cells) {
    for (int64_t c : cells)
        if (c >= 0) _cells[size_t(c)] = Cell{};
}

void PanoramaCache::store(const std::vector<int64_t>& cells, const std::vector<glm::u8vec2>& subs,
                          const std::vector<glm::u8vec4>& colors, const std::vector<float>& nearDistance) {
    VISTA_CHECK(cells.size() == colors.size() && cells.size() == nearDistance.size() && cells.size() == subs.size());
    // Cells hit by two pixels this frame hold only one of them: not exact (record 0).
    if (++_stamp == 0) _stamp = 1;  // 0 = never written
    for (size_t i = 0; i < cells.size(); ++i) {
        int64_t c = cells[i];
        if (c < 0) continue;
        const size_t k = size_t(c);
        Cell& cell = _cells[k];
        const bool twice = cell.stamp == _stamp;
        cell.stamp = _stamp;
        cell.color = colors[i];
        cell.sub = subs[i] ^ glm::u8vec2(kSubBias);
        cell.nearBits = encodeNear(nearDistance[i]);
        cell.record = twice ? 0 : _current;
    }
}

}  // namespace vista
