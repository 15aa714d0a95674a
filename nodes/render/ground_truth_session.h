// GroundTruthSession: what the frames of ground truth are drawn with — the
// offscreen renderer, the ray scene (when the mode or the run-time effects
// cast rays) or the stream of a paged city (its graph, ray scene and label
// twin), the render mode and the root of the label pass. `vista render` and
// the Python module's Renderer draw through it, so that equal cameras give
// equal bytes in both.
//
// setUp(): creates the renderer at setup.width x setup.height, the ray
// scene or the stream, the traffic's agents (setup.traffic: drawn in the
// near field and, where rays are cast, as moving ray instances) and the mode
// `setup.mode` (a name of the registry, render_mode.h). Errors (no GL context, a ray scene that cannot be built,
// an unknown mode) are returned, never thrown. `city` must outlive the
// session. renderFrame(): the mode's colour image of `camera` (rgba, row 0 at
// the top) and, with setup.labels, the labels (renderLabels: the label pass
// over the chunks the mode rasterised, then Embree rays for the pixels its
// far field filled). A session draws from one thread at a time; members are
// destroyed in reverse order (the mode before its context and the stream).
#pragma once
#include <cstddef>
#include <functional>
#include <memory>
#include <string>

#include <osg/Group>
#include <osg/ref_ptr>

#include "foundation/status.h"
#include "nodes/render/city_stream.h"
#include "nodes/render/offscreen.h"
#include "nodes/render/render_mode.h"
#include "nodes/render/traffic_scene.h"
#include "runtime/engine/ground_truth.h"
#include "runtime/engine/image.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/camera.h"
#include "runtime/scene/paged_load.h"
#include "runtime/scene/region_pager.h"
#include "runtime/scene/scene_model.h"

namespace vista {

struct GroundTruthSetup {
    std::string mode = "full";  // "full" or "hybrid" (any registry name works for rgb)
    int width = 640, height = 480;
    ModeOptions options;
    bool labels = false;                           // the depth, semantic and instance channels are drawn
    const PagedManifest* streamed = nullptr;       // a streamed paged city (its manifest), else null
    const PagedManifest* paged = nullptr;          // a paged city, loaded or streamed (its manifest), else null
    RegionPagerOptions stream;                     // streamed: the pager's options
    std::function<void(CityStream&)> streamReady;  // streamed: called once the stream exists (e.g. a memory hold)
    std::shared_ptr<const TrafficTracks> traffic;  // moving agents drawn at each camera's time (null: none)
};

// Scratch buffers of a frame, reused from frame to frame.
struct GroundTruthBuffers {
    Image img;
    LabelImage gt;
    LabelFrame raster;
};

// The costs of one frame's labels.
struct LabelCosts {
    double rasterMs = 0;   // the label pass
    double raysMs = 0;     // the far-field rays
    size_t farPixels = 0;  // pixels labelled by rays
};

struct GroundTruthSession {
    std::unique_ptr<OffscreenRenderer> renderer;
    std::unique_ptr<RayScene> rays;
    std::unique_ptr<CityStream> stream;     // streamed: the mode's graph, rays and label twin
    std::unique_ptr<TrafficScene> traffic;  // setup.traffic: the agents' models, overlay and ray instances
    ModeContext ctx;
    std::unique_ptr<RenderMode> mode;
    osg::ref_ptr<osg::Group> labelRoot = new osg::Group;
    std::string modeName;

    Status setUp(const GroundTruthSetup& setup, const SceneModel& city);
    RayScene* activeRays() { return stream ? stream->rays() : rays.get(); }
    // The mode's colour frame of `camera` into b.img (ray origins placed near the eye first).
    Status renderFrame(const Camera& camera, GroundTruthBuffers& b, FrameStats& stats);
    // The labels of the frame renderFrame() just drew into b.gt.
    Status renderLabels(const Camera& camera, int threads, GroundTruthBuffers& b, LabelCosts& costs);
};

}  // namespace vista
