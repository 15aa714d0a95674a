// The city scene file (.osgb): written from a City by `vista gen`, decoded
// once into a SceneModel by every reader (the graph layout is in
// scene_graph.h, the format in docs/formats.md).
//
// Contract: writeCityFile() writes atomically (temp file + rename): on any
// error no file is left at `path`. Output bytes depend only on the City.
// loadCityFile() returns an error naming the file for missing, unreadable,
// truncated or non-vista files; never crashes on corrupt input. The model it
// returns carries the decoded graph (scene_graph.h sceneRoot) for OSG-side
// consumers. writeGltf(): glTF 2.0 binary (.glb) of the city: one mesh per
// tile and material with COLOR_0, tree prototypes as meshes referenced by
// instance nodes; atomic.
#pragma once
#include <string>

#include "citygen/city.h"
#include "foundation/status.h"
#include "runtime/scene/scene_model.h"

namespace vista {

Status writeCityFile(const City& city, const std::string& path);
Result<SceneModel> loadCityFile(const std::string& path);
Status writeGltf(const City& city, const std::string& path);

}  // namespace vista
