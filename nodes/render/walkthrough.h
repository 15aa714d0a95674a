// loadWalkthrough(): what `vista view`, `vista bench` and `vista render` load
// before their first frame, in one order:
//   1. the city: a city file (loadCityFile), or a paged city directory
//      (paged_walkthrough.h: the manifest and the path first, then the
//      regions within request.paged of the path; refused unless
//      request.allowPaged; with request.streamPaged no region: the city is
//      the stub with the params and the path streets, and the program
//      streams the regions from Walkthrough::manifest);
//   2. request.checkCity(city), if set (e.g. the channels a city must carry);
//   3. the baked files the run's modes draw (loadPairedBakes);
//   4. the walkthrough: request.makePath(city) (for a paged city it ran
//      before step 1's regions were read, on the stub with the path streets);
//   5. the run-time effects: request.effects(the scene's declared effects)
//      into options.effects.
// Every error is bad input (a message naming the file, flag or field): the
// command reports it and exits with code 2. Notes and warnings go to stderr
// prefixed "CMD: " (request.cmd); request.quiet silences the notes.
//
// loadPairedBakes(): loads the baked files (options.bakedFile for impostor,
// and for lodmesh without a mesh bake; options.bakedMeshFile for lodmesh)
// that `modes` draw (every given one when `modes` is empty: the viewer
// switches modes at run time), checks each against the city opened as
// cityPath with root cityRoot (checkBakedFromCity) and keeps them in
// options.loadedBakes, so the modes do not load them again. Errors
// (unreadable, truncated, corrupt, not a baked file, baked from another
// city, a points bake as --baked-mesh, a mesh bake as --baked when mode
// impostor is asked) name the flag and the file. A file without a source city hash (an
// older bake) is a warning on stderr, not an error.
//
// walkthroughPath(): the CSV `csvFile` if not empty (loadPathCsv), else a
// path generated on the city's streets with `options` (generatePath).
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <osg/Node>

#include "citygen/effects.h"
#include "foundation/status.h"
#include "nodes/render/render_mode.h"
#include "runtime/engine/frame_effects.h"
#include "runtime/scene/paged_walkthrough.h"
#include "runtime/scene/paths.h"
#include "runtime/scene/scene_model.h"

namespace vista {

struct WalkthroughRequest {
    std::string city;              // a city file or a paged city directory
    const char* cmd = "vista";     // prefix of notes and warnings
    bool quiet = false;            // no notes on stderr (warnings stay)
    bool allowPaged = true;        // false: a directory is loaded as a city file (and refused by it)
    PagedReach paged;              // what a paged city loads around the path
    bool streamPaged = false;      // a paged city is streamed: no region is loaded here (the stub and manifest only)
    bool pathNeedsStreets = true;  // the path is generated on the streets (not read from a CSV)
    std::function<Result<Path>(const SceneModel& city)> makePath;  // required
    std::function<Status(uint64_t bytes)> beforePagedLoad;  // paged: the selected files' bytes, before any is read
    std::function<void()> cityLoaded;                       // after step 1 (e.g. a memory reading)
    std::function<Status(const SceneModel& city)> checkCity;
    std::vector<std::string> bakedModes;  // the modes whose baked files are loaded; empty = every given file
    std::function<Result<FrameEffects>(const Effects& declared)> effects;  // required
};

struct Walkthrough {
    SceneModel city;
    Path path;
    double cityLoadMs = 0;                          // step 1's wall time (with the path of a paged city)
    std::string pagedJson;                          // paged: the summary.json block of loadPagedNear(); else empty
    std::shared_ptr<const PagedManifest> manifest;  // paged: the city's manifest (for a pager); else null
};

Result<Walkthrough> loadWalkthrough(const WalkthroughRequest& request, ModeOptions& options);

Status loadPairedBakes(const std::string& cmd, const std::string& cityPath, const osg::Node* cityRoot,
                       const std::vector<std::string>& modes, ModeOptions& options);

Result<Path> walkthroughPath(const std::string& csvFile, const PathOptions& options, const SceneModel& city);

}  // namespace vista
