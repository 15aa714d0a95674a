// A baked city file (`vista bake` output) as read by every consumer: the
// city part decoded as a SceneModel plus the ViewCellSwitch root whose
// children are the tiles and the point impostors, or (a bake with
// `--representation mesh`, root user value vista.bake_representation =
// "mesh") the textured depth meshes.
//
// Contract: loadBakedFile() reads the file (integrity trailer checked), checks
// the user value vista.baked = 1, the per-cell lists (ViewCellSwitch::validate)
// and every impostor (PointImpostor::validate) or mesh
// (TexturedDepthMesh::validate; a mesh in a point bake or a point impostor
// in a mesh bake is an error too), so a corrupt or truncated
// file is an error naming the path and the problem, never a crash or a draw
// of garbage. A plain city file is an error that says to run `vista bake`.
#pragma once
#include <cstddef>
#include <string>

#include <osg/ref_ptr>

#include "foundation/status.h"
#include "nodes/view_cell_switch.h"
#include "runtime/scene/scene_model.h"

namespace vista {

struct BakedFile {
    SceneModel city;                   // the city part (tiles) as loadCityFile reads it
    osg::ref_ptr<ViewCellSwitch> root;
    size_t impostors = 0, points = 0;
    bool meshes = false;                  // the representation: textured depth meshes
    size_t meshCount = 0, meshTriangles = 0;
};
// True for the root of a mesh bake (user value vista.bake_representation = "mesh").
bool isMeshBake(const osg::Node* root);
// Loads and checks a baked file; errors name the path and the problem.
Result<BakedFile> loadBakedFile(const std::string& path);

}  // namespace vista
