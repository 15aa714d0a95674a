// Pieces both kinds of `vista render` run share (one camera: cmd_render.cpp;
// a sensor rig: render_rig.cpp): the frames' names, the path check, the
// hashes of the work directory's manifest, classes.json, the kill hook.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "foundation/status.h"
#include "nodes/render/walkthrough.h"
#include "runtime/scene/paths.h"
#include "runtime/scene/scene_model.h"
#include "runtime/traffic/traffic_tracks.h"

namespace vista {

// "000042": the name of frame 42's files.
std::string frameName(size_t f);
// A path sample may stand this far outside the city square (streets run up
// to its border and a vehicle drives beside their centre line).
constexpr double kPathMargin = 50.0;
// World xy of every path sample inside the city square (params.origin +-
// size/2) grown by kPathMargin: the rendered frames, and the samples between
// them too (a LiDAR sweep interpolates the vehicle's pose between samples).
// The error names the sample (index and time), its position and the bounds.
Status checkPathInCity(const Path& path, const SceneModel& city);
// The class table and the instance encoding (classes.json).
nlohmann::json classesJson();
// Content hash of a file's bytes (hex), streamed; `bytes` receives its size.
Result<std::string> fileHash(const std::string& path, uint64_t& bytes);
// Hash of the frames' poses (path index, time, eye, heading, pitch):
// whatever chose them, equal poses give equal frames.
std::string posesHash(const Path& path, const std::vector<size_t>& idx);
// A hash of a traffic run's tracks (times, types, poses) and, when the
// tracks carry signal states, of `trafficDir`/signals.xml's bytes: a resumed
// run or a merged shard with --traffic must draw the same agents and lamps
// (and write the same traffic-light labels).
Result<std::string> trafficHash(const TrafficTracks& tracks, const std::string& trafficDir);
// A double as the manifest writes it (17 significant digits).
std::string manifestNumber(double v);
// Test hook (docs/formats.md): VISTA_RENDER_KILL_AFTER_FRAMES=N makes the run
// kill itself with SIGKILL after it finished N frames, as an interruption would.
long killAfterFrames();
// The walkthrough request both kinds of render make: the city file (never
// paged), notes off, the path from `pathFile` (a CSV) or `pathOptions` on the
// city's streets, `frames` of it as `sampleRuns` says into `idx` (more frames
// than samples only with `repeats`, checkFrameCount), every sample inside the
// city; a city without ground-truth labels is refused when `labelsFor` (the
// channels that need them, for the message) is not empty.
WalkthroughRequest renderRequest(const std::string& city, const std::string& pathFile, const PathOptions& pathOptions,
                                 int frames, int sampleRuns, bool repeats, const std::string& labelsFor,
                                 std::vector<size_t>& idx);
// The median of `v`, null when empty.
nlohmann::json medianOf(const std::vector<double>& v);

}  // namespace vista
