// RayScene: the one Embree wrapper: the scene of a loaded city (raycast mode,
// hybrid far field) or of a triangle soup (the bake's far field of one
// impostor, in the impostor's float frame).
//
// Contract: a city scene is built from a SceneModel. Coordinates: world
// double positions are given to the queries in a scene-local float frame
// around `frameOrigin()` (the city centre). Layout (RaySceneOptions):
//  - regions (default): the city's tile meshes are grouped into square
//    regions of `regionSizeM` (by mesh origin); each region is its own Embree
//    scene with its vertices relative to the region's origin (a whole number
//    of metres from frameOrigin, so the instance's translation is exact in
//    float), instanced into a top-level scene by a translation. Trees are
//    instances of prototype scenes in the top-level scene. Vertex precision is
//    then that of a region's extent (0.1 mm for 2 km), wherever the region
//    lies; ray origins are floats around frameOrigin (half a float step of
//    |eye - frameOrigin|: 1 mm at 16 km), so callers that move far keep the
//    frame near the camera with placeFrameNear().
//  - flat (`regionSizeM` = 0): every tile mesh is one triangle geometry of one
//    scene, its vertices relative to frameOrigin.
//  - paged (the model has SceneModel::regions spans, a paged city merged by
//    loadPagedCity, and `regionSizeM` > 0): one region per span, in span
//    order, as addRegion(region model) makes it from that region's own file,
//    so a scene streamed region by region (in the same order) gives the same
//    hits as this one.
// Regions can be added and removed after the build (addRegion, removeRegion,
// then commit: a commit of the top-level scene, the other regions' BVHs are
// kept). Queries are const and thread-safe among themselves; addRegion,
// removeRegion and commit must not run while another thread queries or
// changes the scene (a pager swaps regions between frames).
// Hits return the interpolated prelit vertex colour: the same colour the
// rasteriser shows. Back faces (triangles clockwise as seen along the ray)
// are culled, as the rasteriser culls them (CullFace BACK on the city root).
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
    // Embree's ids of the hit; instId 0xFFFFFFFF: none; a moving object's hit
    // (placeMovers) has the top bit of instId set (ids unique across both scenes).
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
// impostor: a tree of a coarse level (SceneModel::impostors), traced as its
// prototype's mesh; then mesh and instance are -1. region: the region the hit
// lies in (the index build() gave it or the id addRegion() returned; -1 for
// flat and soup scenes); mesh, instance and impostor index the SceneModel that
// region was made from (build(): the city).
// mover: a moving object placed by placeMovers() (its index in that list),
// with the label given there (moverId, moverClass); -1 otherwise. still: a
// still object of placeMovers()'s `still` list (its slot), labelled the same
// way (moverId, moverClass); -1 otherwise.
struct HitSource {
    int mesh = -1;
    int instance = -1;
    int impostor = -1;
    int region = -1;
    int mover = -1;
    int still = -1;
    uint32_t moverId = 0;
    uint8_t moverClass = 0;
};

// One moving object of a frame (placeMovers): a prototype of
// setMoverPrototypes() placed by `transform` (prototype frame -> world), with
// its ground-truth label (citygen/labels.h instance id and semantic class).
struct MoverPlacement {
    uint32_t prototype = 0;
    glm::dmat4 transform{1.0};
    uint32_t id = 0;
    uint8_t cls = 0;
};

// One slot of placeMovers()'s still objects: an object that stands where it
// is from call to call (a traffic light's lamp overlay) and only sometimes
// changes what it shows (its prototype) or is hidden.
struct StillPlacement {
    MoverPlacement object;
    bool shown = true;
};

// What the far field's cache needs of a still slot (RayScene::stillObjects):
// its world bounding sphere (centre xyz, radius w; the last one it had when
// hidden), whether it is shown, and `version`: the value of stillSerial() at
// its last change (appeared, hidden, another prototype, transform or label).
struct StillState {
    glm::dvec4 sphere{0.0};
    bool shown = false;
    uint64_t version = 0;
};

enum class RayBuildQuality { Low, Medium, High };

struct SoupSceneOptions {
    RayBuildQuality quality = RayBuildQuality::Medium;
    bool cullBackFaces = false;   // true: as the rasteriser and the city build
    glm::dvec3 frameOrigin{0.0};  // reported by frameOrigin(); not applied to the positions
};

// Grid of the frame origins placeFrameNear() chooses, metres.
constexpr double kFrameCellM = 1000.0;

// How a city scene is laid out (see the contract above).
struct RaySceneOptions {
    double regionSizeM = 2000.0;  // side of a region, metres; 0: one flat scene
};

class RayScene {
public:
    static Result<std::unique_ptr<RayScene>> build(const SceneModel& city, const RaySceneOptions& options = {});
    // A city scene without geometry (frame origin given), for regions added later.
    static Result<std::unique_ptr<RayScene>> empty(const glm::dvec3& frameOrigin);
    // Regions built after this call (addRegion, prepareRegion) use Embree's compact layout
    // (RTC_SCENE_FLAG_COMPACT): measured on a streamed 1,024 km² drive, the process's peak
    // memory 16 % lower and the hybrid's frames 6 to 8 % slower (docs/measurements/paging.md).
    void setCompactRegions(bool compact);
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

    // Adds the tiles `tiles` (indices into model.tiles) of `model` as one
    // region: their meshes in a new Embree scene (region-local vertices,
    // origin: the first mesh's origin rounded to whole metres from
    // frameOrigin) instanced into the top-level scene, and their trees
    // (model.instances, and model.impostors drawn as their prototype meshes
    // when the model has them) as instances of the model's prototypes. The
    // model is not kept. Returns the region's id (>= 0, never reused). Seen
    // by queries after commit(). Errors: a tile index out of range, a
    // malformed mesh, an instance of a missing prototype, an Embree error;
    // the scene is then unchanged. Not for flat or soup scenes.
    Result<int> addRegion(const SceneModel& model, const std::vector<uint32_t>& tiles);
    // The whole model as one region: every tile's meshes and trees and every
    // impostor of a prototype the model has (a paged city's region file, full
    // or coarse). The same errors; a model without tiles is an error.
    Result<int> addRegion(const SceneModel& model);
    // A region built off the frame thread: prepareRegion() makes it (on any
    // thread), addPrepared() instances it (between frames).
    struct PreparedRegion;
    // Builds what addRegion(model) adds (the region's Embree scene and its
    // tree prototypes) without changing this scene: it uses only the scene's
    // Embree device, so it may run on another thread while the scene is
    // queried or changed. The model is not kept (the trees' transforms are
    // copied). Errors: those of addRegion(model).
    Result<std::shared_ptr<PreparedRegion>> prepareRegion(const SceneModel& model) const;
    // Instances a prepared region into the top level (seen after commit()),
    // with the hits, ids and errors of addRegion(model). A prepared region is
    // added once. Errors: one prepared by another scene, or added already.
    Result<int> addPrepared(const std::shared_ptr<PreparedRegion>& region);
    // Detaches a region (its instance and its trees): seen after commit().
    // Errors: no live region with that id.
    Status removeRegion(int region);
    // Commits the top-level scene (only its instance BVH is rebuilt).
    Status commit();
    // Moving objects (a traffic run's agents, city scenes): the prototype
    // meshes (SceneMesh positions relative to their origin, in the
    // prototype frame; colours per vertex) become Embree scenes once, and the
    // first call makes the movers' scene: a small instance scene beside the
    // top level (which is never rebuilt for movers). placeMovers() then shows
    // exactly the given objects, one instance each in the movers' scene,
    // re-placed or hidden (rtcDisableGeometry) from a pool of instances, and
    // commits that scene alone. Every query sees both scenes as one: the
    // nearer hit (the top level's at an equal distance), occluded by either;
    // while no object is placed, queries trace the top level alone. Hits
    // report the object's index and label (HitSource). A new prototype set
    // hides the objects placed before. Errors: a malformed prototype, an
    // unknown prototype index, an Embree error. A scene without
    // setMoverPrototypes() has no movers' scene and no mover in it.
    // still (optional; null = as they are): the still objects, one slot per
    // entry (slot i = entry i; slots beyond the list are hidden). They share
    // the movers' scene and its commit, but only a slot whose entry differs
    // from what it shows is re-placed, and each such change advances
    // stillSerial() and the slot's StillState::version; they are not in
    // moverSpheres() (the far field's cache keeps their pixels and forgets
    // them only when they change: far_field.h). A new prototype set hides
    // every slot (a change of each shown one).
    Status setMoverPrototypes(const std::vector<SceneMesh>& prototypes);
    Status placeMovers(const std::vector<MoverPlacement>& movers, const std::vector<StillPlacement>* still = nullptr);
    size_t moverCount() const;  // objects of the last placeMovers()
    // World bounding spheres (centre xyz, radius w) of the last placeMovers()'s
    // objects, in its order (the far field's cache keeps their pixels out).
    const std::vector<glm::dvec4>& moverSpheres() const;
    // Per still slot (every slot placed so far, shown or hidden): see StillState.
    const std::vector<StillState>& stillObjects() const;
    // Advances with every change of a still slot (0 = none yet).
    uint64_t stillSerial() const;
    // placeMovers() calls that placed objects and committed the movers' scene (a counter for tests
    // and the frame's bookkeeping: a caller that re-places nothing does not call).
    uint64_t moverCommits() const;
    int regionCount() const;  // live regions
    // Moves the scene-local frame (regions layout): frameOrigin() becomes
    // `frameOrigin` rounded to whole metres from the current one, every
    // top-level instance is re-placed and the top level committed (no region
    // BVH is rebuilt). Keeping it near the camera keeps float ray origins
    // exact to a few micrometres. Not while another thread queries.
    // Errors: a flat or soup scene.
    Status setFrameOrigin(const glm::dvec3& frameOrigin);
    // setFrameOrigin() to the point of a kFrameCellM grid (around the origin
    // the scene was built with, in x and y) nearest `eye`: a function of the
    // eye alone, so a frame's rays do not depend on the frames before it.
    // Within 710 m of the eye the float step of a ray origin is 61 um at
    // most. No-op for flat and soup scenes. Not while another thread queries.
    Status placeFrameNear(const glm::dvec3& eye);
    // The committed top-level Embree scene (RTCScene; the moving objects are
    // in embreeMoverScene()), for timing raw Embree on the same
    // BVH (tests/bench/bench_raw_rays.cpp). Read-only queries only; owned
    // here (never release or modify it); the caller sets FTZ/DAZ itself.
    RTCSceneTy* embreeScene() const;
    // The movers' Embree scene (setMoverPrototypes), null when there is none;
    // the same terms as embreeScene().
    RTCSceneTy* embreeMoverScene() const;

private:
    RayScene();
    struct Impl;
    std::unique_ptr<Impl> _impl;
};

}  // namespace vista
