// The OSG side of the city file: building the scene graph from a City, and
// the layout every reader of the graph shares (tiles, tree geometries).
//
// Graph (docs/formats.md): root osg::Group "vista.city" with user values
//   vista.format (int, 1), vista.params (canonical params JSON),
//   vista.streets (street graph JSON, street_graph.h), vista.origin_x/_y (double),
//   vista.tile_size_m (double)
// and children: one osg::MatrixTransform per tile (name "tile_IX_IY", double
// translation = world tile origin) holding an osg::Geode with one
// osg::Geometry per material (name = material name; VBOs; per-vertex prelit
// colours; lighting off) and the tile's trees drawn instanced per prototype:
// geometries named kTreeGeometryPrefix + prototype index carrying their
// per-instance matrix columns in vertex attributes kInstanceAttrib0 .. +3.
// Only OSG-side rooms (nodes/, bake/, the vista tool) include this header.
#pragma once
#include <vector>

#include <osg/Geometry>
#include <osg/MatrixTransform>
#include <osg/Node>
#include <osg/ref_ptr>

#include "citygen/city.h"
#include "runtime/scene/scene_model.h"

namespace vista {

struct SceneGraph {
    osg::ref_ptr<osg::Node> root;
};
// The graph a model was decoded from, or null (hand-built model).
osg::Node* sceneRoot(const SceneModel& model);
// Attaches `root` as the model's graph (for models built from a graph in memory).
void setSceneRoot(SceneModel& model, osg::Node* root);

osg::ref_ptr<osg::Node> buildCityScene(const City& city);

constexpr const char* kTreeGeometryPrefix = "tree_prototype_";
constexpr unsigned kInstanceAttrib0 = 12;
// Ground-truth labels (citygen/labels.h; files with the root user value
// vista.labels = 1): every tile geometry and tree prototype carries its
// per-vertex label ids (osg::UIntArray, integer data type preserved) in
// vertex attribute kLabelAttrib; every instanced tree geometry carries each
// instance's id in kTreeIdAttrib (one value per instance, divisor 1).
// Location 5 is reserved for the label pass's per-vertex class.
constexpr unsigned kLabelAttrib = 6;
constexpr unsigned kTreeIdAttrib = 7;
constexpr unsigned kLabelClassAttrib = 5;
// Haze uniforms read by every vista shader that draws city geometry (the
// instanced trees' program as loaded, the haze program of nodes/render):
// colour = mix(vista_haze_color, colour, exp(-vista_haze_density * eye-plane depth)).
// Unset (0) = no haze: the colour passes unchanged.
constexpr const char* kHazeDensityUniform = "vista_haze_density";
constexpr const char* kHazeColorUniform = "vista_haze_color";
// GLSL 1.20 fragment-stage haze shared by those shaders (declares the uniforms
// and `vec4 vistaHaze(vec4 colour)`, which takes the eye-plane depth from
// gl_FragCoord.w: the shaders draw under perspective projections only).
extern const char* const kHazeGlsl;
// GLSL 1.20 vertex shader head of instanced drawing: the four per-instance
// matrix columns (vista_instance0..3) and gl_Position, inside an open
// `void main() {`; the caller appends its outputs and the closing brace.
extern const char* const kInstancedVertexHead;
// The tile transform ("tile_IX_IY") if `node` is one, else null.
osg::MatrixTransform* asCityTile(osg::Node* node);
// The geometries with at least one primitive set under a tile transform, in
// file order: the order in which loadCityFile() lists meshes and instances.
std::vector<osg::Geometry*> tileGeometries(osg::MatrixTransform& tile);

// Decodes a graph in the city layout into plain arrays (what loadCityFile
// does after reading the file). `what` names the source in messages.
// Decoding also gives the instanced trees' program (stored in the file
// without haze) the haze uniforms, so the file's bytes stay as written and
// the trees are hazed like everything else.
Result<SceneModel> decodeCityScene(osg::Node* root, const std::string& what);

}  // namespace vista
