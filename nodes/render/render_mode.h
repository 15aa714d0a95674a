// BenchMode: one way of rendering a walkthrough frame, compared side by side
// by `vista bench` (full, near, raycast, osgimpostor, hybrid, impostor).
//
// Contract: a mode is created once per bench run from a BenchContext and then
// asked for frames in path order, interleaved with the other modes.
// renderFrame() fills `out` (camera.width x camera.height, row 0 at top) and
// `stats`; frame_ms is wall time from the start of the frame to an image
// ready on the CPU side (GL work finished: glFinish before the clock stops).
// It returns an error Status only for setup problems (no display, Embree
// failure); never throws. Modes are not thread-safe; one bench thread calls them.
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "foundation/status.h"
#include "runtime/engine/frame_stats.h"
#include "runtime/scene/camera.h"
#include "runtime/engine/image.h"

namespace osg { class Node; }

namespace vista {

struct SceneModel;
class RayScene;
class OffscreenRenderer;

struct BenchOptions {
    double nearDistance = 100.0;  // metres; < 0 means "auto" (adaptive split)
    int64_t pixelBudget = -1;     // far-field rays per frame; < 0 = unlimited
    int horizonGrid = 512;        // horizon height grid resolution (cells per side)
    bool cache = true;            // panoramic image cache on/off
    int threads = 0;              // 0 = all cores
    std::string bakedFile;        // for the impostor mode
};

struct BenchContext {
    const SceneModel* city = nullptr;
    osg::Node* scene = nullptr;          // the full scene graph as loaded
    OffscreenRenderer* renderer = nullptr;  // shared GL context (all GL modes render through it)
    RayScene* rays = nullptr;            // built on demand by the bench when a mode needs it
    BenchOptions options;
};

class BenchMode {
public:
    virtual ~BenchMode() = default;
    virtual std::string name() const = 0;
    virtual Status renderFrame(const Camera& camera, Image& out, FrameStats& stats) = 0;
    // Called when the walkthrough restarts or jumps (caches must be dropped).
    virtual void reset() {}
};

}  // namespace vista
