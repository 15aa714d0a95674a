// StreamedRayScene: the ray scene of a paged city fed by a RegionPager
// (runtime/scene/region_pager.h): it starts empty (RayScene::empty around the
// city's origin) and, between frames, advance() moves the pager to the
// camera and mirrors what it hands over: each dropped level's region is
// removed, each arrived level added as one region (RayScene::addRegion of the
// region's own model, freed right after), then the top level is committed
// (only when something changed). The whole scene is never rebuilt, and a
// region's Embree scene is built on the pager's worker thread (prepare()):
// the frame thread only instances it.
//
// With options.wait the pager blocks until the desired set is resident, so
// every frame sees exactly the regions within reach of its camera: the scene
// of a frame depends on the camera alone, and when the reach holds the same
// regions as a preloaded run (RayScene::build of the merged model, whose
// regions are added in the same order) the hits are the same.
//
// Trees: a coarse level carries no tree shapes of its own (its impostors
// name the city's prototypes), and a region file may lack shapes it does not
// use; every prototype a region model leaves empty is taken from the city's
// tree prototypes (`prototypes` of create(): those of a loaded full region,
// the same for every region of a city; empty = read from the first full
// region file that loads, at set-up, before the first frame), as
// loadPagedCity() shares them in a merged model.
//
// Errors: an Embree error while adding a region (a Status naming it; the
// scene is then unchanged). A damaged region file is no error: its message
// comes back in the frame's `damaged` and the region falls back as the pager
// says. Not thread-safe: advance() runs between frames, never while another
// thread queries rays().
#pragma once
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "foundation/status.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/region_pager.h"

namespace vista {

// What advance() changed.
struct RayStreamFrame {
    int arrived = 0;  // levels added to the scene
    int dropped = 0;  // levels removed from it
    bool waited = false;
    std::vector<std::string> damaged;  // files that failed to load (each once)
};

class StreamedRayScene {
public:
    ~StreamedRayScene();  // stops the pager first: its workers use the scene
    // `manifest` must outlive the scene. With its own pager (advance()).
    static Result<std::unique_ptr<StreamedRayScene>> create(const PagedManifest& manifest,
                                                            const RegionPagerOptions& options,
                                                            std::vector<SceneMesh> prototypes = {});
    // Without a pager: the caller's pager feeds it through apply() (a
    // program that mirrors the same regions into other structures too).
    static Result<std::unique_ptr<StreamedRayScene>> follower(const PagedManifest& manifest,
                                                              std::vector<SceneMesh> prototypes = {});
    // Own pager: update, collect, apply. Contract: made by create().
    Result<RayStreamFrame> advance(const glm::dvec3& eye, const glm::dvec3& velocity);
    // Worker side (thread-safe): completes the model's tree prototypes and
    // builds its region (RayScene::prepareRegion); null when that fails
    // (apply() then adds the model itself and reports the error).
    std::shared_ptr<RayScene::PreparedRegion> prepare(SceneModel& model) const;
    // Mirrors one pager delta: drops, then arrivals, then a commit if
    // anything changed. prepared[i] (if given and not null) is arrival i's
    // region from prepare(); an arrival without one is prepared here, on the
    // calling thread.
    Result<RayStreamFrame> apply(RegionPagerDelta& delta,
                                 const std::vector<std::shared_ptr<RayScene::PreparedRegion>>& prepared = {});
    const RayScene& rays() const { return *_rays; }
    RayScene& rays() { return *_rays; }
    RegionPagerStats stats() const { return _pager ? _pager->stats() : RegionPagerStats(); }

private:
    StreamedRayScene() = default;
    std::unique_ptr<RayScene> _rays;
    std::unique_ptr<RegionPager> _pager;
    std::vector<SceneMesh> _prototypes;        // the city's tree prototypes
    std::map<std::pair<int, bool>, int> _ids;  // (manifest region, coarse) -> RayScene region id
};

}  // namespace vista
