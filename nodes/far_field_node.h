// FarFieldNode: the draw-side composite of the hybrid renderer for `vista
// view` and stock viewers (thesis ch. 4 steps 3-7 inside one OSG frame).
//
// A Drawable placed in a late render bin (kFarFieldRenderBin), so it draws
// after the near field: it reads back the depth buffer of its viewport (the
// opacity buffer), derives a vista::Camera from the OSG camera's view and
// projection matrices (heading/pitch/roll, fovY, zNear/zFar), runs FarField
// (horizon, panoramic cache, Embree rays; plain arrays) and writes the far-field
// pixels into the frame buffer with glDrawPixels, alpha-tested so that covered
// pixels stay untouched (the few seam-checked pixels that far geometry occludes
// are overwritten). Fixed-function GL (compatibility profile), state saved
// and restored with glPushAttrib/glPopAttrib.
//
// Ownership: the RayScene and HeightGrid must outlive the node. The node keeps
// the FarField (with its cache) and the last frame's statistics. Drawing is
// single-threaded per context (one FarField per node); nothing throws.
// Perspective projections only (an orthographic camera draws nothing).
#pragma once
#include <memory>
#include <mutex>
#include <vector>

#include <osg/Drawable>
#include <osg/Group>
#include <osg/Viewport>
#include <osg/RenderInfo>
#include <osg/observer_ptr>

#include "runtime/engine/frame_stats.h"
#include "runtime/engine/far_field.h"
#include "runtime/engine/horizon.h"
#include "nodes/near_far_split.h"
#include "nodes/near_field_chunks.h"
#include "nodes/readback_drawable.h"

namespace vista {

class RayScene;
struct SceneModel;

constexpr int kFarFieldRenderBin = 10000;

class FarFieldNode : public ReadbackDrawable {
public:
    FarFieldNode(const RayScene& rays, const HeightGrid* grid, const FarFieldOptions& options);
    // Not copyable through CopyOp (owns per-context state); clone returns a fresh node.
    FarFieldNode(const FarFieldNode& o, const osg::CopyOp& copyop = osg::CopyOp::SHALLOW_COPY);
    osg::Object* cloneType() const override { return new FarFieldNode(_rays, _grid, _options); }
    osg::Object* clone(const osg::CopyOp& copyop) const override { return new FarFieldNode(*this, copyop); }
    bool isSameKindAs(const osg::Object* obj) const override {
        return dynamic_cast<const FarFieldNode*>(obj) != nullptr;
    }
    const char* libraryName() const override { return "vista"; }
    const char* className() const override { return "FarFieldNode"; }

    // The split node whose near distance the far field follows (optional).
    void setSplit(NearFarSplit* split) { _split = split; }
    void setOptions(const FarFieldOptions& o);
    FarFieldOptions options() const;

    // Called at cull time (a cull callback set here): starts the far field's
    // horizon and speculative rays for the camera the draw will see
    // (FarField::beginFrame), so that they overlap the near field's draw. The
    // draw takes them only when its camera is exactly that one.
    void beginFrame(const osg::Camera& camera) const;
    // The ray scene changed (a streamed city, between frames): FarField::sceneChanged.
    void sceneChanged(const SceneBoxes& changed);

protected:
    ~FarFieldNode() override;
    // Reads the depth (and, for hazeCovered, the colours), runs FarField and
    // draws the far-field pixels.
    void drawFrame(osg::RenderInfo& renderInfo, const Camera& camera, const osg::Viewport& viewport,
                   double zFar) const override;

private:
    FarFieldOptions frameOptions(double zFar) const;  // _options with the split's near distance; _mutex held
    const RayScene& _rays;
    const HeightGrid* _grid;
    FarFieldOptions _options;
    osg::observer_ptr<NearFarSplit> _split;
    mutable std::unique_ptr<FarField> _far;
    mutable std::vector<float> _depth;
    mutable std::vector<uint32_t> _depthBits, _colorBits;  // scratch of the reads (gl_readback.h)
};

// The hybrid renderer as one graph (the viewer face of the `hybrid` mode and
// stock viewers): the city re-chunked under a NearFarSplit plus a
// FarFieldNode, under a group carrying the city's root state set. `grid`
// must outlive the returned graph (as must `rays`). The second form reuses
// chunks already built (nodes are shared, not copied).
struct HybridSceneOptions {
    double nearDistance = 100.0;
    uint64_t triangleBudget = 0;  // > 0: split by triangle budget instead
    FarFieldOptions far;
};
osg::ref_ptr<osg::Group> buildHybridScene(const SceneModel& city, const RayScene& rays, const HeightGrid& grid,
                                          const HybridSceneOptions& options, NearFarSplit** splitOut = nullptr,
                                          FarFieldNode** farOut = nullptr);
osg::ref_ptr<osg::Group> buildHybridScene(const NearFieldScene& nearField, const RayScene& rays, const HeightGrid& grid,
                                          const HybridSceneOptions& options, NearFarSplit** splitOut = nullptr,
                                          FarFieldNode** farOut = nullptr);

}  // namespace vista
