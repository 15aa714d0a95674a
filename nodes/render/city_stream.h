// CityStream: a paged city streamed for the render modes (bench
// --paged-stream). One RegionPager (runtime/scene/region_pager.h) feeds the
// mirrors of the resident set, updated between frames by advance():
//  - the chunked city graph (graph()): one group per resident region level
//    holding that level's near-field chunks (buildNearFieldScene, built on
//    the pager's worker thread) in their draw order, under a root with the
//    regions' root state. Groups are kept in the order loadPagedCity()
//    merges (full levels by region, then coarse levels by region), so the
//    graph draws what ModeContext::chunkedCity() draws for a preloaded city
//    of the same regions, in the same order;
//  - the ray scene (rays(), when made with rays): a StreamedRayScene follower,
//    each region's Embree scene built on the worker thread too (the frame
//    thread instances it and commits the top level). Coarse levels are
//    traced with their coarse geometry and their tree impostors as the
//    city's tree meshes;
//  - the label twin of the graph (labelGraph(), when made with labels, for
//    the ground truth of `vista render`): one group per resident region level
//    holding the label twins of that level's chunks (NearFieldScene::
//    labelChunks, built on the worker thread with the chunks) in the same
//    order as graph(), under a root with the label pass's root state, so the
//    label pass over it rasterises the pixels graph() draws;
//  - the near field (nearField(), after enableNearField()): the resident
//    levels' chunks, their split index and the horizon's height grid
//    (StreamedNearField), cut on the worker thread and spliced here.
// Which levels carry chunks (setGraphLevels): every level (the default); the
// full regions within a band around the camera only, as the pager's chunk
// parts (the hybrid modes: their near field reaches a few hundred metres;
// farther full regions and every coarse level are only traced, and the
// horizon still gets their height patches); or none (ray casting alone).
// Without chunks for every level the graph is not the whole city, so the
// hybrid does not offer "everything" then. A level's model is freed
// on the worker as soon as what it feeds is made: nothing keeps a decoded
// region beyond its chunks, its Embree scene and its height patch.
// Modes that draw the chunked city (full, near), cast rays (raycast) or
// split the two (hybrid, hybrid-fixed) use them through ModeContext
// (streamedCity, rays, stream); the others need the whole loaded city and
// do not stream (modeStreams()). generation() counts the advances that
// changed the resident set: a mode that caches what it traced (hybrid's
// panoramic cache) drops it when the generation moves (RenderMode::
// sceneChanged, called by the program).
//
// Contract: the manifest outlives the stream; advance() runs between frames,
// never while a frame is drawn or rays are cast. Errors: those of the ray
// scene (an Embree error naming the region). A damaged region file is no
// error: advance() returns its message once and the pager falls back; a
// budget that cannot hold the regions at the camera is no error either:
// advance() says so in CityStreamFrame::shortfall and the caller decides.
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <osg/Group>
#include <osg/ref_ptr>

#include "foundation/status.h"
#include "nodes/render/streamed_near_field.h"
#include "runtime/engine/panorama_cache.h"
#include "runtime/engine/ray_streaming.h"
#include "runtime/scene/region_pager.h"

namespace vista {

// The region levels that carry chunks in the graph and the near field (CityStream::setGraphLevels).
enum class StreamGraph { EveryLevel, NearBand, None };

// Resident bytes per region file byte of what a stream's workers keep of a
// load (measured with tests/bench/stream_memory on the middle regions of a
// 1,024 km² city, docs/measurements/paging.md, rounded up): a level's Embree
// scene (compact layout), full and coarse; its chunks in the graph (a chunk
// part, or a level with chunks), full and coarse; their label twins, per byte
// of chunks. A height patch is below the measurement's resolution.
constexpr double kStreamRaysPerFileByte = 1.1, kStreamCoarseRaysPerFileByte = 1.6;
constexpr double kStreamChunksPerFileByte = 1.2, kStreamCoarseChunksPerFileByte = 4.0;
constexpr double kStreamLabelsPerChunkByte = 0.5;
// The passing peak of decoding and preparing a load on the worker, beyond what it keeps (the
// budget holds back room for the largest region's; measured 1.8).
constexpr double kStreamLoadingPerFileByte = 2.0;
// The memory budget's weights (RegionPagerOptions::cost) of a stream that makes
// ray scenes (rays), chunks on `graph`'s levels and their label twins (labels).
RegionCost streamRegionCost(bool rays, StreamGraph graph, bool labels);

struct CityStreamFrame {
    int arrived = 0, dropped = 0;  // region levels
    // The world boxes (manifest bounds, both levels) of the levels that arrived or left, for
    // RenderMode::sceneChanged.
    SceneBoxes changed;
    bool waited = false;
    std::vector<std::string> damaged;
    // The regions held below the detail their distance from the eye asks for (RegionPager::belowDetail).
    int belowDetail = 0;
    // Non-empty: the budget cannot hold even the coarse levels of the regions at the camera
    // (RegionPager::cameraShortfall); the message names them and the budget they need (GB, the
    // whole process's with holdProcessUnder). Nothing else of the frame is set then.
    std::string shortfall;
};

class CityStream {
public:
    // prototypes: the city's tree prototypes for the ray scene (see
    // StreamedRayScene; empty = read at set-up). rays = false: no ray scene.
    ~CityStream();  // stops the pager first: its workers use the ray scene
    // labels = true: also the label twin (labelGraph()).
    static Result<std::unique_ptr<CityStream>> create(const PagedManifest& manifest, RegionPagerOptions options,
                                                      bool rays, std::vector<SceneMesh> prototypes = {},
                                                      bool labels = false);
    // The near field too (hybrid): chunks, split index and a horizon grid of horizonCells a
    // side (0 = auto) on the paged city's lattice (pagedHeightLattice). Contract: before the
    // first advance() and with rays.
    void enableNearField(int horizonCells);
    // Which levels get chunks (StreamGraph; default EveryLevel); NearBand: the full regions within
    // bandM metres of the camera's lookahead (RegionPagerOptions::chunkRadius). Contract: before
    // the first advance(); bandM finite and >= 0 for NearBand.
    void setGraphLevels(StreamGraph levels, double bandM = 0);
    StreamGraph graphLevels() const { return _graphLevels; }
    // Holds the whole process under `bytes` (--memory-budget): before each advance the
    // pager's budget becomes `bytes` less the process's own memory beside what its loads keep
    // (its GL context, frame buffers and caches, and what the heap keeps between live blocks:
    // the resident set less the held loads' cost, measured while no load is under way and
    // after the heap's free pages are handed back), at least the part of `bytes` the options'
    // budget left out.
    // Contract: options.budgetBytes > 0 and <= bytes.
    void holdProcessUnder(uint64_t bytes);
    // Moves the pager to the eye and mirrors what it hands over. wait = true:
    // this call blocks until the desired set is resident, as every call does
    // with options.wait (e.g. before a viewer's first frame).
    Result<CityStreamFrame> advance(const glm::dvec3& eye, const glm::dvec3& velocity, bool wait = false);
    osg::Group* graph() const { return _root.get(); }
    RayScene* rays() { return _rays ? &_rays->rays() : nullptr; }
    // The label twin of graph(); null unless made with labels.
    osg::Group* labelGraph() const { return _labelRoot.get(); }
    StreamedNearField* nearField() { return _near.get(); }
    uint64_t generation() const { return _generation; }
    // Per manifest region, the level held now (RegionPager::held()).
    std::vector<uint8_t> held() const;
    RegionPagerStats stats() const;
    // The pager's options (with the chunk radius setGraphLevels chose and the budget's weights of
    // what this stream makes, streamRegionCost).
    const RegionPagerOptions& options() const { return _options; }

private:
    CityStream() = default;
    void updateCost() { _options.cost = streamRegionCost(_rays != nullptr, _graphLevels, _labelRoot.valid()); }
    // A group's key: (coarse, region, chunk part), ordered as loadPagedCity merges levels.
    using GroupKey = std::tuple<bool, int, bool>;
    RegionPagerOptions _options;          // the pager's (setGraphLevels makes it again)
    std::unique_ptr<RegionPager> _pager;  // made by the first advance()
    std::unique_ptr<StreamedRayScene> _rays;
    std::unique_ptr<StreamedNearField> _near;  // read by the workers' prepare once set
    const PagedManifest* _manifest = nullptr;
    StreamGraph _graphLevels = StreamGraph::EveryLevel;  // read by the workers' prepare once loads start
    uint64_t _generation = 0;
    bool _advanced = false;
    uint64_t _processBudget = 0;  // holdProcessUnder; 0 = the options' budget as it is
    uint64_t _overhead = 0;       // the process's own memory beside its loads (the last measured)
    uint64_t _overheadFloor = 0;  // ... at least the part of the budget the options left out
    bool _dropsSinceMeasure = false;
    osg::ref_ptr<osg::Group> _root;
    std::map<GroupKey, osg::ref_ptr<osg::Group>> _groups;  // each level's or part's chunk group under _root
    osg::ref_ptr<osg::Group> _labelRoot;                   // labels: the twins of _groups, same keys and order
    std::map<GroupKey, osg::ref_ptr<osg::Group>> _labelGroups;
};

}  // namespace vista
