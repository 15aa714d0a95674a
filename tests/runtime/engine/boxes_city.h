// A generated city written and loaded as a file, with its ray scene and its
// boxes: the fixture of the box tests (test_boxes.cpp, test_rig_boxes.cpp).
#pragma once
#include <memory>
#include <string>
#include <utility>

#include "citygen/generate.h"
#include "foundation/status.h"
#include "runtime/engine/boxes.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/city_file.h"
#include "tests/common/temp_dir.h"

namespace vista::test {

struct BoxesCity {
    SceneModel model;
    std::unique_ptr<RayScene> rays;
    CityBoxes boxes;
};

// Generates `params`, writes and loads the city (as vista render loads it), builds its ray scene and boxes.
inline BoxesCity* makeBoxesCity(const CityParams& params, const std::string& tempName) {
    auto generated = generateCity(params);
    VISTA_CHECK(generated.isOk());
    TempDir dir(tempName);
    VISTA_CHECK(writeCityFile(*generated, dir.file("city.osgb")).isOk());
    auto model = loadCityFile(dir.file("city.osgb"));
    VISTA_CHECK(model.isOk());
    auto* c = new BoxesCity{std::move(*model), nullptr, {}};
    auto rays = RayScene::build(c->model);
    VISTA_CHECK(rays.isOk());
    c->rays = std::move(*rays);
    c->boxes = buildCityBoxes(c->model);
    return c;
}

}  // namespace vista::test
