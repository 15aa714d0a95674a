// Panoramic image cache (thesis §4.4): a cylindrical map of traced far-field
// colours, indexed by world direction, so its contents stay valid when the
// viewer only rotates; confidence records decide which pixels to re-trace
// under a per-frame pixel budget.
//
// Map: `width` azimuth columns over [0, 2 pi) (clockwise from +y, wrapping),
// `height` rows over v = tan(elevation) in [-vMax, vMax] (a cylinder around
// the viewer). Directions steeper than vMax are not cacheable (index -1).
// Resolution: forCamera() picks cells `oversample` times finer than the
// screen's pixel spacing at the image centre (so pixels of one frame rarely
// share a cell), capped at kMaxCells cells.
//
// Confidence records (thesis Fig. 4.6): one per distinct camera (position and
// orientation) for which pixels were traced; each traced cell points to the
// record of its frame. A pixel's error estimate is the distance between its
// record's observer position and the current one (rotation is ignored, as in
// the thesis); record 0 = never traced = worst. selectForTracing() orders the
// candidate pixels' records from worst to best and marks all pixels of the
// worst records for tracing until the budget is met; the record where the
// budget runs out gets every n-th of its pixels traced (n = ceil(count /
// remaining budget), phase rotating per frame), and the rest next frame
// (graceful degradation). Pixels whose record is this very camera (same
// position and orientation) are exact and never re-traced; pixels of the same
// position but another orientation are re-traced last (only with budget
// left), so a viewer who stops converges to the exact image. Cells written by
// two pixels in one frame are reset to record 0, so both keep being traced.
//
// Not thread-safe (one far-field pipeline owns it). Bad input (non-finite
// direction) returns index -1.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "runtime/scene/camera.h"

namespace vista {

struct CacheCandidate {
    int64_t cell;    // panorama cell index, or -1 (not cacheable: always traced)
    uint32_t pixel;  // screen pixel index (y * width + x)
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
    int64_t index(const glm::dvec3& worldDir) const;
    // Fractional map coordinates (column, row) of a direction (for tests).
    glm::dvec2 mapCoord(const glm::dvec3& worldDir) const;

    // Drops every cached colour and record.
    void clear();
    // Starts a frame for `camera`: picks or creates the current record.
    void beginFrame(const Camera& camera);
    // Marks trace[i] (resized to candidates.size()) for the candidates to trace
    // this frame; budget < 0 = unlimited (every non-exact pixel).
    // Returns the number marked.
    int64_t selectForTracing(const std::vector<CacheCandidate>& candidates, int64_t budget, std::vector<uint8_t>& trace);
    // Stores traced colours (cells of one frame; duplicates are reset to record 0).
    void store(const std::vector<int64_t>& cells, const std::vector<glm::u8vec4>& colors);
    glm::u8vec4 color(int64_t cell) const { return _color[size_t(cell)]; }
    uint32_t record(int64_t cell) const { return _record[size_t(cell)]; }
    size_t recordCount() const { return _records.size(); }
    uint32_t currentRecord() const { return _current; }

private:
    struct Record {
        glm::dvec3 eye{0.0};
        double heading = 0, pitch = 0, roll = 0, fovY = 0;
        int width = 0, height = 0;
    };
    void compact();
    int _width = 0, _height = 0;
    double _vMax = 1;
    std::vector<glm::u8vec4> _color;
    std::vector<uint32_t> _record;
    std::vector<Record> _records;  // [0] = never traced
    uint32_t _current = 0;
    uint64_t _frame = 0;
    std::vector<uint32_t> _count;  // scratch per record
};

}  // namespace vista
