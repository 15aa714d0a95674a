// STUB: implemented by the far-field work.
#include "runtime/ray_scene.h"
namespace vista {
struct RayScene::Impl {};
RayScene::RayScene() = default;
RayScene::~RayScene() = default;
Result<std::unique_ptr<RayScene>> RayScene::build(const LoadedCity&) { return Status::error("ray scene not built yet"); }
glm::dvec3 RayScene::frameOrigin() const { return {}; }
RayHit RayScene::intersect(const glm::vec3&, const glm::vec3&, float, float) const { return {}; }
void RayScene::intersectMany(const glm::vec3*, const glm::vec3*, int, RayHit*, float) const {}
bool RayScene::occluded(const glm::vec3&, const glm::vec3&, float, float) const { return false; }
size_t RayScene::triangleCount() const { return 0; }
}
