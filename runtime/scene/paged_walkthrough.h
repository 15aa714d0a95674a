// A paged city (paged_load.h) opened for a walkthrough: first the manifest
// and the streets a seeded path runs on, so that the path exists before any
// region is read; then the regions near that path.
//
// openPagedCity(): reads DIR/manifest.json; `stub` gets the params and,
// when `needStreets` (the walkthrough is made from a seed, not read from a
// CSV), the street graph of pagedPathStreets(). Errors are those of
// readPagedManifest() and pagedPathStreets().
//
// loadPagedNear(): loads the regions within reach.radius metres of the
// path's samples at full detail and the others within reach.far at their
// coarse level (selectPagedRegions / selectCoarseRegions; a path without
// samples counts as the city's origin) and merges them (loadPagedCity).
// Unless `quiet`, a note naming the counts goes to stderr, prefixed "CMD: ";
// every damaged region file is a warning there whatever `quiet` says.
// `pagedJson` (if not null) receives the summary.json block {regions_loaded,
// regions_total, radius_m, bytes_loaded, coarse_regions_loaded, far_m,
// coarse_bytes_loaded, damaged}. `beforeLoad` (if set) is called with the
// selected files' bytes before any is read (a memory-budget check); its
// error stops the load and is returned.
#pragma once
#include <cstdint>
#include <functional>
#include <string>

#include "foundation/status.h"
#include "runtime/scene/paged_load.h"
#include "runtime/scene/paths.h"
#include "runtime/scene/scene_model.h"

namespace vista {

// How much of a paged city a walkthrough loads: regions within `radius`
// metres of the path at full detail, the others within `far` metres at their
// coarse level (0 or <= radius: none). Both in [kMinPagedRadiusM,
// kMaxPagedRadiusM] (validatePagedRadius).
struct PagedReach {
    double radius = kDefaultPagedRadiusM;
    double far = kDefaultPagedFarM;
};

struct PagedOpen {
    PagedManifest manifest;
    SceneModel stub;  // params, and the path streets when asked for
};

Result<PagedOpen> openPagedCity(const std::string& dir, bool needStreets);
Result<SceneModel> loadPagedNear(const PagedOpen& city, const Path& path, const PagedReach& reach, const char* cmd,
                                 bool quiet, std::string* pagedJson = nullptr,
                                 const std::function<Status(uint64_t bytes)>& beforeLoad = nullptr);

}  // namespace vista
