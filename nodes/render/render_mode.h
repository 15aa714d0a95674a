// RenderMode: one way of drawing a walkthrough frame (full, near, raycast,
// osgimpostor, osglod, hybrid, impostor, lodmesh), written once, in nodes/render/
// mode_<name>.{h,cpp}, and used by both programs through this registry:
//   `vista bench` times renderFrame() through the shared OffscreenRenderer;
//   `vista view`  draws viewerScene() in its window, calling
//                 beginViewerFrame() before every frame (the far plane it
//                 returns goes into the projection) and lastViewerStats()
//                 for the HUD.
// For the same camera both faces draw the same picture (same graph, same far
// plane, same culling, same sky; tested within 0.5 dB).
//
// Contract: a mode is created once from a ModeContext (which must outlive
// it) and then asked for frames in path order. renderFrame() fills `out`
// (camera.width x camera.height, row 0 at top) and `stats`; stats.frameMs is
// wall time from the start of the frame to an image on the CPU (glFinish
// included). renderFrame() needs ctx.renderer (error Status without one);
// viewerScene() needs none. Errors are Status values (setup problems: no
// display, no ray scene, no baked file); nothing throws. Modes are not
// thread-safe: one bench thread, or the viewer's single-threaded loop.
// setupMs() lists the set-up costs the mode itself measured (ms), e.g.
// {"chunking", "height_grid", "simplify", "impostors", "baked_load"}; the
// program adds the costs it paid for the mode ("load", "bvh").
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <osg/Group>
#include <osg/Node>
#include <osg/ref_ptr>

#include "foundation/status.h"
#include "nodes/point_impostor.h"
#include "nodes/near_field_chunks.h"
#include "nodes/view_cell_switch.h"
#include "runtime/engine/frame_effects.h"
#include "runtime/engine/frame_stats.h"
#include "runtime/engine/image.h"
#include "runtime/engine/panorama_cache.h"
#include "runtime/scene/camera.h"

namespace vista {

struct SceneModel;
struct PagedManifest;
class RayScene;
class OffscreenRenderer;
class CityStream;
class TrafficScene;

// The near distance of modes that need one when --near is auto (only hybrid
// chooses per frame).
constexpr double kDefaultNearDistance = 100.0;
// The default screen-space error bound of hybrid's flattened near-field chunks (pixels).
constexpr double kDefaultNearDetailPx = 0.0;

struct ModeOptions {
    double nearDistance = kDefaultNearDistance;  // metres, 1 .. 100000; < 0 = auto (hybrid: adaptive split)
    uint64_t triangleBudget = 0;                 // hybrid: > 0 = near field = nearest chunks up to this many triangles
    int64_t pixelBudget = -1;                    // hybrid: far-field rays per frame through the cache; < 0 = unlimited
    int horizonGrid = 0;  // hybrid: horizon height-grid cells per side, 1 .. 8192, 0 = auto (HeightGrid::autoCells)
    bool cache = true;    // hybrid: panoramic image cache on/off
    bool cacheAdaptive = true;  // hybrid: pause the cache while it does not pay (FarFieldOptions::cacheAdaptive)
    // hybrid: pause the horizon while it does not pay (FarFieldOptions::horizonAdaptive). With the
    // cache on, a paused horizon changes which far pixels the cache serves, so frames that must
    // not follow measured times (--cache-always, ground truth) turn it off with cacheAdaptive.
    bool horizonAdaptive = true;
    double cacheErrorPx =
        0.25;             // hybrid: reuse a cached far pixel while its reprojection error is below this, 0 .. 100
    bool overlap = true;  // hybrid: trace the horizon on another thread while the near field is drawn
    double frameMsTarget =
        0.0;          // hybrid: > 0 = the ray budget adapts so the frame takes about this long (ms), 0 .. 10000
    int farStep = 1;  // hybrid: far-field ray spacing, 1 (a ray per pixel) or 2 (FarFieldOptions::rayStep)
    // hybrid: the near field's chunks drawn nearest first (early depth rejection of hidden fragments).
    bool nearFrontToBack = true;
    // hybrid: a near-field chunk is drawn as its flattened twin (window recesses flat,
    // NearFieldScene::coarseChunks) where the twin deviates from it by at most this many
    // pixels on screen (screenDeviationPx), 0 .. 100; 0 = off (no twins built).
    double nearDetailPx = kDefaultNearDetailPx;
    int threads = 0;  // ray-casting threads; 0 = all cores
    double splatSigma =
        kDefaultSplatSigma;     // impostor: splat Gaussian sigma in output pixels (PointImpostor), 0 = 1-pixel points
    std::string bakedFile;      // impostor: the baked file (unless the scene itself is baked)
    std::string bakedMeshFile;  // lodmesh: the mesh bake (unless the scene itself is one)
    FrameEffects effects;       // run-time effects of every mode (haze, glass reflections, night sky)
    // Baked files the program already loaded and checked against the city
    // (checkBakedFromCity), by path as in bakedFile / bakedMeshFile: impostor
    // and lodmesh take the root from here instead of loading the file again
    // (set-up cost "baked_load" = loadMs).
    struct LoadedBake {
        osg::ref_ptr<ViewCellSwitch> root;
        double loadMs = 0;
    };
    std::map<std::string, LoadedBake> loadedBakes;
    // The near distance of modes without an adaptive split.
    double fixedNearDistance() const { return nearDistance > 0 ? nearDistance : kDefaultNearDistance; }
};

// Set-up costs in milliseconds, by name, in the order they were paid.
using SetupTimes = std::vector<std::pair<std::string, double>>;

// What the modes of one program run share. Public fields are set by the
// program before the first mode is created; everything must outlive the modes.
struct ModeContext {
    const SceneModel* city = nullptr;       // the decoded city (ray scene, height grid); null for hand-built graphs
    osg::Node* scene = nullptr;             // the city's graph as loaded (a baked file's root is fine)
    OffscreenRenderer* renderer = nullptr;  // bench: the GL context of renderFrame(); viewer: null
    bool labels = false;                    // nearField() also builds the label twins (vista render)
    const RayScene* rays = nullptr;         // built by the program for modes that need rays
    // A streamed paged city (city_stream.h): the chunked city graph, updated
    // between frames; chunkedCity() returns it (only the modes of
    // modeStreams() are created). Null: the city is loaded.
    osg::Group* streamedCity = nullptr;
    // The stream itself (with streamedCity): nearField() is its near field
    // when it keeps one (CityStream::enableNearField, for hybrid), which
    // also holds the horizon's height grid.
    CityStream* stream = nullptr;
    // A paged city, loaded or streamed: its manifest. hybrid lays its horizon
    // grid on the paged city's lattice (pagedHeightLattice), so a streamed
    // run and a preloaded one of the same regions trace the same grid.
    const PagedManifest* paged = nullptr;
    // A traffic run to draw (--traffic; traffic_scene.h), or null: every mode
    // shows its agents at the camera's time (Camera::time). The effects
    // wrapper places them before each frame (both faces) and draws them in GL
    // (the renderer's overlay, the viewer scene); modes with a ray-cast far
    // field split them (TrafficScene::setSplit: raycast all by rays, hybrid
    // by its near distance; RenderMode::splitsTraffic: then the wrapper only
    // moves it to the frame's time and the mode's split places it, once a
    // frame). Its ray scene is the one the modes trace.
    TrafficScene* traffic = nullptr;
    ModeOptions options;

    // The plain city: a baked root's tiles without its impostors, else `scene`.
    osg::Node* plainScene();
    // The plain city re-chunked (kNearChunkSize), built on the first call and
    // shared by full, near, osglod and hybrid; its cost in chunkingMs(). A
    // streamed city: the stream's near field (it changes between frames;
    // contract: the stream keeps one).
    const NearFieldScene& nearField();
    double chunkingMs() const { return _chunkingMs; }
    // Every chunk of nearField(), in its drawOrder, under one group with the
    // city's root state: the chunked full city (full and near draw it); the
    // streamed graph when streamedCity is set.
    osg::Group* chunkedCity();

private:
    osg::ref_ptr<osg::Node> _plain;
    std::shared_ptr<NearFieldScene> _nearField;
    osg::ref_ptr<osg::Group> _chunked;
    double _chunkingMs = 0;
};

// A baked file for a mode: from ctx.options.loadedBakes when the program
// loaded it already, else loaded and checked now (loadBakedFile; errors name
// the file). loadMs = what loading cost (then or now).
struct ModeBake {
    osg::ref_ptr<ViewCellSwitch> root;
    bool meshes = false;  // a mesh bake (isMeshBake)
    double loadMs = 0;
};
Result<ModeBake> loadBakeForMode(const ModeContext& ctx, const std::string& file);

// What a mode's last renderFrame() rasterised, for the ground-truth label
// pass of `vista render`: the chunks of ModeContext::nearField() it drew (in
// draw order), the far plane (metres, 0 = infinite) and the near distance
// (metres from the eye) beyond which its pixels came from the far field
// (+inf: every drawn pixel is final; uncovered pixels are far field or sky).
// wholeCity: the mode drew every chunk of ModeContext::chunkedCity(); over a
// streamed city (ModeContext::streamedCity) `chunks` is then empty and the
// label pass draws the stream's label twin (CityStream::labelGraph()).
struct RasterSelection {
    std::vector<uint32_t> chunks;
    double zFar = 0;
    double nearDistance = 1e300;
    bool wholeCity = false;
};

class RenderMode {
public:
    virtual ~RenderMode() = default;
    virtual std::string name() const = 0;
    // Bench face: one timed frame into `out`.
    virtual Status renderFrame(const Camera& camera, Image& out, FrameStats& stats) = 0;
    // The walkthrough restarts or jumps: caches are dropped.
    virtual void reset() {}
    // A streamed city's resident regions changed between frames (regions
    // arrived or left the ray scene and the near field; `changed` holds their
    // world boxes): what the mode kept of the old scene that could show them
    // (hybrid: the panoramic cache cells whose rays pass through a box,
    // FarField::sceneChanged, its speculative rays and kept frame) is
    // dropped, so no pixel of a dropped region, and none hiding an arrived
    // one, is served again; the rest is kept.
    virtual void sceneChanged(const SceneBoxes& changed) { (void)changed; }
    // Viewer face: the graph to draw (built on the first call, owned by the mode).
    virtual osg::Node* viewerScene() = 0;
    // Before every viewer frame, with the camera about to be drawn: returns
    // the projection's far plane in metres (0 = infinite).
    virtual double beginViewerFrame(const Camera& camera) {
        (void)camera;
        return 0.0;
    }
    // What the last viewer frame did (pixel classes, stage times, notes) for the HUD.
    virtual FrameStats lastViewerStats() const { return FrameStats(); }
    // True when the mode hazes its drawn pixels itself (both faces): the
    // effects wrapper then keeps the haze program out of the rasteriser.
    virtual bool hazesRasterPixels() const { return false; }
    // True when the mode writes every pixel its GL pass leaves uncovered, sky
    // included (hybrid: every such pixel is classified and filled by the far
    // field): the sky layer under its GL pass is not drawn (both faces).
    virtual bool drawsSky() const { return false; }
    // The pixels the far-field ray stage of the last renderFrame() cast
    // (FarField::lastTraced(), ascending), or null for a mode without one
    // (all but hybrid). `vista bench --dump-rays` writes them as RaySet files.
    virtual const std::vector<uint32_t>* lastTracedPixels() const { return nullptr; }
    // Where those rays started (metres from the eye; FarField::lastRayStart).
    virtual double lastRayStart() const { return 0.0; }
    // The raster part of the last renderFrame() (full, hybrid), or null for
    // modes whose picture is not the chunked near field plus rays.
    virtual const RasterSelection* lastRaster() const { return nullptr; }
    // True when both faces (renderFrame, beginViewerFrame) split the traffic
    // themselves (TrafficScene::setSplit: hybrid, raycast): the effects
    // wrapper then moves the traffic to the frame's time without placing it
    // (TrafficScene::setFrame's splitFollows), so a frame places it once.
    virtual bool splitsTraffic() const { return false; }
    const SetupTimes& setupMs() const { return _setup; }

protected:
    SetupTimes _setup;
};

// A mode that draws one scene graph in both faces (full, near, osgimpostor,
// osglod, impostor): renderFrame() renders _graph through ctx.renderer with
// the far plane that prepare() returns; the viewer draws the same graph with
// the same far plane. describe() adds the mode's notes to a frame's stats.
class GraphMode : public RenderMode {
public:
    Status renderFrame(const Camera& camera, Image& out, FrameStats& stats) override;
    osg::Node* viewerScene() override { return _graph.get(); }
    double beginViewerFrame(const Camera& camera) override { return prepare(camera); }
    FrameStats lastViewerStats() const override {
        FrameStats s;
        describe(s);
        return s;
    }

protected:
    explicit GraphMode(ModeContext& ctx) : _ctx(ctx) {}
    // Called before every frame of either face; returns the far plane (0 = infinite).
    virtual double prepare(const Camera& camera) {
        (void)camera;
        return 0.0;
    }
    virtual void describe(FrameStats& stats) const { (void)stats; }
    ModeContext& _ctx;
    osg::ref_ptr<osg::Node> _graph;  // set by the mode's constructor
};

// ---- the registry ------------------------------------------------------------
using ModeFactory = Result<std::unique_ptr<RenderMode>> (*)(ModeContext& ctx);
struct ModeInfo {
    const char* name;
    const char* summary;  // one line for --help
    bool needsRays;       // the program builds ctx.rays (RayScene) before creating it
    bool needsBaked;      // needs a baked scene or options.bakedFile
    ModeFactory make;
};
// Every mode, in display order: full, near, raycast, osgimpostor, osglod, hybrid, impostor, lodmesh.
const std::vector<ModeInfo>& renderModes();
const ModeInfo* findRenderMode(const std::string& name);
// "full, near, raycast, ..." (for messages and help).
std::string renderModeNames();
// Creates a mode. Unknown name -> error listing the modes; no ctx.scene, or
// a mode that needs rays without ctx.rays -> error naming what is missing.
// Every mode comes wrapped with the run-time effects of ctx.options.effects
// (one implementation for all modes and both faces): the renderer's fog and
// night sky, the haze far plane, and the reflection stage (reflections.h)
// after every frame when the scene marks glass (needs ctx.rays when
// reflections are on: effectsNeedRays()).
Result<std::unique_ptr<RenderMode>> createRenderMode(const std::string& name, ModeContext& ctx);
bool effectsNeedRays(const FrameEffects& fx);
// The modes that draw a streamed paged city (ModeContext::streamedCity):
// those drawing only the chunked city, rays or both split by distance (full,
// near, raycast, hybrid, hybrid-fixed).
bool modeStreams(const std::string& name);
std::string streamingModeNames();  // "full, near, raycast, hybrid, hybrid-fixed" (for messages)
// True for the modes that need the stream's near field (hybrid, hybrid-fixed).
bool modeStreamsNearField(const std::string& name);
// The levels of a stream that the listed modes draw (CityStream::setGraphLevels): none for
// ray casting alone, the near band when the rest are hybrid modes, else every level.
enum class StreamGraph;
StreamGraph streamGraphOf(const std::vector<std::string>& modes);
// The near band of those modes (metres): the farthest near distance they draw (the adaptive
// split's largest middle candidate, or the fixed distance) plus kStreamBandMarginM, the
// distance over which a region's chunks load before the near field needs them.
constexpr double kStreamBandMarginM = 250.0;
double streamNearBand(const ModeOptions& options);
// True when a mode's pictures follow measured times under these options, so
// that two runs of the same frames may differ: hybrid with the adaptive split
// (--near auto), the adaptive cache or horizon with the cache on (not
// --cache-always) or a frame-time
// target; hybrid-fixed with the latter two. Every other mode: false.
bool modeFollowsTimings(const std::string& name, const ModeOptions& options);

}  // namespace vista
