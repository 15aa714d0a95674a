// RayScene: the Embree scene of a loaded city, shared by the raycast mode,
// the hybrid far field and the bake.
//
// Contract: built once from a SceneModel (tile meshes as triangle geometry,
// tree prototypes as instanced geometry); immutable afterwards, so every
// method is thread-safe. Coordinates: world double positions are converted
// to a scene-local float frame around `frameOrigin()` (the city centre), so
// precision holds 1,000 km from the world origin. Hits return the
// interpolated prelit vertex colour: the same colour the rasteriser shows.
// Back faces (triangles clockwise as seen along the ray) are culled, as the
// rasteriser culls them (CullFace BACK on the city root).
// Embree errors are mapped to Status at construction; nothing throws from a
// ray-casting loop. FTZ/DAZ are set on every thread that casts.
#pragma once
#include <cstdint>
#include <memory>

#include <glm/glm.hpp>

#include "foundation/status.h"
#include "runtime/scene/scene_model.h"

namespace vista {

struct RayHit {
    bool hit = false;
    float t = 0;                // distance along the (unit) ray direction, metres
    glm::u8vec4 color{0};       // prelit colour at the hit
    glm::vec3 normal{0.0f};     // geometric normal, scene-local frame
    uint32_t geomId = 0, primId = 0, instId = 0xFFFFFFFFu;
};

class RayScene {
public:
    static Result<std::unique_ptr<RayScene>> build(const SceneModel& city);
    ~RayScene();
    glm::dvec3 frameOrigin() const;  // world position of the scene-local origin
    // Single ray in scene-local coordinates. dir must be unit length.
    RayHit intersect(const glm::vec3& org, const glm::vec3& dir, float tnear = 0.0f, float tfar = 1e30f) const;
    // Coherent batch (packets of 8 internally): n rays sharing no constraints.
    void intersectMany(const glm::vec3* org, const glm::vec3* dir, int n, RayHit* out, float tfar = 1e30f) const;
    // Occlusion test: true if anything lies within (tnear, tfar).
    bool occluded(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar) const;
    size_t triangleCount() const;  // rendered triangles (instances expanded)

private:
    RayScene();
    struct Impl;
    std::unique_ptr<Impl> _impl;
};

}  // namespace vista
