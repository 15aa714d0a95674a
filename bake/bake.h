// The bake: view cells of a loaded city, one point impostor per (cell, street
// end) where the far field is large enough, atomic per-cell results, and the
// assembled baked scene (thesis ch. 5; docs/bake.md).
//
// Far field of (cell, end): the city tiles (root children of the city file)
// that lie entirely between `margin` and `margin + farDepth` metres beyond the
// street end and meet the wedge seen through the street opening
// (half-width = street half-width + openingExtra, widening towards the far
// field with the slope of the line from the cell centre through the opening's
// edge). The impostor replaces exactly these tiles: only their triangles are
// sampled, and the view-cell switch hides them in the cell. Ends whose far
// field has fewer than minTriangles triangles get no impostor.
//
// Impostor frame: origin at the street end (world x, y; z = cell ground
// minimum), x axis = direction of the street end (away from the cell),
// y = left, z = up; points are float in this frame, the frame's matrix is
// stored with the impostor.
//
// Contract: bakeCell() depends only on (city, cell, params) — not on thread
// count, timing or the other cells — so cell results can be baked in any
// order, on any machine, and merged. Cell result files carry a config hash
// and an integrity hash; decodeCellResult() rejects mismatches and truncation.
// assembleBakedScene() output bytes depend only on the cell results.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <osg/ref_ptr>

#include "bake/appearance.h"
#include "bake/sampling.h"
#include "bake/view_cells.h"
#include "foundation/status.h"
#include "nodes/point_impostor.h"
#include "nodes/view_cell_switch.h"
#include "runtime/scene/city_file.h"

namespace vista {

struct BakeParams {
    ViewCellParams cells;
    SamplingParams sampling;
    AppearanceParams appearance;
    double margin = 100.0;       // metres beyond the street end where the far field starts
    double farDepth = 600.0;     // metres of far field beyond that
    double openingExtra = 10.0;  // metres added to the street half-width at the opening
    size_t minTriangles = 2000;  // ends with a smaller far field get no impostor
    uint64_t seed = 1;
    // Canonical text of every parameter that changes results (part of the config hash).
    std::string canonical() const;
};

// One tile of the city file: its root child index, world xy bounds and the
// SceneModel meshes/instances it holds.
struct CityTile {
    uint32_t child = 0;
    glm::dvec2 lo{1e300}, hi{-1e300};
    std::vector<uint32_t> meshes, instances;
    size_t triangles = 0;
};
std::vector<CityTile> indexTiles(const SceneModel& city);

struct ImpostorStats {
    size_t farTriangles = 0, tiles = 0;
    int camW[3] = {0, 0, 0}, camH[3] = {0, 0, 0};
    double requiredStep = 0, usedStep = 0;    // LDI angular step (tangent units)
    int64_t ldiRays = 0, mcRays = 0, mcSamples = 0;
    size_t ldiSamples = 0, afterRemoval = 0, points = 0, textured = 0, dropped = 0;
    size_t noiseSingle = 0;                          // single-coloured by the F test (appearance.h)
    size_t screenPixels = 0, screenBBoxPixels = 0;  // from the cell centre, 640x480 target view
    double bakeMs = 0;                               // not part of the baked scene
};

struct ImpostorResult {
    uint32_t cell = 0;
    uint8_t end = 0;                 // 0: towards node a, 1: towards node b
    glm::dvec3 frameOrigin{0.0};     // world
    glm::dvec2 frameX{1.0, 0.0};     // world direction of the frame's x axis
    std::vector<uint32_t> hiddenTiles;  // root child indices, ascending
    PointImpostorData data;
    ImpostorStats stats;
};

struct CellResult {
    uint32_t cell = 0;
    std::vector<ImpostorResult> impostors;
    std::vector<std::string> notes;  // why ends were skipped
    double bakeMs = 0;
};

struct BakeInput {
    const SceneModel* city = nullptr;
    std::vector<CityTile> tiles;
    std::vector<ViewCell> cells;
    std::vector<SkippedCell> skipped;
};
BakeInput prepareBake(const SceneModel& city, const BakeParams& p);

// Frame helpers (world <-> impostor frame).
glm::dvec3 toImpostorFrame(const ImpostorResult& r, const glm::dvec3& world);
glm::dvec3 fromImpostorFrame(const ImpostorResult& r, const glm::dvec3& local);
// The view cell box in an impostor's frame.
Box3 cellInFrame(const ViewCell& c, const ImpostorResult& r);

// Far-field triangles of (cell, end) in the impostor frame; fills r.frame*
// and r.hiddenTiles. Exposed for tests and measurements.
TriangleSoup farFieldSoup(const BakeInput& in, const ViewCell& cell, int end, const BakeParams& p, ImpostorResult& r);

// Bakes one impostor from a prepared soup. Error only for ill-defined setups.
Status bakeImpostor(const TriangleSoup& soup, const Box3& cellBox, const BakeParams& p, uint64_t entity, ImpostorResult& r);
CellResult bakeCell(const BakeInput& in, const ViewCell& cell, const BakeParams& p);

std::string encodeCellResult(const CellResult& r, uint64_t configHash);
Result<CellResult> decodeCellResult(const std::string& bytes, uint64_t configHash, const std::string& what);

// The baked scene: a ViewCellSwitch named "vista.city" carrying the city
// root's user values and state (so loadCityFile() reads it as a city), the
// tiles, then one impostor node per result (MatrixTransform "impostor_C_E" ->
// Geode -> PointImpostor). `results` must be sorted by cell id.
osg::ref_ptr<ViewCellSwitch> assembleBakedScene(const SceneModel& city, const std::vector<ViewCell>& cells,
                                                const std::vector<CellResult>& results, const std::string& paramsText);

}  // namespace vista
