// ViewCellSwitch: the root of a baked city. In a view cell it draws the near
// geometry plus the cell's point impostors and skips the tiles they replace;
// outside every cell it draws the city as it is.
//
// Plain part (no OSG): ViewCellBox (an oriented box, world metres, double)
// and ViewCellGrid (a uniform 2D grid over the cells' xy bounds for a fast
// "which cell contains the viewer" lookup). The lookup returns the LOWEST
// cell id that contains the point (cells overlap at street intersections), so
// the answer never depends on build order or timing. Pure; thread-safe after
// build().
//
// Node: children [0, tileCount) are the city tiles (osg::MatrixTransform
// "tile_IX_IY", as written by buildCityScene), children [tileCount, n) are
// impostor nodes. Per cell: a list of tile children to hide and a list of
// impostor children to draw (indices into the children). The cull traversal
// picks the cell from the eye point (node-local = world frame); every other
// traversal (update, intersection, ...) sees the tiles only. The lookup can be
// forced (setForcedCell) and impostors switched off (setImpostorsEnabled) for
// measurements.
//
// Near-field chunks (run time, not serialized; the baked render modes set
// them): with setNearChunks() the cull traversal draws the city as the 40 m
// chunks of the shared near-field chunking (nodes/near_field_chunks.h, the
// chunks `full` and `hybrid` draw) instead of the whole 250 m tiles, so OSG
// culls them against the frustum chunk by chunk. In a cell a chunk of a
// replaced (hidden) tile is skipped unless its box comes within the near
// distance of the eye (the test and distance of hybrid's near field,
// selectNearField): beyond it the cell's far representation stands in.
// Chunks of tiles the cell does not replace are drawn (frustum culled), so the
// drawn chunks are always a subset of what `full` draws. Outside every cell
// (or impostors off): every chunk, as `full`. Serialized by osgDB (wrapper "vista::ViewCellSwitch", in
// view_cell_switch.cpp); bad per-cell indices in a loaded file are reported
// by validate(), never dereferenced.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <osg/Array>
#include <osg/Group>

#include "nodes/near_field_chunks.h"

namespace vista {

struct ViewCellBox {
    glm::dvec3 center{0.0};     // world position of the box centre
    glm::dvec2 axis{1.0, 0.0};  // unit vector along the street (node a -> node b)
    double halfLength = 0;      // along axis
    double halfWidth = 0;       // across the street
    double halfHeight = 0;      // vertical

    glm::dvec2 side() const { return {-axis.y, axis.x}; }  // left of axis
    bool contains(const glm::dvec3& p, double eps = 0.0) const;
    // The 8 corners (bit 0: +axis, bit 1: +side, bit 2: +z).
    void corners(glm::dvec3 out[8]) const;
    void boundsXY(glm::dvec2& lo, glm::dvec2& hi) const;
};

class ViewCellGrid {
public:
    // binSize <= 0 picks a bin about the size of the average cell.
    void build(const std::vector<ViewCellBox>& cells, double binSize = 0.0);
    // Lowest index of a cell containing p, or -1.
    int find(const glm::dvec3& p) const;
    size_t size() const { return _cells.size(); }

private:
    std::vector<ViewCellBox> _cells;
    glm::dvec2 _lo{0.0};
    double _bin = 1.0;
    int _nx = 0, _ny = 0;
    std::vector<uint32_t> _start, _items;
};

class ViewCellSwitch : public osg::Group {
public:
    ViewCellSwitch();
    ViewCellSwitch(const ViewCellSwitch& o, const osg::CopyOp& op = osg::CopyOp::SHALLOW_COPY);
    META_Node(vista, ViewCellSwitch)

        void setCells(const std::vector<ViewCellBox>& cells);
    const std::vector<ViewCellBox>& cells() const { return _cells; }
    // Children to hide / impostor children to draw when the viewer is in `cell`.
    void setCellChildren(uint32_t cell, const std::vector<uint32_t>& hidden, const std::vector<uint32_t>& impostors);
    std::vector<uint32_t> hiddenOf(uint32_t cell) const;
    std::vector<uint32_t> impostorsOf(uint32_t cell) const;
    void setTileCount(unsigned n) { _tileCount = n; }
    unsigned getTileCount() const { return _tileCount; }

    int cellAt(const glm::dvec3& eye) const { return _grid.find(eye); }
    // -2 = automatic (default); -1 = no cell; >= 0 = this cell.
    void setForcedCell(int c) { _forced = c; }
    // Automatic lookup outside every cell: false (default) = no cell (the
    // plain city); true = the nearest cell (render mode lodmesh). Run time
    // only, not serialized.
    void setNearestFallback(bool on) { _nearestFallback = on; }
    // The lowest id among the cells nearest to p (Euclidean distance to the
    // box; cells with an empty box are skipped), -1 without cells. O(cells).
    int nearestCell(const glm::dvec3& p) const;
    void setImpostorsEnabled(bool on) { _impostorsOn = on; }
    // Cell chosen by the last cull traversal (-1: none).
    int lastCell() const { return _lastCell; }

    // Draw the tiles as these chunks (see above). nf.chunks/objects/chunkTile
    // index-aligned, chunkTile = child index of the tile here (< tile count;
    // other values are drawn always); drawn in nf.drawOrder. nearDistance in
    // metres (>= 0). An empty scene switches back to whole tiles.
    void setNearChunks(const NearFieldScene& nf, double nearDistance);
    bool hasNearChunks() const { return !_chunkNodes.empty(); }
    double nearChunkDistance() const { return _chunkNear; }
    // Chunks the last cull traversal passed on (before OSG's frustum culling).
    unsigned lastChunkCount() const { return _lastChunks; }

    // Consistency of the per-cell lists with the children; message names the
    // first problem, empty when fine.
    std::string validate() const;

    void traverse(osg::NodeVisitor& nv) override;

    // Serializer access (flat arrays): 9 doubles per cell
    // (cx, cy, cz, ax, ay, halfLength, halfWidth, halfHeight, 0), and CSR lists.
    const osg::DoubleArray* getCellData() const { return _cellData.get(); }
    void setCellData(osg::DoubleArray* a);
    const osg::UIntArray* getHiddenStart() const { return _hiddenStart.get(); }
    void setHiddenStart(osg::UIntArray* a) { _hiddenStart = a; }
    const osg::UIntArray* getHiddenItems() const { return _hiddenItems.get(); }
    void setHiddenItems(osg::UIntArray* a) { _hiddenItems = a; }
    const osg::UIntArray* getImpostorStart() const { return _impStart.get(); }
    void setImpostorStart(osg::UIntArray* a) { _impStart = a; }
    const osg::UIntArray* getImpostorItems() const { return _impItems.get(); }
    void setImpostorItems(osg::UIntArray* a) { _impItems = a; }
    unsigned getTileCountProp() const { return _tileCount; }
    void setTileCountProp(unsigned n) { _tileCount = n; }

protected:
    ~ViewCellSwitch() override = default;

private:
    void rebuildLists(uint32_t cell, const std::vector<uint32_t>& hidden, const std::vector<uint32_t>& impostors);
    std::vector<ViewCellBox> _cells;
    ViewCellGrid _grid;
    osg::ref_ptr<osg::DoubleArray> _cellData;
    osg::ref_ptr<osg::UIntArray> _hiddenStart, _hiddenItems, _impStart, _impItems;
    unsigned _tileCount = 0;
    int _forced = -2;
    bool _impostorsOn = true;
    bool _nearestFallback = false;
    int _lastCell = -1;
    // Near-field chunks, in draw order (run time only).
    std::vector<osg::ref_ptr<osg::Node>> _chunkNodes;
    std::vector<int32_t> _chunkTile;
    std::vector<SplitObject> _chunkBoxes;
    double _chunkNear = 0;
    unsigned _lastChunks = 0;
    std::vector<uint8_t> _hiddenMask;  // scratch of the cull traversal, per tile
};

}  // namespace vista
