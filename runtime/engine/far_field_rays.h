// Primary rays: the camera's pixel-centre rays cast into a RayScene, written
// as colours (prelit colour on a hit, sky colour on a miss). One loop serves
// the far field's ray stage (far_field_rays.cpp) and the whole-frame raycast
// of the `raycast` render mode (frame_raycast.h); the haze of their pixels is
// far_field_haze.h.
//
// Directions: PixelRays::dir(x, y) == Camera::rayDirection(x + 0.5, y + 0.5)
// bit for bit (the same operations in the same order, basis hoisted). Origin:
// the eye in the scene's local frame. A miss shows primarySkyColor(dir) =
// skyColor(asin(dir.z)), the rasteriser's background, alpha 255.
//
// Coherence: the pixel list is cut into runs at image-row changes (a run
// closes at a row change once it holds a packet, so a dense row is one run and
// sparse rows share packets); each run is cast in 8-wide packets
// (RayScene::intersectMany), runs in parallel in a tbb::task_arena of
// `threads` workers (0 = the caller's arena, all cores). castFrame casts one
// run per row. A pixel's packet depends on the list only, never on the thread
// count, so images and counts are deterministic. Any order is correct;
// ascending order (rows contiguous) gives the coherent packets.
//
// Contract (VISTA_CHECK): out has the camera's size; every pixel index
// (y * width + x) is < width * height. Nothing throws; thread-safe for
// distinct outputs (the RayScene is immutable).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "runtime/engine/frame_effects.h"
#include "runtime/engine/frame_stats.h"
#include "runtime/engine/image.h"
#include "runtime/scene/camera.h"

namespace vista {

class RayScene;

// The camera's pixel-centre ray directions with the view basis computed once.
class PixelRays {
public:
    explicit PixelRays(const Camera& camera);
    // Image-plane offsets of pixel centres at unit distance along forward:
    // dir = normalize(forward + screenX * right + screenY * up).
    double screenX(int x) const { return (2.0 * (x + 0.5) / _width - 1.0) * _tanHalf * _aspect; }
    double screenY(int y) const { return (1.0 - 2.0 * (y + 0.5) / _height) * _tanHalf; }
    glm::dvec3 dir(int x, int y) const { return glm::normalize(_f + screenX(x) * _r + screenY(y) * _u); }

private:
    glm::dvec3 _f, _r, _u;
    double _tanHalf, _aspect;
    int _width, _height;
};

// Sky colour of a ray that hits nothing (unit direction, world frame).
glm::u8vec4 primarySkyColor(const glm::dvec3& dir);

// Smallest cos(angle to the forward axis) of any pixel-centre ray of the camera (the corners).
double minForwardCosine(const Camera& camera);

// The packet grouping of castPrimaryRays for a pixel list: the start of
// every run (see Coherence above), then n. Empty list: {0}.
std::vector<size_t> coherentRuns(const uint32_t* pixels, size_t n, int width);

// The rays castPrimaryRays casts for the listed pixels, bit for bit: the eye
// in the scene-local frame around `frameOrigin`, unit float directions, and
// far limits (hazeFar > 0: where the ray's eye-plane depth reaches hazeFar;
// else 1e30), and where they start (tnear, RayShading::tnear). For timing
// the stage against raw Embree (bench_raw_rays).
struct PrimaryRays {
    glm::vec3 org{0.0f};
    float tnear = 0.0f;
    std::vector<glm::vec3> dirs;
    std::vector<float> tfars;
};
PrimaryRays primaryRays(const Camera& camera, const glm::dvec3& frameOrigin, const uint32_t* pixels, size_t n,
                        double hazeFar, double tnear = 0.0);

struct RayCounts {
    uint64_t rays = 0;  // rays cast (hit or miss)
    uint64_t hits = 0;  // rays that hit geometry
};

// What the rays of a frame shade with: run-time effects (haze clips rays at
// fx.hazeFar() of eye-plane depth, hits beyond show the sky; night sky) and,
// optionally, the eye-plane depth of every entry (+inf on a miss) for the
// haze stage. Glass marks (alpha) of hit colours are kept.
// The surface a ray showed: its triangle (geometry, primitive, instance), or
// all ~0 for a ray that showed the sky (a miss, or a hit beyond the haze).
struct SurfaceKey {
    uint32_t geom = ~0u, prim = ~0u, inst = ~0u;
    bool sky() const { return geom == ~0u; }
    bool operator==(const SurfaceKey& o) const { return geom == o.geom && prim == o.prim && inst == o.inst; }
};

struct RayShading {
    const FrameEffects* effects = nullptr;  // null = none
    float* depth = nullptr;                 // n entries (castPrimaryRays) or width*height (castFrame)
    SurfaceKey* keys = nullptr;             // optional, like depth: the surface each entry showed
    // Rays start at this distance (metres, >= 0): the far field sets the near distance, since a
    // pixel the near field left uncovered has no surface nearer than it (nodes/near_far_split.h).
    float tnear = 0.0f;
    // Every pixel that shows a surface is hazed as it is written (DepthHaze, at its eye-plane
    // depth; needs effects with haze), so no pass over the pixels follows.
    bool haze = false;
};

// Casts the rays of the n listed pixels (indices y * width + x) and writes
// their colours into `out`; other pixels are untouched. Adds to `counts`.
// hit (optional, n entries): 1 where entry k's ray hit geometry, else 0.
void castPrimaryRays(const RayScene& scene, const Camera& camera, const uint32_t* pixels, size_t n, Image& out,
                     RayCounts& counts, int threads, uint8_t* hit = nullptr, const RayShading& shading = {});

// The listed pixels (null = every pixel of the frame, in order) grouped into
// the given runs: the entries runs[r] .. runs[r + 1] - 1 of every run r
// (runs.back() = the entry count), each run cast in packets of 8, runs in
// parallel. castPrimaryRays groups its list with coherentRuns();
// castFrame (frame_raycast.h) casts one run per image row.
void castPixelRuns(const RayScene& scene, const Camera& camera, const uint32_t* pixels, const std::vector<size_t>& runs,
                   Image& out, RayCounts& counts, int threads, uint8_t* hit, const RayShading& shading);

}  // namespace vista
