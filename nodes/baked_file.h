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
//
// Pairing (docs/formats.md "Baked file"): a bake records the content hash of
// its source city (sceneFileContentHash, 16 hex digits) as the root user value
// vista.source_city_hash. checkBakedFromCity() compares it with the city a
// program opened; every reader that pairs a baked file with a city (vista
// bench/view --baked/--baked-mesh) calls it before drawing anything.
#pragma once
#include <cstddef>
#include <string>

#include <osg/Node>

#include <osg/ref_ptr>

#include "foundation/status.h"
#include "nodes/view_cell_switch.h"
#include "runtime/scene/scene_model.h"

namespace vista {

struct BakedFile {
    SceneModel city;  // the city part (tiles) as loadCityFile reads it
    osg::ref_ptr<ViewCellSwitch> root;
    size_t impostors = 0, points = 0;
    bool meshes = false;  // the representation: textured depth meshes
    size_t meshCount = 0, meshTriangles = 0;
    std::string sourceCityHash;  // vista.source_city_hash; "" = baked before the field existed
};
// True for the root of a mesh bake (user value vista.bake_representation = "mesh").
bool isMeshBake(const osg::Node* root);
// Loads and checks a baked file; errors name the path and the problem.
Result<BakedFile> loadBakedFile(const std::string& path);

// The city a scene file stands for, as a content hash: for a baked root its
// vista.source_city_hash ("" if it has none), else (a plain city) the file's
// own content hash. `root` is the file's root as loaded. Errors name the path.
Result<std::string> cityIdentity(const std::string& path, const osg::Node* root);

// Checks that `baked` (loaded from bakedPath) was baked from the city opened
// as cityPath (its root as loaded: cityRoot). Different hashes -> an error
// naming both files, both hashes and the rebake command. A baked file (or a
// baked city file) without vista.source_city_hash -> ok, and *warning (if
// given) names the file that cannot be checked; otherwise *warning = "".
Status checkBakedFromCity(const std::string& bakedPath, const BakedFile& baked, const std::string& cityPath,
                          const osg::Node* cityRoot, std::string* warning = nullptr);

}  // namespace vista
