// ShapeGrid: quadrilaterals (Quad, four corners in metres, city frame) by
// the square cells of a uniform grid that their bounding boxes touch; the
// broad phase of the lane model's crossing tests (lanes.cpp).
//
// insert(q, id): ids must come in strictly increasing order (checked), so
// that every cell's list is sorted. A quad with a non-finite corner (NaN
// or infinite) is not stored.
// query(q, first, last, keep, out): into `out` (cleared first), sorted and
// without repeats, the ids in [first, last) for which keep(id) holds of the
// quads sharing a cell with q. Every quad whose bounding box meets q's
// bounding box is among them; others may be too (they share a cell only).
// Only the part of a cell's list in [first, last) is read, and `keep` runs
// before the sort: a caller that skips most of a cell's quads (a turn's own
// junction) pays for the quads it keeps. Nothing for a non-finite q.
// Not thread-safe for concurrent insert; concurrent queries are fine.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "foundation/status.h"

namespace vista {

using Quad = std::array<glm::dvec2, 4>;

class ShapeGrid {
public:
    explicit ShapeGrid(double cell) : _cell(cell) {}

    void insert(const Quad& q, uint32_t id) {
        forCells(q, [&](uint64_t k) {
            std::vector<uint32_t>& ids = _cells[k];
            VISTA_CHECK(ids.empty() || ids.back() < id);
            ids.push_back(id);
        });
    }

    template <class Keep>
    void query(const Quad& q, uint32_t first, uint32_t last, Keep keep, std::vector<uint32_t>& out) const {
        out.clear();
        forCells(q, [&](uint64_t k) {
            auto it = _cells.find(k);
            if (it == _cells.end()) return;
            const std::vector<uint32_t>& ids = it->second;
            for (auto i = std::lower_bound(ids.begin(), ids.end(), first); i != ids.end() && *i < last; ++i)
                if (keep(*i)) out.push_back(*i);
        });
        std::sort(out.begin(), out.end());
        out.erase(std::unique(out.begin(), out.end()), out.end());
    }

private:
    template <class F>
    void forCells(const Quad& q, F f) const {
        glm::dvec2 lo(1e300), hi(-1e300);
        for (const glm::dvec2& p : q) {
            if (!std::isfinite(p.x + p.y)) return;  // glm::min and max would pass over a NaN
            lo = glm::min(lo, p), hi = glm::max(hi, p);
        }
        for (long y = long(std::floor(lo.y / _cell)); y <= long(std::floor(hi.y / _cell)); ++y)
            for (long x = long(std::floor(lo.x / _cell)); x <= long(std::floor(hi.x / _cell)); ++x)
                f((uint64_t(x) << 32) ^ (uint64_t(y) & 0xFFFFFFFFull));
    }

    double _cell;
    std::unordered_map<uint64_t, std::vector<uint32_t>> _cells;
};

}  // namespace vista
