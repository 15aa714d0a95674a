#include "nodes/view_cell_switch.h"

#include <algorithm>
#include <cmath>

#include <osg/NodeVisitor>
#include <osgDB/InputStream>
#include <osgDB/ObjectWrapper>
#include <osgDB/OutputStream>

namespace vista {

bool ViewCellBox::contains(const glm::dvec3& p, double eps) const {
    const glm::dvec3 d = p - center;
    const double u = d.x * axis.x + d.y * axis.y;
    const double v = -d.x * axis.y + d.y * axis.x;
    return std::abs(u) <= halfLength + eps && std::abs(v) <= halfWidth + eps && std::abs(d.z) <= halfHeight + eps;
}

void ViewCellBox::corners(glm::dvec3 out[8]) const {
    const glm::dvec2 s = side();
    for (int i = 0; i < 8; ++i) {
        const double a = (i & 1) ? halfLength : -halfLength;
        const double b = (i & 2) ? halfWidth : -halfWidth;
        const double c = (i & 4) ? halfHeight : -halfHeight;
        out[i] = center + glm::dvec3(axis.x * a + s.x * b, axis.y * a + s.y * b, c);
    }
}

void ViewCellBox::boundsXY(glm::dvec2& lo, glm::dvec2& hi) const {
    const double ex = std::abs(axis.x) * halfLength + std::abs(axis.y) * halfWidth;
    const double ey = std::abs(axis.y) * halfLength + std::abs(axis.x) * halfWidth;
    lo = glm::dvec2(center.x - ex, center.y - ey);
    hi = glm::dvec2(center.x + ex, center.y + ey);
}

void ViewCellGrid::build(const std::vector<ViewCellBox>& cells, double binSize) {
    _cells = cells;
    _start.clear();
    _items.clear();
    _nx = _ny = 0;
    if (cells.empty()) return;
    glm::dvec2 lo(1e300), hi(-1e300);
    double avg = 0;
    size_t used = 0;
    for (const auto& c : cells) {
        if (!(c.halfHeight > 0)) continue;  // absent cell (no street edge / degenerate)
        ++used;
        glm::dvec2 a, b;
        c.boundsXY(a, b);
        lo = glm::min(lo, a);
        hi = glm::max(hi, b);
        avg += std::max(b.x - a.x, b.y - a.y);
    }
    if (used == 0) return;
    avg /= double(used);
    _bin = binSize > 0 ? binSize : std::max(avg, 1.0);
    // Keep the grid modest (<= 1M bins) whatever the input.
    while (((hi.x - lo.x) / _bin + 1) * ((hi.y - lo.y) / _bin + 1) > 1e6) _bin *= 2;
    _lo = lo;
    _nx = int((hi.x - lo.x) / _bin) + 1;
    _ny = int((hi.y - lo.y) / _bin) + 1;
    std::vector<std::vector<uint32_t>> bins(size_t(_nx) * size_t(_ny));
    for (size_t i = 0; i < cells.size(); ++i) {
        if (!(cells[i].halfHeight > 0)) continue;
        glm::dvec2 a, b;
        cells[i].boundsXY(a, b);
        const int x0 = std::clamp(int((a.x - lo.x) / _bin), 0, _nx - 1),
                  x1 = std::clamp(int((b.x - lo.x) / _bin), 0, _nx - 1);
        const int y0 = std::clamp(int((a.y - lo.y) / _bin), 0, _ny - 1),
                  y1 = std::clamp(int((b.y - lo.y) / _bin), 0, _ny - 1);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) bins[size_t(y) * size_t(_nx) + size_t(x)].push_back(uint32_t(i));
    }
    _start.resize(bins.size() + 1);
    _start[0] = 0;
    for (size_t b = 0; b < bins.size(); ++b) {
        _items.insert(_items.end(), bins[b].begin(), bins[b].end());  // ascending ids per bin
        _start[b + 1] = uint32_t(_items.size());
    }
}

int ViewCellGrid::find(const glm::dvec3& p) const {
    if (_nx == 0 || !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return -1;
    const double fx = (p.x - _lo.x) / _bin, fy = (p.y - _lo.y) / _bin;
    if (fx < 0 || fy < 0 || fx >= _nx || fy >= _ny) return -1;
    const size_t b = size_t(int(fy)) * size_t(_nx) + size_t(int(fx));
    for (uint32_t k = _start[b]; k < _start[b + 1]; ++k)
        if (_cells[_items[k]].contains(p)) return int(_items[k]);
    return -1;
}

ViewCellSwitch::ViewCellSwitch()
    : _cellData(new osg::DoubleArray),
      _hiddenStart(new osg::UIntArray),
      _hiddenItems(new osg::UIntArray),
      _impStart(new osg::UIntArray),
      _impItems(new osg::UIntArray) {
    _hiddenStart->push_back(0);
    _impStart->push_back(0);
}

ViewCellSwitch::ViewCellSwitch(const ViewCellSwitch& o, const osg::CopyOp& op)
    : osg::Group(o, op),
      _cells(o._cells),
      _grid(o._grid),
      _cellData(o._cellData),
      _hiddenStart(o._hiddenStart),
      _hiddenItems(o._hiddenItems),
      _impStart(o._impStart),
      _impItems(o._impItems),
      _tileCount(o._tileCount),
      _forced(o._forced),
      _impostorsOn(o._impostorsOn),
      _nearestFallback(o._nearestFallback),
      _chunkNodes(o._chunkNodes),
      _chunkTile(o._chunkTile),
      _chunkBoxes(o._chunkBoxes),
      _chunkNear(o._chunkNear) {}

void ViewCellSwitch::setNearChunks(const NearFieldScene& nf, double nearDistance) {
    _chunkNodes.clear();
    _chunkTile.clear();
    _chunkBoxes.clear();
    _chunkNear = std::max(0.0, nearDistance);
    const size_t n = nf.chunks.size();
    if (nf.objects.size() != n) return;  // not a chunking: keep the whole tiles
    for (uint32_t i : nf.drawOrder) {
        if (i >= n || !nf.chunks[i]) continue;
        _chunkNodes.push_back(nf.chunks[i]);
        _chunkTile.push_back(i < nf.chunkTile.size() ? nf.chunkTile[i] : -1);
        _chunkBoxes.push_back(nf.objects[i]);
    }
}

void ViewCellSwitch::setCells(const std::vector<ViewCellBox>& cells) {
    osg::ref_ptr<osg::DoubleArray> a = new osg::DoubleArray;
    for (const auto& c : cells) {
        const double v[9] = {c.center.x,   c.center.y,  c.center.z,   c.axis.x, c.axis.y,
                             c.halfLength, c.halfWidth, c.halfHeight, 0.0};
        a->insert(a->end(), v, v + 9);
    }
    setCellData(a.get());
    _hiddenStart = new osg::UIntArray(unsigned(cells.size() + 1));
    _impStart = new osg::UIntArray(unsigned(cells.size() + 1));
    _hiddenItems = new osg::UIntArray;
    _impItems = new osg::UIntArray;
}

void ViewCellSwitch::setCellData(osg::DoubleArray* a) {
    _cellData = a ? a : new osg::DoubleArray;
    _cells.clear();
    const size_t n = _cellData->size() / 9;
    for (size_t i = 0; i < n; ++i) {
        const double* v = &(*_cellData)[i * 9];
        ViewCellBox c;
        c.center = glm::dvec3(v[0], v[1], v[2]);
        c.axis = glm::dvec2(v[3], v[4]);
        c.halfLength = v[5];
        c.halfWidth = v[6];
        c.halfHeight = v[7];
        _cells.push_back(c);
    }
    _grid.build(_cells);
}

static void csrSet(osg::ref_ptr<osg::UIntArray>& start, osg::ref_ptr<osg::UIntArray>& items, uint32_t cell,
                   const std::vector<uint32_t>& list) {
    // Rebuild the CSR list with `cell` replaced (cells are few; this is not hot).
    std::vector<std::vector<uint32_t>> all(start->size() - 1);
    for (size_t c = 0; c + 1 < start->size(); ++c)
        for (uint32_t k = (*start)[c]; k < (*start)[c + 1]; ++k) all[c].push_back((*items)[k]);
    all[cell] = list;
    osg::ref_ptr<osg::UIntArray> s = new osg::UIntArray, it = new osg::UIntArray;
    s->push_back(0);
    for (const auto& l : all) {
        it->insert(it->end(), l.begin(), l.end());
        s->push_back(unsigned(it->size()));
    }
    start = s;
    items = it;
}

void ViewCellSwitch::setCellChildren(uint32_t cell, const std::vector<uint32_t>& hidden,
                                     const std::vector<uint32_t>& impostors) {
    rebuildLists(cell, hidden, impostors);
}

void ViewCellSwitch::rebuildLists(uint32_t cell, const std::vector<uint32_t>& hidden,
                                  const std::vector<uint32_t>& impostors) {
    if (cell >= _cells.size()) return;
    csrSet(_hiddenStart, _hiddenItems, cell, hidden);
    csrSet(_impStart, _impItems, cell, impostors);
}

static std::vector<uint32_t> csrGet(const osg::UIntArray* start, const osg::UIntArray* items, uint32_t cell) {
    std::vector<uint32_t> out;
    if (!start || !items || cell + 1 >= start->size()) return out;
    const uint32_t a = (*start)[cell], b = (*start)[cell + 1];
    for (uint32_t k = a; k < b && k < items->size(); ++k) out.push_back((*items)[k]);
    return out;
}

std::vector<uint32_t> ViewCellSwitch::hiddenOf(uint32_t cell) const {
    return csrGet(_hiddenStart.get(), _hiddenItems.get(), cell);
}
std::vector<uint32_t> ViewCellSwitch::impostorsOf(uint32_t cell) const {
    return csrGet(_impStart.get(), _impItems.get(), cell);
}

std::string ViewCellSwitch::validate() const {
    const size_t n = _cells.size();
    if (_cellData->size() % 9 != 0)
        return "cell data size " + std::to_string(_cellData->size()) + " is not a multiple of 9";
    for (size_t i = 0; i < n; ++i) {
        const auto& c = _cells[i];
        const double len = glm::length(c.axis);
        if (c.halfHeight == 0 && c.halfLength == 0 && c.halfWidth == 0) continue;  // absent cell
        if (!(std::abs(len - 1.0) < 1e-6) || !(c.halfLength >= 0) || !(c.halfWidth >= 0) || !(c.halfHeight >= 0) ||
            !std::isfinite(c.center.x + c.center.y + c.center.z))
            return "cell " + std::to_string(i) + " is not a valid box";
    }
    if (_tileCount > getNumChildren()) return "tile count " + std::to_string(_tileCount) + " exceeds the child count";
    auto checkCsr = [&](const osg::UIntArray* s, const osg::UIntArray* it, const char* what,
                        bool tiles) -> std::string {
        if (!s || !it || s->size() != n + 1) return std::string(what) + ": list count does not match the cell count";
        if ((*s)[0] != 0 || (*s)[n] != it->size()) return std::string(what) + ": list offsets are inconsistent";
        for (size_t c = 0; c < n; ++c)
            if ((*s)[c] > (*s)[c + 1])
                return std::string(what) + ": list offsets decrease at cell " + std::to_string(c);
        for (unsigned v : *it) {
            if (tiles ? v >= _tileCount : (v < _tileCount || v >= getNumChildren()))
                return std::string(what) + ": child index " + std::to_string(v) + " out of range";
        }
        return {};
    };
    std::string e = checkCsr(_hiddenStart.get(), _hiddenItems.get(), "hidden tiles", true);
    if (!e.empty()) return e;
    return checkCsr(_impStart.get(), _impItems.get(), "impostors", false);
}

int ViewCellSwitch::nearestCell(const glm::dvec3& p) const {
    int best = -1;
    double bestD = 1e300;
    for (size_t c = 0; c < _cells.size(); ++c) {
        const ViewCellBox& b = _cells[c];
        if (!(b.halfLength > 0) || !(b.halfWidth > 0)) continue;
        const glm::dvec3 d = p - b.center;
        const double a = std::max(std::abs(d.x * b.axis.x + d.y * b.axis.y) - b.halfLength, 0.0);
        const double s = std::max(std::abs(-d.x * b.axis.y + d.y * b.axis.x) - b.halfWidth, 0.0);
        const double z = std::max(std::abs(d.z) - b.halfHeight, 0.0);
        const double dist = a * a + s * s + z * z;
        if (dist < bestD) {
            bestD = dist;
            best = int(c);
        }
    }
    return best;
}

void ViewCellSwitch::traverse(osg::NodeVisitor& nv) {
    const unsigned nChildren = getNumChildren();
    const unsigned tiles = std::min(_tileCount, nChildren);
    if (nv.getVisitorType() != osg::NodeVisitor::CULL_VISITOR) {
        for (unsigned i = 0; i < tiles; ++i) _children[i]->accept(nv);
        return;
    }
    int cell = _forced;
    if (cell == -2) {
        const osg::Vec3 e = nv.getEyePoint();
        cell = _grid.find(glm::dvec3(e.x(), e.y(), e.z()));
        if (cell < 0 && _nearestFallback) cell = nearestCell(glm::dvec3(e.x(), e.y(), e.z()));
    }
    if (cell >= int(_cells.size())) cell = -1;
    _lastCell = cell;
    if (!_chunkNodes.empty()) {
        const bool inCell = cell >= 0 && _impostorsOn;
        _hiddenMask.assign(tiles, 0);
        if (inCell) {
            const uint32_t hs = (*_hiddenStart)[size_t(cell)], he = (*_hiddenStart)[size_t(cell) + 1];
            for (uint32_t k = hs; k < he && k < _hiddenItems->size(); ++k)
                if ((*_hiddenItems)[k] < tiles) _hiddenMask[(*_hiddenItems)[k]] = 1;
        }
        const osg::Vec3 e = nv.getEyePoint();
        const glm::dvec3 eye(e.x(), e.y(), e.z());
        unsigned drawn = 0;
        for (size_t k = 0; k < _chunkNodes.size(); ++k) {
            const int32_t t = _chunkTile[k];
            if (inCell && t >= 0 && unsigned(t) < tiles && _hiddenMask[size_t(t)] &&
                boxDistance(_chunkBoxes[k], eye) > _chunkNear)
                continue;
            _chunkNodes[k]->accept(nv);
            ++drawn;
        }
        _lastChunks = drawn;
        if (!inCell) return;
        const uint32_t is = (*_impStart)[size_t(cell)], ie = (*_impStart)[size_t(cell) + 1];
        for (uint32_t j = is; j < ie && j < _impItems->size(); ++j) {
            const unsigned c = (*_impItems)[j];
            if (c < nChildren) _children[c]->accept(nv);
        }
        return;
    }
    if (cell < 0 || !_impostorsOn) {
        for (unsigned i = 0; i < tiles; ++i) _children[i]->accept(nv);
        return;
    }
    const uint32_t hs = (*_hiddenStart)[size_t(cell)], he = (*_hiddenStart)[size_t(cell) + 1];
    // Hidden lists are ascending: walk them alongside the tiles.
    uint32_t k = hs;
    for (unsigned i = 0; i < tiles; ++i) {
        while (k < he && k < _hiddenItems->size() && (*_hiddenItems)[k] < i) ++k;
        if (k < he && k < _hiddenItems->size() && (*_hiddenItems)[k] == i) continue;
        _children[i]->accept(nv);
    }
    const uint32_t is = (*_impStart)[size_t(cell)], ie = (*_impStart)[size_t(cell) + 1];
    for (uint32_t j = is; j < ie && j < _impItems->size(); ++j) {
        const unsigned c = (*_impItems)[j];
        if (c < nChildren) _children[c]->accept(nv);
    }
}

}  // namespace vista

// osgDB serializer: class "vista::ViewCellSwitch". Stock osgviewer finds it
// through the osgdb_vista plugin (library name derived from the "vista::" prefix).
REGISTER_OBJECT_WRAPPER(vista_ViewCellSwitch, new vista::ViewCellSwitch, vista::ViewCellSwitch,
                        "osg::Object osg::Node osg::Group vista::ViewCellSwitch") {
    ADD_UINT_SERIALIZER(TileCountProp, 0);
    ADD_OBJECT_SERIALIZER(CellData, osg::DoubleArray, NULL);
    ADD_OBJECT_SERIALIZER(HiddenStart, osg::UIntArray, NULL);
    ADD_OBJECT_SERIALIZER(HiddenItems, osg::UIntArray, NULL);
    ADD_OBJECT_SERIALIZER(ImpostorStart, osg::UIntArray, NULL);
    ADD_OBJECT_SERIALIZER(ImpostorItems, osg::UIntArray, NULL);
}
