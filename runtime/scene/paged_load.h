// Reading a paged city (docs/formats.md "Paged city", written by
// bake/gen/paged_city.h): the regions near a walkthrough, merged into one SceneModel,
// so that `vista bench/view/path DIR.paged` fit a 32 or 64 km city in memory.
//
// readPagedManifest(): parses DIR/manifest.json (format "vista.paged_city",
// version kPagedCityVersion) into the region list. Errors name the file and the field, the
// value as written and the allowed range (docs/formats.md "Paged city"):
// missing or unreadable manifest, bad JSON, wrong format or version; a
// `generation` that is not {seed, key} (key: 16 hex digits) or whose seed is
// not the params' seed;
// region_size_m outside validateRegionSize's range (citygen/regions.h);
// regions_x/regions_y outside 1 .. kMaxManifestRegionsPerSide or other than
// the grid region_size_m makes of the city; per region: region, ix, iy not
// integers of the grid (entry i must be region i, at ix = i % regions_x, iy =
// i / regions_x: a region listed twice is refused), empty not a boolean,
// triangles not an integer in 0 .. kMaxManifestCount; for a non-empty
// region, bounds that are not 6 finite numbers with min <= max, files
// without exactly one "full" and one "coarse" entry, a role other than
// those, a name that is empty, has a path separator or is listed by
// another region, bytes not an integer in 1 .. kMaxRegionFileBytes; and a
// manifest whose every region is empty.
//
// The generation's identity: every region file (full and coarse level) of a
// paged city carries, as user values of its root, kPagedGenerationKey (the
// generation key: a hash of the canonical params, the region size and the
// format, the key of the writer's records) and kPagedSeedKey (the seed, in
// decimal); the manifest's `generation` holds the same two. A region file
// whose identity differs from its manifest's (regions of two generations
// mixed in one directory) is refused by loadPagedRegion(), never drawn.
//
// selectPagedRegions(): the non-empty regions whose world xy bounds
// (manifest `bounds`) come within `radiusM` metres (2D distance to the
// rectangle) of at least one of `points` (world metres), in region order.
//
// selectCoarseRegions(): the non-empty regions within `farM` of the points
// that are not in `full` (the regions loaded at full detail), in region
// order: the far city, loaded at its coarse level (bake/gen/paged_city.h: detail 0, no
// trees) so that the ray-cast far field still sees it. farM <= radius of
// `full`, or 0: none.
//
// loadPagedCity(): loads each selected region's full file (loadCityFile;
// its size must match the manifest's), then each `coarse` region's coarse
// file (the same checks), and merges them: tiles, meshes and tree instances
// of every region in that order (the merged graph is a new "vista.city" root
// over the regions' tile transforms, SceneTile::child indexes it; one
// SceneModel::regions span per region read, in that order), the root
// state and user values of the first full region; streets = the union of the
// regions' street graphs (nodes merged by exact position, edges by their end
// nodes, in first-seen order), a subgraph of the city's graph. Ground-truth
// ids are numbered per region, so the merged model is unlabelled (labelled =
// false, ids empty). A missing, truncated or corrupt region file (or one
// whose size differs from the manifest) does not stop the load: its message
// (naming the file) goes to report->damaged, a full region then falls back to
// its coarse level, and the rest of the city loads. A region file of another
// generation than the manifest's is an error (loadPagedRegion). Errors: no region
// selected (points far from the city, or none), or no full region readable
// (the message names the radius or every damaged file).
//
// loadPagedRegion(): region `region`'s full file (or its coarse level),
// after checking that the file exists and has the manifest's size; the
// region's own SceneModel (loadCityFile), whose generation identity must be
// the manifest's. Errors name the file: missing, another size than the
// manifest's, unreadable or corrupt; another generation than the manifest's
// (the message names the region file and the manifest, and `foreign`, if not
// null, is set: such a directory is refused, whatever the caller does with
// damaged files); an empty region or an index out of range. Thread-safe
// (reads the manifest only).
//
// pagedPathStreets(): the street graph that a path of a paged city made from
// a seed runs on: the whole city's graph, grown again from the manifest's
// params (growStreets, as `vista gen` made it: paged cities are never OSM
// imports; about a second for the 64 km city), so `--seed N` gives the same
// path as on the single-file city of the same params. No region is read.
// Radius: kMinPagedRadiusM .. kMaxPagedRadiusM (validatePagedRadius names
// the option, the value and the range).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/params.h"
#include "citygen/street_graph.h"
#include "foundation/status.h"
#include "runtime/scene/scene_model.h"

namespace vista {

// The index and the manifest inside a paged city's directory (written by
// `vista gen -o DIR.paged`, bake/gen/paged_city.h).
constexpr const char* kPagedIndexFile = "index.osgb";
constexpr const char* kPagedManifestFile = "manifest.json";
// The paged city format's version (manifest `version`, the index's vista.format).
constexpr int kPagedCityVersion = 2;
// User values on every region file's root: the generation's identity (see above).
constexpr const char* kPagedGenerationKey = "vista.generation";
constexpr const char* kPagedSeedKey = "vista.seed";

constexpr double kDefaultPagedRadiusM = 3000.0;
constexpr double kMinPagedRadiusM = 0.0;
constexpr double kMaxPagedRadiusM = 100000.0;
// Default reach of the coarse far city (--paged-far): every region of the largest city.
constexpr double kDefaultPagedFarM = kMaxPagedRadiusM;
// Ranges of manifest.json's fields (readPagedManifest): regions per side,
// a region file's bytes, a region's triangle count.
constexpr int kMaxManifestRegionsPerSide = 4096;
constexpr uint64_t kMaxRegionFileBytes = uint64_t(1) << 40;  // 1 TiB
constexpr uint64_t kMaxManifestCount = uint64_t(1) << 40;

struct PagedRegionEntry {
    int region = 0, ix = 0, iy = 0;
    bool empty = true;
    glm::dvec3 lo{0.0}, hi{0.0};  // world bounds of the geometry (non-empty only)
    std::string file;             // the full file, relative to the directory
    uint64_t bytes = 0;           // its size per the manifest
    std::string coarseFile;       // the coarse level, relative to the directory
    uint64_t coarseBytes = 0;     // its size per the manifest
    uint64_t triangles = 0;       // rendered triangles per the manifest
};

struct PagedManifest {
    std::string dir;
    CityParams params;
    std::string generation;  // the generation key (manifest generation.key, 16 hex digits)
    double regionSizeM = 0;
    int regionsX = 0, regionsY = 0;
    std::vector<PagedRegionEntry> regions;  // every region of the grid, empty ones included
    int nonEmpty() const;
};

struct PagedLoadReport {
    int regionsLoaded = 0;
    int regionsTotal = 0;  // non-empty regions of the city
    double radiusM = 0;
    uint64_t bytesLoaded = 0;          // file bytes of the loaded regions (full and coarse)
    int coarseLoaded = 0;              // regions loaded at their coarse level
    uint64_t coarseBytes = 0;          // file bytes of those coarse files
    std::vector<std::string> files;    // loaded region files (relative names), full then coarse
    std::vector<std::string> damaged;  // one message per missing or damaged file (it names the file)
};

// True when `path` is a directory (a paged city is a directory; a city file is not).
bool isPagedCityPath(const std::string& path);
// `option` = `value` within [kMinPagedRadiusM, kMaxPagedRadiusM] and finite.
Status validatePagedRadius(const std::string& option, double value);

Result<PagedManifest> readPagedManifest(const std::string& dir);
std::vector<int> selectPagedRegions(const PagedManifest& m, const std::vector<glm::dvec2>& points, double radiusM);
std::vector<int> selectCoarseRegions(const PagedManifest& m, const std::vector<glm::dvec2>& points, double farM,
                                     const std::vector<int>& full);
Result<SceneModel> loadPagedCity(const PagedManifest& m, const std::vector<int>& regions, double radiusM,
                                 PagedLoadReport* report = nullptr, const std::vector<int>& coarse = {});
Result<SceneModel> loadPagedRegion(const PagedManifest& m, int region, bool coarse, bool* foreign = nullptr);
Result<StreetGraph> pagedPathStreets(const PagedManifest& m);

}  // namespace vista
