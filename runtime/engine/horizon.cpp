// Horizon tracing: height grid + conservative 2D rays (see horizon.h).
#include "runtime/engine/horizon.h"
#include "foundation/status.h"
#include "foundation/units.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

namespace vista {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTieEps = 1e-9;  // relative tolerance for "the ray crosses a grid corner"

struct Box2 {
    glm::dvec3 lo{kInf}, hi{-kInf};
    void add(const glm::dvec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    bool valid() const { return lo.x <= hi.x; }
};

// Scene-local bounds of a model: of the vertices its meshes' indices reference
// and of its tree instances (each its prototype's box, transformed), and each
// instance's own box (invalid when its prototype has no geometry).
struct SceneBoxes {
    Box2 all;
    std::vector<Box2> instances;
};

SceneBoxes sceneBoxes(const SceneModel& city, const glm::dvec3& frameOrigin) {
    SceneBoxes b;
    for (const SceneMesh& m : city.meshes) {
        const glm::dvec3 shift = m.origin - frameOrigin;
        for (uint32_t i : m.indices)
            if (i < m.positions.size()) b.all.add(glm::dvec3(m.positions[i]) + shift);
    }
    std::vector<Box2> protoBox(city.prototypes.size());
    for (size_t p = 0; p < city.prototypes.size(); ++p) {
        const SceneMesh& m = city.prototypes[p];
        for (uint32_t i : m.indices)
            if (i < m.positions.size()) protoBox[p].add(glm::dvec3(m.positions[i]) + m.origin);
    }
    b.instances.resize(city.instances.size());
    for (size_t k = 0; k < city.instances.size(); ++k) {
        const SceneInstance& inst = city.instances[k];
        if (inst.prototype >= protoBox.size() || !protoBox[inst.prototype].valid()) continue;
        const Box2& pb = protoBox[inst.prototype];
        for (int c = 0; c < 8; ++c) {
            const glm::dvec4 v((c & 1) ? pb.hi.x : pb.lo.x, (c & 2) ? pb.hi.y : pb.lo.y, (c & 4) ? pb.hi.z : pb.lo.z,
                               1.0);
            b.instances[k].add(glm::dvec3(inst.transform * v) - frameOrigin);
        }
        b.all.add(b.instances[k].lo);
        b.all.add(b.instances[k].hi);
    }
    return b;
}

// Calls splat(lo, hi) with the scene-local box of every triangle of the
// city's meshes, then with each valid instance box.
template <class Splat>
void splatScene(const SceneModel& city, const glm::dvec3& frameOrigin, const std::vector<Box2>& instBox,
                Splat&& splat) {
    for (const SceneMesh& m : city.meshes) {
        const glm::dvec3 shift = m.origin - frameOrigin;
        for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
            Box2 b;
            for (int k = 0; k < 3; ++k) {
                const uint32_t i = m.indices[t + size_t(k)];
                if (i < m.positions.size()) b.add(glm::dvec3(m.positions[i]) + shift);
            }
            if (b.valid()) splat(b.lo, b.hi);
        }
    }
    for (const Box2& b : instBox)
        if (b.valid()) splat(b.lo, b.hi);
}

// A 2D DDA over square cells `unit` grid cells wide, starting in cell (x, y)
// for the ray s0 + d * t (grid units); tMax = the ray parameter where it
// leaves the current cell in x / y.
struct GridWalk {
    int x, y, stepX, stepY;
    double tMaxX, tMaxY, tDeltaX, tDeltaY;
    GridWalk(int x0, int y0, double sx0, double sy0, double dx, double dy, double unit)
        : x(x0),
          y(y0),
          stepX(dx > 0 ? 1 : -1),
          stepY(dy > 0 ? 1 : -1),
          tDeltaX(dx != 0 ? 1.0 / std::abs(dx) * unit : kInf),
          tDeltaY(dy != 0 ? 1.0 / std::abs(dy) * unit : kInf) {
        tMaxX = std::max(0.0, dx > 0 ? ((x + 1) * unit - sx0) / dx : dx < 0 ? (sx0 - x * unit) / -dx : kInf);
        tMaxY = std::max(0.0, dy > 0 ? ((y + 1) * unit - sy0) / dy : dy < 0 ? (sy0 - y * unit) / -dy : kInf);
    }
    double next() const { return std::min(tMaxX, tMaxY); }
    bool corner() const { return std::abs(tMaxX - tMaxY) <= kTieEps * std::max(1.0, next()); }
    void advance() {
        if (corner()) {
            x += stepX;
            y += stepY;
            tMaxX += tDeltaX;
            tMaxY += tDeltaY;
        } else if (tMaxX < tMaxY) {
            x += stepX;
            tMaxX += tDeltaX;
        } else {
            y += stepY;
            tMaxY += tDeltaY;
        }
    }
};

}  // namespace

int HeightGrid::autoCells(double extentM) {
    if (!(extentM > 0)) return kAutoMinCells;
    return int(std::clamp(std::ceil(extentM / kAutoCellM), double(kAutoMinCells), double(kAutoMaxCells)));
}

HeightGrid HeightGrid::build(const SceneModel& city, const glm::dvec3& frameOrigin, int cells) {
    const bool automatic = cells <= 0;
    cells = std::clamp(cells, 1, 8192);
    HeightGrid g;
    g._origin = frameOrigin;
    // Pass 1: bounds of everything (scene-local).
    const SceneBoxes boxes = sceneBoxes(city, frameOrigin);
    const Box2& all = boxes.all;
    const std::vector<Box2>& instBox = boxes.instances;
    if (!all.valid()) return g;  // empty
    g._boundsMin = all.lo;
    g._boundsMax = all.hi;
    double extent = std::max(all.hi.x - all.lo.x, all.hi.y - all.lo.y) + 4 * kCellMargin;
    extent = std::max(extent, 1e-3);
    if (automatic) cells = autoCells(extent);
    g._cells = cells;
    g._cellSize = extent / cells;
    g._min = glm::dvec2(all.lo.x, all.lo.y) - glm::dvec2(2 * kCellMargin);
    const size_t n = size_t(cells) * size_t(cells);
    g._maxZ.assign(n, -std::numeric_limits<float>::infinity());
    g._minZ.assign(n, std::numeric_limits<float>::infinity());
    auto splat = [&](const glm::dvec3& lo, const glm::dvec3& hi) {
        int x0 = int(std::floor((lo.x - kCellMargin - g._min.x) / g._cellSize));
        int x1 = int(std::floor((hi.x + kCellMargin - g._min.x) / g._cellSize));
        int y0 = int(std::floor((lo.y - kCellMargin - g._min.y) / g._cellSize));
        int y1 = int(std::floor((hi.y + kCellMargin - g._min.y) / g._cellSize));
        x0 = std::clamp(x0, 0, cells - 1);
        x1 = std::clamp(x1, 0, cells - 1);
        y0 = std::clamp(y0, 0, cells - 1);
        y1 = std::clamp(y1, 0, cells - 1);
        // Round heights outwards so the float grid never understates the double geometry.
        float zmax = std::nextafter(float(hi.z), std::numeric_limits<float>::infinity());
        float zmin = std::nextafter(float(lo.z), -std::numeric_limits<float>::infinity());
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                size_t i = size_t(y) * size_t(cells) + size_t(x);
                g._maxZ[i] = std::max(g._maxZ[i], zmax);
                g._minZ[i] = std::min(g._minZ[i], zmin);
            }
    };
    // Every triangle's box, then each instance's conservative box (tree crowns are compact).
    splatScene(city, frameOrigin, instBox, splat);
    // Blocks: max / min over their cells.
    g._blocks = (cells + kBlock - 1) / kBlock;
    const size_t nb = size_t(g._blocks) * size_t(g._blocks);
    g._blockMaxZ.assign(nb, -std::numeric_limits<float>::infinity());
    g._blockMinZ.assign(nb, std::numeric_limits<float>::infinity());
    for (int y = 0; y < cells; ++y)
        for (int x = 0; x < cells; ++x) {
            const size_t i = size_t(y) * size_t(cells) + size_t(x);
            const size_t b = size_t(y / kBlock) * size_t(g._blocks) + size_t(x / kBlock);
            g._blockMaxZ[b] = std::max(g._blockMaxZ[b], g._maxZ[i]);
            g._blockMinZ[b] = std::min(g._blockMinZ[b], g._minZ[i]);
        }
    return g;
}

HeightGrid HeightGrid::lattice(const glm::dvec2& worldLo, const glm::dvec2& worldHi, const glm::dvec3& frameOrigin,
                               int cells) {
    VISTA_CHECK(std::isfinite(worldLo.x) && std::isfinite(worldLo.y) && std::isfinite(worldHi.x) &&
                std::isfinite(worldHi.y) && worldLo.x <= worldHi.x && worldLo.y <= worldHi.y);
    const bool automatic = cells <= 0;
    cells = std::clamp(cells, 1, 8192);
    HeightGrid g;
    g._origin = frameOrigin;
    const glm::dvec2 lo = worldLo - glm::dvec2(frameOrigin), hi = worldHi - glm::dvec2(frameOrigin);
    g._boundsMin = glm::dvec3(kInf);  // no geometry yet
    g._boundsMax = glm::dvec3(-kInf);
    double extent = std::max(hi.x - lo.x, hi.y - lo.y) + 4 * kCellMargin;
    extent = std::max(extent, 1e-3);
    if (automatic) cells = autoCells(extent);
    g._cells = cells;
    g._cellSize = extent / cells;
    g._min = lo - glm::dvec2(2 * kCellMargin);
    const size_t n = size_t(cells) * size_t(cells);
    g._maxZ.assign(n, -std::numeric_limits<float>::infinity());
    g._minZ.assign(n, std::numeric_limits<float>::infinity());
    g._blocks = (cells + kBlock - 1) / kBlock;
    const size_t nb = size_t(g._blocks) * size_t(g._blocks);
    g._blockMaxZ.assign(nb, -std::numeric_limits<float>::infinity());
    g._blockMinZ.assign(nb, std::numeric_limits<float>::infinity());
    return g;
}

HeightPatch HeightGrid::patch(const SceneModel& city) const {
    HeightPatch p;
    if (_cells == 0) return p;
    const glm::dvec3 frameOrigin = _origin;
    // Bounds (as build()): the referenced vertices and the instances' boxes.
    const SceneBoxes boxes = sceneBoxes(city, frameOrigin);
    const Box2& all = boxes.all;
    const std::vector<Box2>& instBox = boxes.instances;
    if (!all.valid()) return p;
    p.lo = all.lo;
    p.hi = all.hi;
    const int cells = _cells;
    auto range = [&](double lo, double hi, double min, int* a, int* b) {
        *a = std::clamp(int(std::floor((lo - kCellMargin - min) / _cellSize)), 0, cells - 1);
        *b = std::clamp(int(std::floor((hi + kCellMargin - min) / _cellSize)), 0, cells - 1);
    };
    int x1 = 0, y1 = 0;
    range(all.lo.x, all.hi.x, _min.x, &p.x0, &x1);
    range(all.lo.y, all.hi.y, _min.y, &p.y0, &y1);
    p.nx = x1 - p.x0 + 1;
    p.ny = y1 - p.y0 + 1;
    p.maxZ.assign(size_t(p.nx) * size_t(p.ny), -std::numeric_limits<float>::infinity());
    p.minZ.assign(p.maxZ.size(), std::numeric_limits<float>::infinity());
    // The same cells and heights as build()'s splat.
    auto splat = [&](const glm::dvec3& lo, const glm::dvec3& hi) {
        int ax = 0, bx = 0, ay = 0, by = 0;
        range(lo.x, hi.x, _min.x, &ax, &bx);
        range(lo.y, hi.y, _min.y, &ay, &by);
        const float zmax = std::nextafter(float(hi.z), std::numeric_limits<float>::infinity());
        const float zmin = std::nextafter(float(lo.z), -std::numeric_limits<float>::infinity());
        for (int y = ay; y <= by; ++y)
            for (int x = ax; x <= bx; ++x) {
                const size_t i = size_t(y - p.y0) * size_t(p.nx) + size_t(x - p.x0);
                p.maxZ[i] = std::max(p.maxZ[i], zmax);
                p.minZ[i] = std::min(p.minZ[i], zmin);
            }
    };
    splatScene(city, frameOrigin, instBox, splat);
    return p;
}

void HeightGrid::splicePatch(const HeightPatch& p) {
    for (int y = 0; y < p.ny; ++y)
        for (int x = 0; x < p.nx; ++x) {
            const size_t i = size_t(y + p.y0) * size_t(_cells) + size_t(x + p.x0);
            const size_t k = size_t(y) * size_t(p.nx) + size_t(x);
            _maxZ[i] = std::max(_maxZ[i], p.maxZ[k]);
            _minZ[i] = std::min(_minZ[i], p.minZ[k]);
        }
}

void HeightGrid::updateBlocks(int x0, int y0, int x1, int y1) {
    for (int by = y0 / kBlock; by <= y1 / kBlock; ++by)
        for (int bx = x0 / kBlock; bx <= x1 / kBlock; ++bx) {
            float hi = -std::numeric_limits<float>::infinity(), lo = std::numeric_limits<float>::infinity();
            for (int y = by * kBlock; y < std::min(_cells, (by + 1) * kBlock); ++y)
                for (int x = bx * kBlock; x < std::min(_cells, (bx + 1) * kBlock); ++x) {
                    const size_t i = size_t(y) * size_t(_cells) + size_t(x);
                    hi = std::max(hi, _maxZ[i]);
                    lo = std::min(lo, _minZ[i]);
                }
            const size_t b = size_t(by) * size_t(_blocks) + size_t(bx);
            _blockMaxZ[b] = hi;
            _blockMinZ[b] = lo;
        }
}

void HeightGrid::updateBounds() {
    _boundsMin = glm::dvec3(kInf);
    _boundsMax = glm::dvec3(-kInf);
    for (const auto& [key, p] : _patches) {
        if (p->nx == 0) continue;
        _boundsMin = glm::min(_boundsMin, p->lo);
        _boundsMax = glm::max(_boundsMax, p->hi);
    }
}

void HeightGrid::addPatch(uint64_t key, std::shared_ptr<const HeightPatch> patch) {
    VISTA_CHECK(patch && _patches.count(key) == 0);
    VISTA_CHECK(patch->nx == 0 || (patch->x0 >= 0 && patch->y0 >= 0 && patch->x0 + patch->nx <= _cells &&
                                   patch->y0 + patch->ny <= _cells));
    const HeightPatch& p = *patch;
    _patches[key] = std::move(patch);
    if (p.nx == 0) return;
    splicePatch(p);
    updateBlocks(p.x0, p.y0, p.x0 + p.nx - 1, p.y0 + p.ny - 1);
    _boundsMin = glm::min(_boundsMin, p.lo);
    _boundsMax = glm::max(_boundsMax, p.hi);
}

void HeightGrid::removePatch(uint64_t key) {
    auto it = _patches.find(key);
    if (it == _patches.end()) return;
    const std::shared_ptr<const HeightPatch> gone = it->second;
    _patches.erase(it);
    if (gone->nx == 0) return;
    const int x0 = gone->x0, y0 = gone->y0, x1 = gone->x0 + gone->nx - 1, y1 = gone->y0 + gone->ny - 1;
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
            const size_t i = size_t(y) * size_t(_cells) + size_t(x);
            _maxZ[i] = -std::numeric_limits<float>::infinity();
            _minZ[i] = std::numeric_limits<float>::infinity();
        }
    // The other patches over the rectangle, re-splatted there.
    for (const auto& [k, p] : _patches) {
        const int ax = std::max(x0, p->x0), bx = std::min(x1, p->x0 + p->nx - 1);
        const int ay = std::max(y0, p->y0), by = std::min(y1, p->y0 + p->ny - 1);
        for (int y = ay; y <= by; ++y)
            for (int x = ax; x <= bx; ++x) {
                const size_t i = size_t(y) * size_t(_cells) + size_t(x);
                const size_t s = size_t(y - p->y0) * size_t(p->nx) + size_t(x - p->x0);
                _maxZ[i] = std::max(_maxZ[i], p->maxZ[s]);
                _minZ[i] = std::min(_minZ[i], p->minZ[s]);
            }
    }
    updateBlocks(x0, y0, x1, y1);
    updateBounds();
}

double HeightGrid::rectBound(double x0, double x1, double y0, double y1, double zLo, double zHi, const glm::dvec3& eye,
                             double nearDistance, double maxDistance) {
    if (zHi == -kInf) return -kInf;
    double nx = std::max({x0 - eye.x, 0.0, eye.x - x1}), ny = std::max({y0 - eye.y, 0.0, eye.y - y1});
    double fx = std::max(std::abs(eye.x - x0), std::abs(eye.x - x1)),
           fy = std::max(std::abs(eye.y - y0), std::abs(eye.y - y1));
    double dmin2 = nx * nx + ny * ny, dmax2 = fx * fx + fy * fy;
    if (dmin2 > maxDistance * maxDistance) return -kInf;
    double dz = zHi - eye.z;
    if (nearDistance > 0) {
        double dzLo = zLo - eye.z;
        double dzMax = std::max(std::abs(dz), std::abs(dzLo));
        if (dmax2 + dzMax * dzMax < nearDistance * nearDistance) return -kInf;
    }
    if (dz >= 0) return dmin2 > 0 ? dz / std::sqrt(dmin2) : kInf;
    return dz / std::sqrt(dmax2);
}

double HeightGrid::cellBound(int ix, int iy, const glm::dvec3& eye, double nearDistance, double maxDistance) const {
    const size_t i = size_t(iy) * size_t(_cells) + size_t(ix);
    const double x0 = _min.x + ix * _cellSize - kCellMargin, y0 = _min.y + iy * _cellSize - kCellMargin;
    return rectBound(x0, x0 + _cellSize + 2 * kCellMargin, y0, y0 + _cellSize + 2 * kCellMargin, double(_minZ[i]),
                     double(_maxZ[i]), eye, nearDistance, maxDistance);
}

// A block's rectangle contains its cells' rectangles and its heights bound
// theirs, so its bound is >= each cell's (nearer or equal nearest point,
// farther or equal farthest point, higher or equal top).
double HeightGrid::blockBound(int bx, int by, const glm::dvec3& eye, double nearDistance, double maxDistance) const {
    const size_t b = size_t(by) * size_t(_blocks) + size_t(bx);
    const double x0 = _min.x + bx * kBlock * _cellSize - kCellMargin;
    const double x1 = _min.x + std::min(_cells, (bx + 1) * kBlock) * _cellSize + kCellMargin;
    const double y0 = _min.y + by * kBlock * _cellSize - kCellMargin;
    const double y1 = _min.y + std::min(_cells, (by + 1) * kBlock) * _cellSize + kCellMargin;
    return rectBound(x0, x1, y0, y1, double(_blockMinZ[b]), double(_blockMaxZ[b]), eye, nearDistance, maxDistance);
}

double HeightGrid::traceRay(const glm::dvec3& eye, double azimuth, double nearDistance, double maxDistance) const {
    return trace(eye, azimuth, nearDistance, maxDistance, true);
}

double HeightGrid::traceRayFlat(const glm::dvec3& eye, double azimuth, double nearDistance, double maxDistance) const {
    return trace(eye, azimuth, nearDistance, maxDistance, false);
}

// One ray's walk over the grid in cell units: the bound `best` of every cell
// the ray touches, walked cell by cell or block by block, stopping once no
// later cell can beat it.
class HeightGrid::RayTrace {
public:
    RayTrace(const HeightGrid& g, const glm::dvec3& eye, double azimuth, double nearDistance, double maxDistance)
        : _g(g),
          _eye(eye),
          _nearDistance(nearDistance),
          _maxDistance(maxDistance),
          _n(g._cells),
          _s(g._cellSize),
          _px((eye.x - g._min.x) / g._cellSize),
          _py((eye.y - g._min.y) / g._cellSize),
          _dx(std::sin(azimuth)),
          _dy(std::cos(azimuth)) {
        if (std::abs(_dx) < 1e-15) _dx = 0;
        if (std::abs(_dy) < 1e-15) _dy = 0;
    }

    // Clips the ray (t >= 0) against the grid square [0, n]^2; false when it misses.
    bool clipToGrid() {
        if (!clip(_px, _dx) || !clip(_py, _dy)) return false;
        _sx0 = _px + _dx * _t0;
        _sy0 = _py + _dy * _t0;
        _tLen = _t1 - _t0;
        return true;
    }

    // Walks from the start cell (over blocks or every cell), then visits the
    // cells a ray along a grid line or starting on one touches; returns the bound.
    double walk(bool blocks) {
        const int n = _n;
        // Start cell: the cell the ray enters just after t0.
        const double ex = _px + _dx * _t0, ey = _py + _dy * _t0;
        int ix = cellAt(ex, _dx, 0, n - 1), iy = cellAt(ey, _dy, 0, n - 1);
        if (blocks) runBlocks(ix, iy);
        else run(ix, iy);
        // A ray running along a grid line touches the cells on both sides.
        if (_dx == 0 && onLine(ex)) {
            int l = int(std::round(ex));
            if (l - 1 >= 0 && l - 1 != ix) run(l - 1, iy);
            if (l < n && l != ix) run(l, iy);
        }
        if (_dy == 0 && onLine(ey)) {
            int l = int(std::round(ey));
            if (l - 1 >= 0 && l - 1 != iy) run(ix, l - 1);
            if (l < n && l != iy) run(ix, l);
        }
        // Starting on a corner/line (eye on a grid line): the neighbour cells the
        // start point touches may hold geometry arbitrarily close to the ray start.
        if (onLine(ex) || onLine(ey)) {
            int cx = int(std::round(ex)), cy = int(std::round(ey));
            for (int yy = (onLine(ey) ? cy - 1 : iy); yy <= (onLine(ey) ? cy : iy); ++yy)
                for (int xx = (onLine(ex) ? cx - 1 : ix); xx <= (onLine(ex) ? cx : ix); ++xx)
                    if (xx >= 0 && yy >= 0 && xx < n && yy < n)
                        _best = std::max(_best, _g.cellBound(xx, yy, _eye, _nearDistance, _maxDistance));
        }
        return _best;
    }

private:
    // Narrows [t0, t1] to where the ray's coordinate p + d * t lies in [0, n].
    bool clip(double p, double d) {
        if (d == 0) return p >= 0 && p <= _n;
        double a = (0 - p) / d, b = (_n - p) / d;
        if (a > b) std::swap(a, b);
        _t0 = std::max(_t0, a);
        _t1 = std::min(_t1, b);
        return _t0 <= _t1;
    }

    // The cell (clamped to [lo, hi]) of coordinate p; on a line heading down, the lower cell.
    static int cellAt(double p, double d, int lo, int hi) {
        double c = std::floor(p);
        if (d < 0 && c == p) c -= 1;
        return std::clamp(int(c), lo, hi);
    }

    static bool onLine(double p) { return std::abs(p - std::round(p)) <= kTieEps * std::max(1.0, std::abs(p)); }

    bool inGrid(int x, int y) const { return x >= 0 && y >= 0 && x < _n && y < _n; }

    void visit(int x, int y) {
        if (inGrid(x, y)) _best = std::max(_best, _g.cellBound(x, y, _eye, _nearDistance, _maxDistance));
    }

    // Visits the four cells around grid corner (qx, qy).
    void visitAround(int qx, int qy) {
        visit(qx - 1, qy - 1);
        visit(qx, qy - 1);
        visit(qx - 1, qy);
        visit(qx, qy);
    }

    // Nothing touched after ray parameter tNext can beat `best` (farther is
    // lower when best > 0), or it all lies beyond the distance limit.
    bool laterCellsLose(double tNext) const {
        const double distM = (_t0 + tNext - 1.5) * _s - 2 * kCellMargin;  // nearest point of any later cell
        return (_best > 0 && distM > 0 && (_zTop - _eye.z) / distM < _best) || distM > _maxDistance;
    }

    // The cells from (w.x, w.y) up to ray parameter tStop; with a block
    // (bx >= 0) only while inside it, without one also stopping early.
    void walkCells(GridWalk w, double tStop, int bx, int by) {
        const double eps = kTieEps * (bx < 0 ? 1.0 : std::max(1.0, tStop));
        while (inGrid(w.x, w.y) && (bx < 0 || (w.x / kBlock == bx && w.y / kBlock == by))) {
            visit(w.x, w.y);
            const double tNext = w.next();
            if (tNext > tStop + eps) break;
            if (bx < 0 && laterCellsLose(tNext)) break;
            if (w.corner()) {  // through a grid corner: both side cells touch the ray
                visit(w.x + w.stepX, w.y);
                visit(w.x, w.y + w.stepY);
            }
            w.advance();
        }
    }

    void run(int ix, int iy) { walkCells(GridWalk(ix, iy, _sx0, _sy0, _dx, _dy, 1.0), _tLen, -1, -1); }

    // The same walk over blocks of kBlock x kBlock cells: a block whose bound
    // cannot beat `best` is passed over whole; otherwise its cells along the
    // ray's stretch [tIn, tOut] inside it are walked as in run(). A ray
    // through a block corner, or entering a block through a cell corner,
    // touches the four cells around that corner.
    void runBlocks(int ix, int iy) {
        const int n = _n;
        GridWalk b(ix / kBlock, iy / kBlock, _sx0, _sy0, _dx, _dy, double(kBlock));
        double tIn = 0;
        bool first = true;
        while (b.x >= 0 && b.y >= 0 && b.x < _g._blocks && b.y < _g._blocks) {
            const double tOut = std::min(b.next(), _tLen);
            if (_g.blockBound(b.x, b.y, _eye, _nearDistance, _maxDistance) > _best) {
                int cx = ix, cy = iy;
                if (!first) {  // where the ray enters the block
                    const double qx = _sx0 + _dx * tIn, qy = _sy0 + _dy * tIn;
                    cx = cellAt(qx, _dx, b.x * kBlock, std::min(n, (b.x + 1) * kBlock) - 1);
                    cy = cellAt(qy, _dy, b.y * kBlock, std::min(n, (b.y + 1) * kBlock) - 1);
                    if (onLine(qx) && onLine(qy)) visitAround(int(std::round(qx)), int(std::round(qy)));
                }
                walkCells(GridWalk(cx, cy, _sx0, _sy0, _dx, _dy, 1.0), tOut, b.x, b.y);
            }
            first = false;
            const double tNext = b.next();
            if (tNext > _tLen + kTieEps || laterCellsLose(tNext)) break;
            tIn = tNext;
            if (b.corner())
                visitAround(b.stepX > 0 ? (b.x + 1) * kBlock : b.x * kBlock,
                            b.stepY > 0 ? (b.y + 1) * kBlock : b.y * kBlock);
            b.advance();
        }
    }

    const HeightGrid& _g;
    const glm::dvec3 _eye;
    const double _nearDistance, _maxDistance;
    const int _n;
    const double _s;
    const double _px, _py;  // the eye in cell units
    double _dx, _dy;
    double _t0 = 0, _t1 = kInf;
    // Highest geometry anywhere: bounds the remaining cells for early exit.
    const double _zTop = _g._boundsMax.z + 1e-3;
    double _best = -kInf;
    double _sx0 = 0, _sy0 = 0, _tLen = 0;
};

double HeightGrid::trace(const glm::dvec3& eye, double azimuth, double nearDistance, double maxDistance,
                         bool blocks) const {
    if (_cells == 0) return -kInf;
    RayTrace ray(*this, eye, azimuth, nearDistance, maxDistance);
    if (!ray.clipToGrid()) return -kInf;
    return ray.walk(blocks);
}

bool horizonApplies(const Camera& camera, std::string* reason) {
    if (!camera.upright()) {
        if (reason) *reason = "horizon off: camera rolled";
        return false;
    }
    if (std::abs(camera.pitch) + 0.5 * camera.fovY >= kHalfPi - 1e-3) {
        if (reason) *reason = camera.pitch > 0 ? "horizon off: zenith in view" : "horizon off: nadir in view";
        return false;
    }
    return true;
}

namespace {

struct ColumnGeometry {
    double cp, sp, t, aspect;
    int W, H;
    ColumnGeometry(const Camera& c)
        : cp(std::cos(c.pitch)),
          sp(std::sin(c.pitch)),
          t(std::tan(0.5 * c.fovY)),
          aspect(double(c.width) / double(c.height)),
          W(c.width),
          H(c.height) {}
    double sx(double px) const { return (2.0 * px / W - 1.0) * t * aspect; }
    double sy(double py) const { return (1.0 - 2.0 * py / H) * t; }
    // Azimuth relative to the heading, and tan(elevation), of the ray through (px, py).
    double relAzimuth(double px, double py) const { return std::atan2(sx(px), cp - sy(py) * sp); }
    double tanElev(double px, double py) const {
        double a = cp - sy(py) * sp, b = sx(px);
        return (sp + sy(py) * cp) / std::sqrt(a * a + b * b);
    }
};

}  // namespace

double pixelTanElevation(const Camera& camera, double px, double py) {
    glm::dvec3 d = camera.rayDirection(px, py);
    double h = std::sqrt(d.x * d.x + d.y * d.y);
    return h > 0 ? d.z / h : (d.z > 0 ? kInf : -kInf);
}

HorizonResult traceHorizon(const HeightGrid& grid, const Camera& camera, const HorizonOptions& options) {
    VISTA_CHECK(camera.width >= 1 && camera.height >= 1);
    const int W = camera.width, H = camera.height;
    HorizonResult r;
    r.row.assign(size_t(W), 0);
    if (!horizonApplies(camera, &r.reason)) return r;
    r.active = true;
    auto needed = [&](int x) { return !options.columnNeeded || (*options.columnNeeded)[size_t(x)] != 0; };
    if (grid.empty()) {  // no geometry anywhere: every pixel is sky
        for (int x = 0; x < W; ++x) r.row[size_t(x)] = H;
        return r;
    }
    const ColumnGeometry cg(camera);
    const glm::dvec3 eye = camera.eye - grid.frameOrigin() - glm::dvec3(0.0, 0.0, std::max(0.0, options.lift));
    // Azimuth range of each needed column (pixel centres, top and bottom rows).
    std::vector<double> lo(static_cast<size_t>(W)), hi(static_cast<size_t>(W));
    double relMin = kInf, relMax = -kInf;
    for (int x = 0; x < W; ++x) {
        if (!needed(x)) continue;
        double a = cg.relAzimuth(x + 0.5, 0.5), b = cg.relAzimuth(x + 0.5, H - 0.5);
        lo[size_t(x)] = std::min(a, b);
        hi[size_t(x)] = std::max(a, b);
        relMin = std::min(relMin, lo[size_t(x)]);
        relMax = std::max(relMax, hi[size_t(x)]);
    }
    if (relMin > relMax) return r;  // no column needed
    // Ray spacing: wedge width at the farthest grid point below half a cell.
    const double s = grid.cellSize();
    const glm::dvec2 g0 = grid.gridMin(), g1 = g0 + glm::dvec2(s * grid.cells());
    double dmax = 0;
    for (int c = 0; c < 4; ++c) {
        glm::dvec2 corner((c & 1) ? g1.x : g0.x, (c & 2) ? g1.y : g0.y);
        dmax = std::max(dmax, glm::length(corner - glm::dvec2(eye.x, eye.y)));
    }
    const double delta = 0.5 * s / std::max(dmax, s);
    const int sub = std::max(1, options.subsample);
    const double a0 = relMin - delta;
    const double span = relMax - relMin + 2 * delta;
    const int64_t nRays64 = int64_t(std::ceil(span / delta)) + 2;
    if (nRays64 > (int64_t(1) << 22)) {
        r.active = false;
        r.reason = "horizon off: too many horizon rays for this grid";
        return r;
    }
    const int nRays = int(nRays64);
    // Which rays are needed: per column [kLo, kHi] widened to the subsampling lattice.
    std::vector<int> kLo(static_cast<size_t>(W)), kHi(static_cast<size_t>(W));
    std::vector<uint8_t> want(size_t(nRays) + size_t(sub) + 1, 0);
    for (int x = 0; x < W; ++x) {
        if (!needed(x)) continue;
        int a = int(std::floor((lo[size_t(x)] - a0) / delta)), b = int(std::ceil((hi[size_t(x)] - a0) / delta));
        a = std::max(0, (a / sub) * sub);
        b = std::min(int(want.size()) - 1, ((b + sub - 1) / sub) * sub);
        kLo[size_t(x)] = a;
        kHi[size_t(x)] = b;
        for (int k = a; k <= b; k += sub) want[size_t(k)] = 1;
    }
    std::vector<int> list;
    for (int k = 0; k < int(want.size()); ++k)
        if (want[size_t(k)]) list.push_back(k);
    // Per 2D ray: the horizontal distance its columns' pixels reach before
    // the eye-plane depth limit (|d_xy| / (d . forward) per unit depth is
    // monotonic along a column: its top and bottom pixels bound it).
    std::vector<double> reach(want.size(), options.maxDistance);
    if (std::isfinite(options.maxEyeDepth)) {
        std::fill(reach.begin(), reach.end(), 0.0);
        const glm::dvec3 fwd = camera.forward();
        auto horizontalReach = [&](double px, double py) {
            const glm::dvec3 d = camera.rayDirection(px, py);
            return options.maxEyeDepth * std::sqrt(d.x * d.x + d.y * d.y) / std::max(glm::dot(d, fwd), 1e-9);
        };
        for (int x = 0; x < W; ++x) {
            if (!needed(x)) continue;
            const double rx = std::max(horizontalReach(x + 0.5, 0.5), horizontalReach(x + 0.5, H - 0.5)) * (1.0 + 1e-6);
            for (int k = kLo[size_t(x)]; k <= kHi[size_t(x)]; k += sub)
                reach[size_t(k)] = std::max(reach[size_t(k)], rx);
        }
        for (double& v : reach) v = std::min(v, options.maxDistance);
    }
    std::vector<double> value(want.size(), -kInf);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, list.size(), 16), [&](const tbb::blocked_range<size_t>& br) {
        for (size_t i = br.begin(); i != br.end(); ++i) {
            int k = list[i];
            value[size_t(k)] =
                grid.traceRay(eye, camera.heading + a0 + k * delta, options.nearDistance, reach[size_t(k)]);
        }
    });
    r.raysTraced = int(list.size());
    // Per column: bound -> first row whose centre ray may reach geometry.
    for (int x = 0; x < W; ++x) {
        if (!needed(x)) continue;
        double bound = -kInf;
        for (int k = kLo[size_t(x)]; k <= kHi[size_t(x)]; k += sub) bound = std::max(bound, value[size_t(k)]);
        if (bound == kInf) {
            r.row[size_t(x)] = 0;
            continue;
        }
        if (bound == -kInf) {  // nothing in the column's wedge (beyond the near distance): all sky
            r.row[size_t(x)] = H;
            continue;
        }
        const double limit = bound + 1e-9 * (1.0 + std::abs(bound));
        // tanElev decreases with y: binary search for the first y with tanElev <= limit.
        int a = 0, b = H;
        while (a < b) {
            int m = (a + b) / 2;
            if (cg.tanElev(x + 0.5, m + 0.5) > limit) a = m + 1;
            else b = m;
        }
        r.row[size_t(x)] = a;
    }
    return r;
}

}  // namespace vista
