// Streaming a paged city in the three walkthrough commands (`vista bench`,
// `vista view`, `vista render`; the default for a paged city): one set-up and one
// per-frame step, so the commands stream alike. The streaming itself is a
// CityStream (nodes/render/city_stream.h): one RegionPager feeding the
// chunked city graph, the ray scene and (render) the label twin, advanced
// between frames on the frame thread while the loads run on its worker.
//
// pagedStreamOptions(): the pager options of the flags: --paged-radius and
// --paged-far around the camera, --paged-prefetch seconds ahead (default
// kDefaultPagedPrefetchS), --paged-wait, and the budget: what --memory-budget
// leaves after `preloadMb` (streamBudgetBytes; errors name
// --memory-budget). checkStreamingModes(): every mode streams (modeStreams),
// else an error naming --paged-stream and the modes that do.
// notePagedStream(): the stderr note "CMD: paged city: streaming its N
// regions around the camera (...)".
//
// choosePagedStream(): whether a run streams its city: a paged city streams
// unless --paged-preload is given, or no streaming flag is given and
// `cannotStream` says why this run cannot (a mode that does not stream; the
// run then preloads, with a note on stderr unless `quiet`). Errors name the
// flag: --paged-stream, --paged-wait or --paged-prefetch with a city file or
// with a run that cannot stream (`cannotStream`), --paged-preload with a city
// file.
//
// advancePagedStream(): CityStream::advance for a camera at `eye` moving at
// `velocity` (m/s). A stream that cannot stream is an error: region files
// that cannot be read (each appended to `damaged`, if not null; the message
// names them), or a budget that cannot hold the regions at the camera (the
// message names --memory-budget and the budget they need). Errors: those of
// CityStream::advance too.
//
// StreamDetail: the frames that drew a region below the detail its distance
// asks for (CityStreamFrame::belowDetail), in all and after the first second
// of path time. noteStreamDetail(): that count on stderr ("CMD: paged
// stream: N of M frames drew a region below the detail its distance asks for
// (K after the first second)").
//
// pathVelocity(): the camera's velocity at path sample i (metres per second;
// towards the next sample, or from the previous one at the end; zero for a
// path of one sample). pagedStreamJson(): the summary.json block
// paged.stream (docs/formats.md, docs/reference/bench-output.md) of a streamed run.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "cmd/options.h"
#include "foundation/status.h"
#include "nodes/render/city_stream.h"
#include "runtime/scene/paged_walkthrough.h"
#include "runtime/scene/paths.h"
#include "runtime/scene/region_pager.h"

namespace vista {

Result<RegionPagerOptions> pagedStreamOptions(const PagedReach& reach, const PagedStreamFlags& flags, double budgetGb,
                                              double preloadMb);
// --memory-budget GB held for the whole process (CityStream::holdProcessUnder) when the
// stream has a budget; nothing otherwise.
void holdStreamUnder(CityStream& stream, double budgetGb);
Status checkStreamingModes(const std::vector<std::string>& modes);
Result<bool> choosePagedStream(const char* cmd, const PagedStreamFlags& flags, const std::string& city,
                               const std::string& cannotStream, bool quiet);

struct StreamDetail {
    int frames = 0, belowDetail = 0, belowDetailAfterFirstSecond = 0;
    double t0 = 0;
    // A frame at path time `t` (seconds) drawn after `f`.
    void add(const CityStreamFrame& f, double t);
};
void noteStreamDetail(const char* cmd, const StreamDetail& d);
void notePagedStream(const char* cmd, const PagedManifest& manifest, const RegionPagerOptions& options);
Result<CityStreamFrame> advancePagedStream(CityStream& stream, const char* cmd, const glm::dvec3& eye,
                                           const glm::dvec3& velocity, std::vector<std::string>* damaged,
                                           bool wait = false);
glm::dvec3 pathVelocity(const Path& path, size_t i);
nlohmann::json pagedStreamJson(const RegionPagerOptions& options, const RegionPagerStats& stats, int framesWithArrivals,
                               const std::vector<std::string>& damaged, const StreamDetail& detail);

}  // namespace vista
