// RayScene: the one Embree wrapper: the scene of a loaded city (raycast mode,
// hybrid far field) or of a triangle soup (the bake's far field of one
// impostor, in the impostor's float frame).
//
// Contract: a city scene is built once from a SceneModel (tile meshes as triangle geometry,
// tree prototypes as instanced geometry); immutable afterwards, so every
// method is thread-safe. Coordinates: world double positions are converted
// to a scene-local float frame around `frameOrigin()` (the city centre), so
// precision holds 1,000 km from the world origin. Hits return the
// interpolated prelit vertex colour: the same colour the rasteriser shows.
// Back faces (triangles clockwise as seen along the ray) are culled, as the
// rasteriser culls them (CullFace BACK on the city root).
// Embree errors are mapped to Status at construction; nothing throws from a
// ray-casting loop. FTZ/DAZ are set on every thread that casts.
// Soup scenes (build(TriangleSoup, SoupSceneOptions)): the soup's positions
// are used as they are (the caller's float frame; frameOrigin() reports the
// option's value), one triangle geometry, no robust traversal, the build
// quality and back-face culling as the options say (default: medium, no
// culling), and the caller's floating-point mode is left alone (no FTZ/DAZ).
// Bad soups (colour count != vertex count, index out of range or not a
// multiple of 3, non-finite vertex) are a returned Status.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "foundation/status.h"
#include "runtime/scene/scene_model.h"

struct RTCSceneTy;  // Embree's scene handle (RTCScene), opaque here

namespace vista {

struct RayHit {
    bool hit = false;
    float t = 0;             // distance along the (unit) ray direction, metres
    glm::u8vec4 color{0};    // prelit colour at the hit
    glm::vec3 normal{0.0f};  // geometric normal, scene-local frame
    uint32_t geomId = 0, primId = 0, instId = 0xFFFFFFFFu;
    float u = 0, v = 0;  // barycentric coordinates of the hit in its triangle
};

// Triangles in one float frame, a prelit colour per vertex.
struct TriangleSoup {
    std::vector<glm::vec3> positions;
    std::vector<glm::u8vec4> colors;  // per vertex (same size as positions)
    std::vector<uint32_t> indices;    // 3 per triangle
    size_t triangleCount() const { return indices.size() / 3; }
};

// What a hit of a city scene struck: the SceneModel mesh index (tile
// meshes) or the instance index (trees), the other -1; both -1 for a miss or
// a soup scene. primId of the hit indexes the mesh's / prototype's triangles.
struct HitSource {
    int mesh = -1;
    int instance = -1;
};

enum class RayBuildQuality { Low, Medium, High };

struct SoupSceneOptions {
    RayBuildQuality quality = RayBuildQuality::Medium;
    bool cullBackFaces = false;   // true: as the rasteriser and the city build
    glm::dvec3 frameOrigin{0.0};  // reported by frameOrigin(); not applied to the positions
};

class RayScene {
public:
    static Result<std::unique_ptr<RayScene>> build(const SceneModel& city);
    static Result<std::unique_ptr<RayScene>> build(const TriangleSoup& soup, const SoupSceneOptions& options = {});
    ~RayScene();
    glm::dvec3 frameOrigin() const;  // world position of the scene-local origin
    // Single ray in scene-local coordinates. dir must be unit length.
    RayHit intersect(const glm::vec3& org, const glm::vec3& dir, float tnear = 0.0f, float tfar = 1e30f) const;
    // Coherent batch (packets of 8 internally): n rays sharing no constraints.
    // tfars (optional, n values): a far limit per ray instead of `tfar`;
    // tnear: every ray starts there (surfaces nearer are not seen; tnear > tfar = a miss).
    void intersectMany(const glm::vec3* org, const glm::vec3* dir, int n, RayHit* out, float tfar = 1e30f,
                       const float* tfars = nullptr, float tnear = 0.0f) const;
    // Occlusion test: true if anything lies within (tnear, tfar).
    bool occluded(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar) const;
    // Coherent batch of occlusion tests (packets of 8): out[i] = 1 if anything
    // lies within (tnear, tfars[i]) along ray i, else 0 (also when tnear > tfars[i]).
    void occludedMany(const glm::vec3* org, const glm::vec3* dir, int n, const float* tfars, uint8_t* out,
                      float tnear = 0.0f) const;
    // All surfaces along the ray in (tnear, tfar), nearest first, at most
    // maxHits: each next cast starts max(minGap, 1e-5 t) beyond the last hit.
    int allHits(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar, int maxHits, float minGap,
                RayHit* out) const;
    // allHits for n rays at once, in packets of 8 (each layer one packet
    // cast for the lanes still going): ray i's hits go to
    // out[i * maxHits .. i * maxHits + counts[i]), nearest first, within
    // (tnears[i], tfars[i]) (tnears[i] > tfars[i]: no hit). The same rule
    // as allHits for the next cast.
    void allHitsMany(const glm::vec3* org, const glm::vec3* dir, int n, const float* tnears, const float* tfars,
                     int maxHits, float minGap, RayHit* out, int* counts) const;
    // The prelit colour at a hit, interpolated and not rounded: RGB 0..1.
    glm::vec3 hitColor(const RayHit& h) const;
    // The SceneModel entity a hit struck (ground-truth labels).
    HitSource source(const RayHit& h) const;
    size_t triangleCount() const;  // rendered triangles (instances expanded)
    // The committed Embree scene (RTCScene), for timing raw Embree on the same
    // BVH (tests/bench/bench_raw_rays.cpp). Read-only queries only; owned
    // here (never release or modify it); the caller sets FTZ/DAZ itself.
    RTCSceneTy* embreeScene() const;

private:
    RayScene();
    struct Impl;
    std::unique_ptr<Impl> _impl;
};

}  // namespace vista
