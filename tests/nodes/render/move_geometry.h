// Moving a loaded city's geometry away from its frame origin (tests and
// measurements of precision far from the origin).
#pragma once
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <osg/Group>
#include <osg/MatrixTransform>

#include "runtime/scene/scene_graph.h"
#include "runtime/scene/scene_model.h"

namespace vista::test {

// Moves every piece of `city`'s geometry by `d` (world metres) while its frame
// origin (params.origin) stays, as a region in a corner of a large paged city
// lies far from that city's centre: tile origins and bounds, meshes, trees,
// impostors and the graph's tile transforms. False when a child of the city
// root is not a tile transform (nothing is moved then).
inline bool moveGeometry(SceneModel& city, const glm::dvec3& d) {
    osg::Group* root = sceneRoot(city) ? sceneRoot(city)->asGroup() : nullptr;
    if (!root) return false;
    for (unsigned i = 0; i < root->getNumChildren(); ++i)
        if (!dynamic_cast<osg::MatrixTransform*>(root->getChild(i))) return false;
    for (unsigned i = 0; i < root->getNumChildren(); ++i) {
        auto* xf = static_cast<osg::MatrixTransform*>(root->getChild(i));
        xf->setMatrix(xf->getMatrix() * osg::Matrixd::translate(d.x, d.y, d.z));
    }
    for (SceneMesh& m : city.meshes) m.origin += d;
    const glm::dmat4 t = glm::translate(glm::dmat4(1.0), d);
    for (SceneInstance& in : city.instances) in.transform = t * in.transform;
    for (SceneInstance& in : city.impostors) in.transform = t * in.transform;
    for (SceneTile& tile : city.tiles) {
        tile.origin += d;
        tile.lo += glm::dvec2(d);
        tile.hi += glm::dvec2(d);
    }
    return true;
}

}  // namespace vista::test
