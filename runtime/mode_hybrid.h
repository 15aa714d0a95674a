// `hybrid` bench mode (issue 4, thesis ch. 4): near field rasterised through
// the OffscreenRenderer, far field filled per pixel by FarField (opacity from
// the near field's depth, horizon, panoramic cache, Embree rays), composited
// on the CPU (uncovered pixels of the read-back near image are replaced).
//
// Near field granularity: the city's 250 m tiles are far coarser than a 100 m
// near distance, so the mode re-chunks the loaded scene into square chunks
// (kNearChunkSize metres, by triangle centroid; triangles larger than a chunk
// go to a per-tile "large" chunk; trees by trunk position, drawn with the
// city file's own instanced state set). Same vertices, colours and state as
// the loaded scene, so near-field pixels equal the `full` mode's.
//
// Options (BenchOptions): nearDistance (< 0 = auto: AdaptiveSplit),
// pixelBudget, horizonGrid, cache, threads. FrameStats: pixel classes (Table
// 4.1), stagesMs: cull, near (GL draw + readback), opacity, horizon, cache,
// rays, composite; notes: skipped stages, chosen near distance in auto mode.
// Errors: missing ray scene / renderer / city -> error Status from the factory.
#pragma once
#include <memory>
#include <vector>

#include <osg/Group>
#include <osg/Node>
#include <osg/StateSet>

#include "citygen/status.h"
#include "runtime/adaptive_split.h"
#include "runtime/bench_mode.h"

namespace vista {

constexpr double kNearChunkSize = 40.0;  // metres

// The city re-chunked for a fine near/far split: chunks[i] is drawn iff
// objects[i] is selected. rootState = the city root's state set.
struct NearFieldScene {
    osg::ref_ptr<osg::StateSet> rootState;
    std::vector<osg::ref_ptr<osg::Node>> chunks;
    std::vector<SplitObject> objects;
    uint64_t triangles = 0;
};
// Builds chunks from a scene graph written by buildCityScene()/loaded by
// loadCityFile(). Unknown node layouts are kept as single chunks (bounds from
// OSG), so any scene works, only more coarsely.
NearFieldScene buildNearFieldScene(osg::Node* cityScene, double chunkSize = kNearChunkSize);

Result<std::unique_ptr<BenchMode>> makeHybridMode(BenchContext& ctx);

}  // namespace vista
