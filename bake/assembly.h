// Assembly of the baked scene from the cell results (docs/reference/bake.md "Files").
//
// The baked scene: a ViewCellSwitch named "vista.city" carrying the city
// root's user values and state (so loadCityFile() reads it as a city) plus
// vista.baked = 1 and vista.bake_params = paramsText; its children are the
// city tiles (shared, not copied), then one impostor node per result in
// order (MatrixTransform "impostor_C_E" holding the impostor frame -> Geode ->
// PointImpostor). The switch is indexed by cell id (= street edge id); ids
// without a cell get an empty box. Results for cell ids beyond `cells` are
// ignored. Representation Mesh: the per-cell children are the textured
// depth meshes instead (MatrixTransform "lodmesh_C_E" -> Geode ->
// TexturedDepthMesh), registered in the same per-cell lists, and the root
// carries vista.bake_representation = "mesh" (a point bake has no such value,
// so its bytes are unchanged). sourceCityHash (sceneFileContentHash() of the
// input city file) is stored as vista.source_city_hash, so readers can refuse
// a baked file of another city; "" stores nothing. Contract: `results` sorted by cell id (output bytes then depend
// only on the results). A hand-built city (no scene graph) gives a switch
// without tiles.
#pragma once
#include <string>
#include <vector>

#include <osg/ref_ptr>

#include "bake/bake_params.h"
#include "bake/cell_result.h"
#include "bake/view_cells.h"
#include "nodes/view_cell_switch.h"
#include "runtime/scene/scene_model.h"

namespace vista {

osg::ref_ptr<ViewCellSwitch> assembleBakedScene(const SceneModel& city, const std::vector<ViewCell>& cells,
                                                const std::vector<CellResult>& results, const std::string& paramsText,
                                                BakeRepresentation representation = BakeRepresentation::Points,
                                                const std::string& sourceCityHash = "");

}  // namespace vista
