// SceneModel: a city file decoded once into plain arrays (no OSG types), the
// one input of every consumer that is not a scene graph: the Embree ray
// scene, the horizon height grid, the near-field chunker, the bake, paths.
//
// Layout: `meshes` = one triangle mesh per (tile, material) in file order,
// float positions relative to a double world `origin`; `prototypes` = tree
// prototype meshes (origin 0) drawn by `instances` (prototype frame -> world).
// `tiles` lists the city file's tiles in file order: the root child index,
// the world origin, the world xy bounds and which meshes and instances each
// holds (every mesh and instance belongs to exactly one tile). Colours are
// the prelit vertex colours that the rasteriser shows.
// `graph` is the OSG scene graph the model was decoded from (opaque here;
// runtime/scene/scene_graph.h gives it to OSG-side code), null for a model
// built by hand (tests). Values are immutable after loading by convention;
// sharing a const SceneModel between threads is safe.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/mesh.h"
#include "citygen/params.h"
#include "citygen/street_graph.h"

namespace vista {

struct SceneMesh {
    glm::dvec3 origin{0.0};            // world position of the mesh frame
    std::vector<glm::vec3> positions;  // metres, relative to origin
    std::vector<glm::u8vec4> colors;   // prelit RGBA, one per position
    std::vector<uint32_t> indices;     // triangles (3 per triangle)
    // Ground truth (citygen/labels.h): the geometry's material (Count when
    // its name is none) and the label id per vertex (tile meshes: instance
    // id; prototypes: the part's Material), empty for files without labels.
    Material material = Material::Count;
    std::vector<uint32_t> ids;
};

struct SceneInstance {
    uint32_t prototype = 0;
    glm::dmat4 transform{1.0};  // prototype frame -> world
    uint32_t id = 0;            // ground-truth instance id (labels.h: tree index), 0 when unlabelled
};

struct SceneTile {
    uint32_t child = 0;                // index of the tile among the scene root's children
    glm::dvec3 origin{0.0};            // world origin of the tile
    glm::dvec2 lo{1e300}, hi{-1e300};  // world xy bounds of its geometry (lo > hi: empty)
    std::vector<uint32_t> meshes, instances;
    size_t triangles = 0;  // rendered triangles (instances expanded)
};

// One region of a paged city inside a model merged from several
// (paged_load.h loadPagedCity): its tiles and its tree impostors are the
// ranges [firstTile, firstTile + tileCount) and [firstImpostor, firstImpostor +
// impostorCount) of the model; its meshes and instances are those its tiles list.
struct SceneRegionSpan {
    int region = -1;      // index into the paged city's manifest regions
    bool coarse = false;  // its coarse level (else its full file)
    uint32_t firstTile = 0, tileCount = 0;
    uint32_t firstImpostor = 0, impostorCount = 0;
};

struct SceneGraph;  // defined in runtime/scene/scene_graph.h (OSG side)

struct SceneModel {
    CityParams params;
    StreetGraph streets;                // city frame (add params.origin for world)
    std::vector<SceneMesh> meshes;      // tile meshes (world origin per mesh)
    std::vector<SceneMesh> prototypes;  // tree prototypes (origin 0)
    std::vector<SceneInstance> instances;
    // Tree impostors (tree_impostor_graph.h; coarse levels of a paged city):
    // in no tile's lists; the graph draws them as quads (counted in
    // `triangles`), the ray scene traces them as their prototype meshes.
    std::vector<SceneInstance> impostors;
    std::vector<SceneTile> tiles;          // empty for hand-built models
    std::vector<SceneRegionSpan> regions;  // the paged regions merged into it, in merge order; empty for a city file
    size_t triangles = 0;                  // rendered triangles (instances expanded)
    bool labelled = false;                 // the file carries ground-truth labels (vista.labels)
    std::shared_ptr<SceneGraph> graph;     // the decoded OSG graph, or null
};

// World xy bounds of a mesh / an instance (expanding lo/hi).
void expandBounds(const SceneMesh& m, glm::dvec2& lo, glm::dvec2& hi);
void expandBounds(const SceneModel& city, const SceneInstance& in, glm::dvec2& lo, glm::dvec2& hi);

}  // namespace vista
