// A paged city: a directory that stock osgviewer pages region by region
// (docs/formats.md "Paged city"), written by `vista gen -o DIR.paged`.
//
// Layout of DIR:
//   index.osgb                 root osg::Group "vista.paged_city" with one osg::PagedLOD
//                              per non-empty region (child 0: the coarse file, child 1:
//                              the region file, relative names; ranges pagedRanges())
//   region_IX_IY.osgb          a normal vista city file (city_file.h) of the region's tiles
//   region_IX_IY.coarse.osgb   its coarse level (RegionalCity::coarse), also a city file
//   manifest.json              params, region grid, per region: files, bytes, hashes, bounds, counts;
//                              `streets` names streets.json when the streets were given
//   streets.json               the whole street graph (streetGraphToJson) of a city whose streets
//                              were given (an OSM import), for readers that cannot grow it again
//   records/region_IX_IY.json  one record per finished region (what resume checks)
// and, when `xodr` names a file (beside or outside DIR), the road network of the whole
// city as one OpenDRIVE file (openDriveXml of the whole street graph and blocks: the bytes
// `vista gen --xodr` writes for the single-file city of the same streets), written with the
// index (staged into the same batch).
// Empty regions (no geometry) have a record and a manifest entry but no files and no PagedLOD.
//
// generatePagedCity(): generates every region of `options.shard` (region index
// % count == index) that has no valid record, writing each region's files
// atomically and then its record; a region whose record, file size or content
// hash does not match (a kill mid-write, a truncated or corrupt file, other
// params) is generated again, never trusted. Unsharded (count 1) or with
// `merge`, it then writes index.osgb and manifest.json (atomically, together)
// once every region has a valid record; `merge` generates nothing and is an
// error naming the missing regions when some are not done, and the shards
// K/N to run again when `mergeShards` gives the N the shards ran with. The bytes of every
// file depend only on params, the region size and the given inputs: the same for any thread
// count, any split into shards and any number of interruptions. Shards of one
// city may run concurrently in separate processes on the same directory.
// Memory: the street graph and blocks of the whole city plus one region; with
// `xodr`, also the lane model and the OpenDRIVE text of the whole road network.
//
// Contract: params valid (validateParams; size_m up to kMaxPagedSizeM),
// region size validateRegionSize, shard 0 <= index < count; otherwise an error
// Status naming the field, before anything is written. `dir` must be a
// directory or not exist (checkPagedOutput). I/O errors name the path. A run
// that fails before it finished a region leaves no directory it created
// (no empty DIR or records/); finished regions stay for the next run.
#pragma once
#include <cstdint>
#include <string>

#include "citygen/opendrive.h"
#include "citygen/params.h"
#include "citygen/regions.h"
#include "foundation/atomic_file.h"
#include "foundation/progress.h"
#include "foundation/shard.h"
#include "foundation/status.h"
#include "runtime/scene/paged_load.h"

namespace vista {

struct PagedCityOptions {
    std::string dir;
    double regionSizeM = 2000.0;
    Shard shard;
    bool merge = false;
    int mergeShards = 0;  // with merge: the N of the shards' K/N (0: unknown)
    // With merge: the command that runs one shard with the same parameters,
    // ending in `--shard` (the refusal appends K/N and prints it for each
    // shard to run again); empty: the refusal names the shards only.
    std::string shardCommand;
    Progress* progress = nullptr;
    // Given instead of grown (an OSM import: vista gen --osm); `inputKey`
    // identifies that input (e.g. a hash of the file and the import options)
    // in every region record, so a resume with other input remakes the regions.
    RegionalInputs inputs;
    std::string inputKey;
    // Non-null: index.osgb and manifest.json are staged into this batch and
    // the caller commits them with its own outputs (--stats); null: they are
    // committed here.
    OutputBatch* batch = nullptr;
    // Non-empty: write the whole road network as OpenDRIVE to this path when the
    // index is written (unsharded or merge; a shard writes none).
    std::string xodr;
};

struct PagedCityReport {
    int regions = 0;       // in the grid
    int generated = 0;     // this run
    int reused = 0;        // valid records found (this shard's regions)
    int regenerated = 0;   // of `generated`: had a record or files that did not check out
    int emptyRegions = 0;  // of those this run generated or reused
    bool indexWritten = false;
    bool xodrWritten = false;
    OpenDriveCounts roads;               // of the OpenDRIVE file, when xodrWritten
    size_t streetEdges = 0, blocks = 0;  // of the whole city (0 if nothing was generated)
    // Totals over the regions this run generated or reused.
    size_t buildings = 0, trees = 0, triangles = 0, bytes = 0;
    double baseSeconds = 0, regionSeconds = 0, indexSeconds = 0, xodrSeconds = 0;
};

// `dir` does not exist (its nearest existing ancestor is a writable directory)
// or is a writable directory; the message names `option` and the path.
Status checkPagedOutput(const std::string& option, const std::string& dir);

Result<PagedCityReport> generatePagedCity(const CityParams& params, const PagedCityOptions& options);

// File names inside DIR (relative; the index and the manifest: paged_load.h).
std::string regionFileName(int ix, int iy);
std::string coarseFileName(int ix, int iy);

// PagedLOD ranges (metres from the eye to the region's bounding-sphere centre)
// for a region of `regionSizeM` and bounding radius `radius` in a city of side
// `citySizeM`: full detail within radius + regionSizeM; the coarse level out
// to radius + clamp(4 x the city's half-diagonal, 6, 16 region sizes) (so
// osgviewer's home view of a small city shows it), nothing beyond.
void pagedRanges(double regionSizeM, double citySizeM, double radius, double& fullRange, double& coarseRange);

}  // namespace vista
