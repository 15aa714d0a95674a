// The city scene file (.osgb): writing from a City and loading for the runtime.
//
// Format (docs/formats.md): root osg::Group "vista.city" with user values
//   vista.format (int, 1), vista.params (canonical params JSON),
//   vista.streets (street graph JSON, street_graph.h), vista.origin_x/_y (double),
//   vista.tile_size_m (double)
// and children: one osg::MatrixTransform per tile (name "tile_IX_IY", double
// translation = world tile origin) holding an osg::Geode with one
// osg::Geometry per material (name = material name; VBOs; per-vertex prelit
// colours; lighting off) and the tile's trees drawn instanced per prototype.
// Stock osgviewer / osgconv open it with no plugin.
//
// Contract: writeCityFile() writes atomically (temp file + rename): on any
// error no file is left at `path`. Output bytes depend only on the City.
// loadCityFile() returns an error naming the file for missing, unreadable,
// truncated or non-vista files; never crashes on corrupt input.
#pragma once
#include <string>
#include <vector>

#include <osg/Geometry>
#include <osg/MatrixTransform>
#include <osg/Node>
#include <osg/ref_ptr>

#include "citygen/city.h"
#include "citygen/status.h"

namespace vista {

osg::ref_ptr<osg::Node> buildCityScene(const City& city);
Status writeCityFile(const City& city, const std::string& path);

// World-space triangle soup of one tile/material or one tree prototype,
// extracted for ray casting. Positions are relative to `origin` (world, double).
struct LoadedMesh {
    glm::dvec3 origin{0.0};
    std::vector<glm::vec3> positions;
    std::vector<glm::u8vec4> colors;
    std::vector<uint32_t> indices;
};
struct LoadedInstance {
    uint32_t prototype = 0;
    glm::dmat4 transform{1.0};  // prototype frame -> world
};

struct LoadedCity {
    osg::ref_ptr<osg::Node> scene;     // the root as read
    CityParams params;
    StreetGraph streets;               // city frame (add params.origin for world)
    std::vector<LoadedMesh> meshes;    // tile meshes (world origin per mesh)
    std::vector<LoadedMesh> prototypes;// tree prototypes (origin 0)
    std::vector<LoadedInstance> instances;
    size_t triangles = 0;              // rendered triangles (instances expanded)
};

Result<LoadedCity> loadCityFile(const std::string& path);

// Scene-file layout shared by every reader of city files (loader, hybrid
// re-chunking, bake): tree geometries are named kTreeGeometryPrefix + prototype
// index and carry their per-instance matrix columns in vertex attributes
// kInstanceAttrib0 .. kInstanceAttrib0 + 3.
constexpr const char* kTreeGeometryPrefix = "tree_prototype_";
constexpr unsigned kInstanceAttrib0 = 12;
// The tile transform ("tile_IX_IY") if `node` is one, else null.
osg::MatrixTransform* asCityTile(osg::Node* node);
// The geometries with at least one primitive set under a tile transform, in
// file order: the order in which loadCityFile() lists meshes and instances.
std::vector<osg::Geometry*> tileGeometries(osg::MatrixTransform& tile);

// glTF 2.0 binary (.glb) of the city: one mesh per tile and material with
// COLOR_0, tree prototypes as meshes referenced by instance nodes. Atomic write.
Status writeGltf(const City& city, const std::string& path);

// Atomic file write helper used by every writer of the project.
Status writeFileAtomic(const std::string& path, const std::string& bytes);

}  // namespace vista
