// Panoramic image cache (thesis §4.4) with a quality-bounded reuse policy: a
// cylindrical map of traced far-field colours, indexed by world direction (so
// its contents stay valid while the viewer only rotates), where every cell
// also records the observer position it was traced from and how near the
// surfaces around it were. A cached colour is reused while its estimated
// reprojection error stays below a bound in pixels; otherwise it is
// re-traced, the worst first, within an optional per-frame pixel budget.
//
// Map: `width` azimuth columns over [0, 2 pi) (clockwise from +y, wrapping),
// `height` rows over v = tan(elevation) in [-vMax, vMax] (a cylinder around
// the viewer). Directions steeper than vMax are not cacheable (index -1).
// Resolution: forCamera() picks cells `oversample` times finer than the
// screen's pixel spacing at the image centre (so pixels of one frame rarely
// share a cell), capped at kMaxCells cells.
//
// Records: one per distinct camera (position and orientation) for which
// pixels were traced; each traced cell points to the record of its frame;
// record 0 = never traced. Per cell the cache also keeps where in the cell
// its ray went (the sub-cell position, 1/256 of a cell) and `near` (metres):
// the nearest far-field surface within the screen window of its pixel when it
// was traced (+inf when all was sky).
//
// Error of reusing a cell for a pixel whose ray falls at sub-cell position s,
// seen from eye e (CachePolicy), with b = |e - record eye|:
//   error_px = (max(b / near, b / lowerDepth - windowPx * radPerPixel) + offset(s)) / radPerPixel
// A point at distance d moves by at most b / d radians when the eye moves by
// b, so the first term bounds how far the cell's own content and every
// surface of its window have moved; the second bounds a surface from outside
// the window (no far surface is nearer than lowerDepth, e.g. the near
// distance, so it moves at most b / lowerDepth and must cross windowPx
// pixels first). offset(s) is the angle between the cell's traced ray and
// the pixel's ray (the resampling error, also when only rotating). Never
// traced = +inf; the very camera of the record = exact (never re-traced).
// selectForTracing() marks every non-exact candidate whose error is not
// below maxErrorPx (so maxErrorPx = 0 re-traces all but exact cells); with a
// budget >= 0 only the `budget` largest errors among them (cells not
// cacheable always count first). Cells written by two pixels in one frame are
// reset to record 0, so both keep being traced.
//
// Not thread-safe (one far-field pipeline owns it). Bad input (non-finite
// direction) returns index -1.
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "foundation/zeroed_array.h"

#include <glm/glm.hpp>

#include "runtime/scene/camera.h"

namespace vista {

// World boxes (low and high corner) of parts of a scene that arrived or left (a streamed city's
// region levels): what FarField::sceneChanged and RenderMode::sceneChanged take.
using SceneBoxes = std::vector<std::pair<glm::dvec3, glm::dvec3>>;

struct CacheCandidate {
    int64_t cell;               // panorama cell index, or -1 (not cacheable: always traced)
    uint32_t pixel;             // screen pixel index (y * width + x)
    glm::u8vec2 sub{128, 128};  // where the pixel's ray falls in the cell (1/256 of a cell; index())
};

struct CachePolicy {
    double maxErrorPx = 0.25;   // reuse while the error is below this (pixels, >= 0)
    double radPerPixel = 1e-3;  // angular size of a pixel at the image centre (> 0)
    double lowerDepth =
        0.0;                // no far surface is nearer (metres); 0 = unknown (then the window term is +inf when moving)
    double windowPx = 8.0;  // radius of the screen window that `near` of a cell covers (pixels)
    int64_t budget = -1;    // most cells re-traced per frame; < 0 = no cap
};

class PanoramaCache {
public:
    static constexpr int64_t kMaxCells = int64_t(1) << 24;

    PanoramaCache(int width, int height, double vMax);
    // Resolution for a camera: vMax covers the view at pitch up to +-10 degrees more.
    static PanoramaCache forCamera(const Camera& camera, double oversample = 1.5);

    int width() const { return _width; }
    int height() const { return _height; }
    double vMax() const { return _vMax; }
    // The cell of a direction (and, if `sub` is given, where in the cell it falls, in 1/256 of a cell).
    int64_t index(const glm::dvec3& worldDir, glm::u8vec2* sub = nullptr) const;
    // Fractional map coordinates (column, row) of a direction (for tests).
    glm::dvec2 mapCoord(const glm::dvec3& worldDir) const;

    // Drops every cached colour and record. The cells are zeroed in place:
    // every page of the map is then resident, so the frames after a restart
    // (a walkthrough's first frames, after its warm-up) pay no first touch of
    // a page inside the far field's cache stage.
    void clear();
    // Forgets the cells whose ray, from the eye of any record, could pass
    // through the box [lo, hi] (a part of the scene that arrived or left).
    // Records whose eye lies more than `reach` metres from the current
    // record's are forgotten whole (no memory touched; pass the largest
    // baseline at which the policy still reuses a cell, e.g. reuseReach());
    // of the others, the cells within the box's azimuth and elevation span
    // seen from the current eye, widened by the largest distance b to their
    // eyes (a point at distance d is seen from an eye b away at most
    // asin(b / d) off) and by a cell. Every cell goes when the box comes
    // within b of the current eye horizontally. Returns the number of cells
    // zeroed (0 when nothing was traced yet).
    uint64_t invalidateBox(const glm::dvec3& lo, const glm::dvec3& hi, double reach);
    // The largest eye distance at which `policy` can still reuse a cell (metres; 0 = never:
    // lowerDepth unknown): (maxErrorPx + windowPx) * radPerPixel * lowerDepth.
    static double reuseReach(const CachePolicy& policy);
    // Starts a frame for `camera`: picks or creates the current record.
    void beginFrame(const Camera& camera);
    // The reprojection error (pixels) of reusing `cell` now for a ray at `sub` (see above); -1 = exact.
    double error(int64_t cell, glm::u8vec2 sub, const CachePolicy& policy) const;
    // Marks trace[i] (resized to candidates.size()) for the candidates to
    // trace this frame under `policy`. Returns the number marked.
    int64_t selectForTracing(const std::vector<CacheCandidate>& candidates, const CachePolicy& policy,
                             std::vector<uint8_t>& trace);
    // Stores traced colours of this frame with where their rays fell in the
    // cells and the nearest far surface of their window (nearDistance,
    // metres, +inf = none); duplicates are reset to record 0.
    void store(const std::vector<int64_t>& cells, const std::vector<glm::u8vec2>& subs,
               const std::vector<glm::u8vec4>& colors, const std::vector<float>& nearDistance);
    // Resets cells to never traced (a moving object may have been in them:
    // FarFieldOptions::cacheMovers); -1 entries are skipped.
    void forget(const std::vector<int64_t>& cells);
    glm::u8vec4 color(int64_t cell) const { return _cells[size_t(cell)].color; }
    float nearDistance(int64_t cell) const { return decodeNear(_cells[size_t(cell)].nearBits); }
    uint32_t record(int64_t cell) const { return _cells[size_t(cell)].record; }
    size_t recordCount() const { return _records.size(); }
    uint32_t currentRecord() const { return _current; }

private:
    struct Record {
        glm::dvec3 eye{0.0};
        double heading = 0, pitch = 0, roll = 0, fovY = 0;
        int width = 0, height = 0;
        bool forgotten = false;  // invalidateBox: its cells count as never traced
    };
    void compact();
    int _width = 0, _height = 0;
    double _vMax = 1;
    // One cell, 16 bytes (one cache line holds four; a lookup or a store
    // touches one), zero-initialised so that a fresh panorama costs nothing
    // until touched: colour (alpha 0 = never traced), nearest far surface
    // (float bits XOR those of +inf: zero = +inf), sub-cell position (XOR
    // 128: zero = the centre), the store() call that last wrote it (16 bits,
    // wrapping: a stale match only makes a cell re-traced), record (0 =
    // never traced).
    struct Cell {
        glm::u8vec4 color;
        uint32_t nearBits;
        glm::u8vec2 sub;
        uint16_t stamp;
        uint32_t record;
    };
    static_assert(sizeof(Cell) == 16, "a panorama cell is 16 bytes");
    static uint32_t encodeNear(float d);
    static float decodeNear(uint32_t v);
    static constexpr uint8_t kSubBias = 128;
    ZeroedArray<Cell> _cells;
    std::vector<Record> _records;  // [0] = never traced
    uint32_t _current = 0;
    std::vector<double> _baseline;  // per record: distance to the current eye (beginFrame)
    uint16_t _stamp = 0;
    std::vector<double> _error;  // scratch of selectForTracing
};

}  // namespace vista
