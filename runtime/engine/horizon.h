// Horizon tracing (thesis §4.5): a 2D height grid of the city and, per frame,
// the highest screen row far geometry can reach in every pixel column.
// Pixels above that row are sky and need no ray.
//
// HeightGrid: cells x cells square cells over the xy bounding square of all
// geometry, in the scene-local frame (world minus `frameOrigin`, as RayScene).
// Each cell stores the max and min z of every triangle whose (slightly
// enlarged, kCellMargin) xy bounding box overlaps it: conservative, so geometry
// touching a cell border counts in both cells. Built once; immutable; thread-safe.
//
// A streamed city (regions arriving and leaving): lattice() lays the cells
// over a fixed xy rectangle (a paged city's bounds, so the cells do not move
// as regions come and go) with no geometry; patch() computes one model's
// cells on that lattice (const: any thread, e.g. a pager's worker), and
// addPatch() / removePatch() splice it in or out between frames: only the
// cells and blocks of the patch's rectangle are touched (removal re-splats
// the other patches that overlap it), never the whole grid. The cells after
// any sequence of adds and removes are those of the patches present, the
// same as one patch of their merged model. Geometry outside the lattice is
// clamped into its border cells. Not thread-safe while it changes.
//
// traceHorizon(): for an upright camera (roll == 0, zenith and nadir outside
// the view: |pitch| + fovY/2 < pi/2) casts 2D rays through the grid at
// azimuth steps fine enough (spacing * farthest grid distance < cell size / 2)
// that every cell inside the wedge between two adjacent rays is touched by
// one of them; each ray records the largest tan(elevation) any geometry in a
// touched cell can have (cell max height over the cell's nearest distance, or
// over its farthest distance when the cell lies below the eye). Each column's
// bound is the max over the rays spanning its azimuth range (the column's
// pixel-centre rays change azimuth with row when the camera is pitched), and
// the horizon row is the first row (from the top) whose pixel-centre ray may
// reach geometry. Hence with subsample == 1 the result is conservative: no
// pixel with geometry on its centre ray is ever above the horizon.
// Cells whose every point lies within `nearDistance` of the eye are skipped:
// that geometry is drawn by the near field (objects straddling the near
// distance are drawn whole), so it covers its pixels anyway.
// subsample > 1 traces only every n-th ray and fills between with the max of
// the neighbours (thesis: used while the viewer moves; then not strictly
// conservative). `columnNeeded` (optional, one flag per column) limits the
// work to columns that still have uncovered pixels.
// A camera with roll or with zenith/nadir in view returns active = false and a
// reason; rows are then all 0 (nothing culled). Bad cameras (width/height < 1)
// are contract violations.
#pragma once
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "runtime/scene/camera.h"
#include "runtime/scene/scene_model.h"

namespace vista {

// One model's cells on a grid's lattice (HeightGrid::patch): the rectangle
// [x0, x0 + nx) x [y0, y0 + ny) of cells, each cell's max / min z, and the
// model's scene-local bounds. Empty (nx = 0) for a model without geometry.
struct HeightPatch {
    int x0 = 0, y0 = 0, nx = 0, ny = 0;
    std::vector<float> maxZ, minZ;  // nx * ny, row-major
    glm::dvec3 lo{0.0}, hi{0.0};
};

class HeightGrid {
public:
    static constexpr double kCellMargin = 1e-3;  // metres added around every triangle's bounding box

    // Automatic resolution: cells of about kAutoCellM metres, within
    // kAutoMinCells .. kAutoMaxCells a side. A horizon over cells much coarser
    // than the buildings (the 32 km city in 512 cells: 62 m) bounds every
    // column by the tallest building in a wide cell near the eye: 5 to 10 times
    // the far rays, nearly all of them missing.
    static constexpr double kAutoCellM = 4.0;
    static constexpr int kAutoMinCells = 512, kAutoMaxCells = 2048;
    static int autoCells(double extentM);

    HeightGrid() = default;
    // cells: 1..8192 (clamped), or <= 0: autoCells() of the geometry's xy extent.
    // frameOrigin: world position of the scene-local origin.
    static HeightGrid build(const SceneModel& city, const glm::dvec3& frameOrigin, int cells);
    // A grid without geometry whose cells cover the world xy rectangle [worldLo, worldHi] (as
    // build() lays them over a city's bounds; cells as there). Contract: finite, worldLo <= worldHi.
    static HeightGrid lattice(const glm::dvec2& worldLo, const glm::dvec2& worldHi, const glm::dvec3& frameOrigin,
                              int cells);
    // `model`'s cells on this grid's lattice (its origin: frameOrigin()). Thread-safe.
    HeightPatch patch(const SceneModel& model) const;
    // Splices a patch in (key not present) or out (unknown key: nothing). Contract: a patch of
    // this lattice.
    void addPatch(uint64_t key, std::shared_ptr<const HeightPatch> patch);
    void removePatch(uint64_t key);
    size_t patchCount() const { return _patches.size(); }

    bool empty() const { return _cells == 0 || !(_boundsMin.x <= _boundsMax.x); }  // no geometry at all
    int cells() const { return _cells; }
    double cellSize() const { return _cellSize; }
    glm::dvec2 gridMin() const { return _min; }          // scene-local xy of cell (0,0)'s corner
    glm::dvec3 boundsMin() const { return _boundsMin; }  // scene-local bounding box of all geometry
    glm::dvec3 boundsMax() const { return _boundsMax; }
    glm::dvec3 frameOrigin() const { return _origin; }
    // -inf / +inf for a cell without geometry. ix, iy in [0, cells).
    float maxZ(int ix, int iy) const { return _maxZ[size_t(iy) * size_t(_cells) + size_t(ix)]; }
    float minZ(int ix, int iy) const { return _minZ[size_t(iy) * size_t(_cells) + size_t(ix)]; }

    // Largest tan(elevation) seen from `eye` (scene-local) of any geometry in
    // cells touched by the 2D ray at `azimuth` (radians clockwise from +y),
    // skipping cells entirely within `nearDistance`. -inf if nothing; +inf if
    // geometry above the eye may lie at distance 0 (eye inside a cell with
    // geometry above it).
    // Cells whose nearest xy point lies beyond `maxDistance` are skipped too
    // (haze: nothing there is drawn or traced).
    // Walks blocks of kBlock x kBlock cells first and visits the cells of a
    // block only if the block's bound (its max height, its nearest and
    // farthest points) could beat the best so far: the same value as visiting
    // every cell (traceRayFlat, kept for tests), at a fraction of the visits.
    double traceRay(const glm::dvec3& eye, double azimuth, double nearDistance,
                    double maxDistance = std::numeric_limits<double>::infinity()) const;
    double traceRayFlat(const glm::dvec3& eye, double azimuth, double nearDistance,
                        double maxDistance = std::numeric_limits<double>::infinity()) const;
    static constexpr int kBlock = 8;

private:
    double trace(const glm::dvec3& eye, double azimuth, double nearDistance, double maxDistance, bool blocks) const;
    class RayTrace;  // one ray's walk over the cells and blocks
    double cellBound(int ix, int iy, const glm::dvec3& eye, double nearDistance, double maxDistance) const;
    // The bound of any geometry in the xy rectangle [x0, x1] x [y0, y1] (scene-local metres) with heights in [zLo,
    // zHi].
    static double rectBound(double x0, double x1, double y0, double y1, double zLo, double zHi, const glm::dvec3& eye,
                            double nearDistance, double maxDistance);
    double blockBound(int bx, int by, const glm::dvec3& eye, double nearDistance, double maxDistance) const;
    int _cells = 0;
    double _cellSize = 0;
    glm::dvec2 _min{0.0};
    glm::dvec3 _boundsMin{0.0}, _boundsMax{0.0}, _origin{0.0};
    std::vector<float> _maxZ, _minZ;
    int _blocks = 0;                                                  // blocks per side: ceil(cells / kBlock)
    std::vector<float> _blockMaxZ, _blockMinZ;                        // over each block's cells
    std::map<uint64_t, std::shared_ptr<const HeightPatch>> _patches;  // lattice(): the patches present
    void splicePatch(const HeightPatch& p);                           // max / min into the cells
    void updateBlocks(int x0, int y0, int x1, int y1);                // the blocks over cells [x0, x1] x [y0, y1]
    void updateBounds();                                              // the union of the patches' bounds
};

struct HorizonOptions {
    double nearDistance = 0;                                       // metres; 0 = consider all geometry
    double maxDistance = std::numeric_limits<double>::infinity();  // metres: ignore geometry beyond (haze)
    // Eye-plane depth beyond which nothing is traced (haze; metres): each
    // column ignores geometry horizontally farther than its pixels reach
    // before that depth (tighter than one maxDistance for the whole view).
    double maxEyeDepth = std::numeric_limits<double>::infinity();
    int subsample = 1;                                   // >= 1
    const std::vector<uint8_t>* columnNeeded = nullptr;  // size camera.width, or null = all
    // Metres added to every cell's top (>= 0): moving objects up to this tall
    // standing on the grid's geometry (a traffic run's agents) stay below the
    // horizon. Traced as an eye this much lower, which gives the same bound.
    double lift = 0;
};

struct HorizonResult {
    bool active = false;
    std::string reason;    // why inactive ("camera rolled", ...)
    std::vector<int> row;  // per column: rows y < row[x] are sky (0..height)
    int raysTraced = 0;    // 2D rays cast this frame
};

// True if horizon tracing applies to this camera (upright, no zenith/nadir in view).
bool horizonApplies(const Camera& camera, std::string* reason = nullptr);

HorizonResult traceHorizon(const HeightGrid& grid, const Camera& camera, const HorizonOptions& options = {});

// tan(elevation) of the centre ray of pixel (x + 0.5, y + 0.5): exposed for tests.
double pixelTanElevation(const Camera& camera, double px, double py);

}  // namespace vista
