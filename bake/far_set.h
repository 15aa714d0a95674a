// Far-field selection: which city tiles an impostor of (view cell, street
// end) replaces, and their triangles in the impostor frame (thesis 5.5;
// docs/reference/bake.md "Pipeline", far field).
//
// The far field of (cell, end) = the tiles with triangles that lie entirely
// between `margin` and `margin + farDepth` metres beyond the street end
// (along the frame's x axis) and meet the wedge seen through the street
// opening: |y| <= hw0 + slope (x - margin), hw0 = street half-width +
// openingExtra, slope = hw0 / (cell half-length + margin) (the line from the
// cell centre through the opening's edge), or straddle y = 0. The impostor
// replaces exactly these tiles: only their triangles are sampled, and the
// view-cell switch hides them in the cell. Ends whose far field has fewer than
// max(minTriangles, 1) triangles get no impostor (bake/bake_cell.h).
// A city with the `haze` effect ends the far field at the visibility
// distance (depth min(farDepth, visibility - margin)): nothing beyond is drawn.
//
// Tiles: SceneModel::tiles as loadCityFile decoded them; a hand-built model
// (tests; no tiles) gets one tile per mesh, then one per instance, numbered
// in that order. Pure; thread-safe on a const SceneModel.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "bake/impostor_frame.h"
#include "bake/view_cells.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/scene_model.h"

namespace vista {

struct FarSetParams {
    double margin = 100.0;       // metres beyond the street end where the far field starts
    double farDepth = 600.0;     // metres of far field beyond that
    double openingExtra = 10.0;  // metres added to the street half-width at the opening
    size_t minTriangles = 2000;  // ends with a smaller far field get no impostor
};

// The tiles the bake selects from (see above).
std::vector<SceneTile> bakeTiles(const SceneModel& city);

struct FarSet {
    ImpostorFrame frame;
    std::vector<uint32_t> tiles;  // root child indices of the replaced tiles, ascending
    TriangleSoup soup;            // their triangles in the frame (tree instances expanded)
};

FarSet selectFarSet(const SceneModel& city, const std::vector<SceneTile>& tiles, const ViewCell& cell, int end,
                    const FarSetParams& p);

}  // namespace vista
