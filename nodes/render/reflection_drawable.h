// ReflectionDrawable: the viewer face of the reflection stage
// (runtime/engine/reflections.h). Drawn after everything else (the effects
// wrapper puts it in a late render bin), it reads the frame back, runs
// reflectionStage() on it when it holds glass pixels and draws the result
// over the viewport; the bench face runs the same stage on its image.
// `rays` and `fx` must outlive the drawable; fx is read every frame (live
// toggles). Thread safety and state: ReadbackDrawable.
#pragma once
#include <cstdint>
#include <vector>

#include "nodes/readback_drawable.h"
#include "runtime/engine/frame_effects.h"

namespace vista {

class RayScene;

class ReflectionDrawable : public ReadbackDrawable {
public:
    ReflectionDrawable(const RayScene* rays, const FrameEffects* fx) : _rays(rays), _fx(fx) {}
    ReflectionDrawable(const ReflectionDrawable& o, const osg::CopyOp& op)
        : ReadbackDrawable(o, op), _rays(o._rays), _fx(o._fx) {}
    META_Object(vista, ReflectionDrawable);

protected:
    void drawFrame(osg::RenderInfo& renderInfo, const Camera& camera, const osg::Viewport& viewport,
                   double zFar) const override;

private:
    ReflectionDrawable() = default;
    const RayScene* _rays = nullptr;
    const FrameEffects* _fx = nullptr;
    mutable std::vector<uint32_t> _gl;  // scratch of the colour read (gl_readback.h)
};

}  // namespace vista
