// FarScene: a small Embree scene of one impostor's far field (the tiles it
// replaces), in the impostor's float frame. Used by LDI sampling (all hits
// along a ray) and Monte Carlo appearance (first hit, occlusion).
//
// Why not RayScene: the bake needs a scene per far field (only the replaced
// tiles, so points never come from geometry that stays drawn) and an all-hits
// query; both are a few lines on top of Embree. Shading matches RayScene and
// the rasteriser: the interpolated prelit vertex colour.
//
// Contract: build() copies the triangles; bad input (index out of range,
// non-finite vertex) and Embree errors are a returned Status. Immutable after
// build, so every query is thread-safe. dir must be unit length.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "foundation/status.h"

namespace vista {

struct FarHit {
    bool hit = false;
    float t = 0;
    glm::vec3 normal{0.0f};  // unit geometric normal (not oriented)
    glm::vec3 color{0.0f};   // prelit colour, 0..1
};

struct TriangleSoup {
    std::vector<glm::vec3> positions;
    std::vector<glm::u8vec4> colors;  // per vertex (same size as positions)
    std::vector<uint32_t> indices;    // 3 per triangle
    size_t triangleCount() const { return indices.size() / 3; }
};

class FarScene {
public:
    static Result<std::unique_ptr<FarScene>> build(const TriangleSoup& soup);
    ~FarScene();
    FarHit intersect(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar) const;
    bool occluded(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar) const;
    // All surfaces along the ray in (tnear, tfar), nearest first, at most
    // maxHits; successive hits are at least `minGap` apart.
    int allHits(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar, int maxHits, float minGap,
                FarHit* out) const;
    size_t triangleCount() const;

private:
    FarScene();
    struct Impl;
    std::unique_ptr<Impl> _impl;
};

}  // namespace vista
