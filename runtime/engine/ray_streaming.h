// StreamedRayScene: the ray scene of a paged city fed by a RegionPager
// (runtime/scene/region_pager.h) that the caller owns (CityStream, which
// mirrors the same regions into the chunked graph and the near field): it
// starts empty (RayScene::empty around the city's origin) and, between
// frames, apply() mirrors what the pager handed over: each dropped level's
// region is removed, each arrived level added as one region (the region's
// own model, freed right after), then the top level is committed (only when
// something changed). Chunk parts (RegionArrival::chunks) are not traced and
// pass by. The whole scene is never rebuilt, and a region's
// Embree scene is built on the pager's worker thread (prepare(), from the
// pager's prepare hook): the frame thread only instances it.
//
// With the pager's wait option it blocks until the desired set is resident, so
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
// loadPagedCity() shares them in a merged model. So a coarse level is traced
// with its coarse geometry and its tree impostors as the full trees' meshes.
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
    // The caller's pager feeds it through apply(); the pager must be stopped before the scene
    // is destroyed (its workers call prepare()).
    static Result<std::unique_ptr<StreamedRayScene>> follower(const PagedManifest& manifest,
                                                              std::vector<SceneMesh> prototypes = {});
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

private:
    StreamedRayScene() = default;
    std::unique_ptr<RayScene> _rays;
    std::vector<SceneMesh> _prototypes;        // the city's tree prototypes
    std::map<std::pair<int, bool>, int> _ids;  // (manifest region, coarse) -> RayScene region id
};

}  // namespace vista
