// `raycast`: every pixel ray cast with Embree (mode_raycast.h).
#include "nodes/render/mode_raycast.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include <osg/Geode>
#include <osg/RenderInfo>
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include "citygen/lighting.h"
#include "foundation/timing.h"
#include "nodes/far_field_node.h"
#include "runtime/engine/ray_scene.h"

namespace vista {
namespace {

// One primary ray per pixel centre into `rays`; fills `out` and the pixel
// classes, rays and the "rays" stage of `stats`.
// TODO(merge): call castFrame() / castPrimaryRays() of
// runtime/engine/far_field_rays.h (branch `far`) instead of this loop.
void castEveryPixel(const RayScene& rays, const Camera& camera, Image& out, FrameStats& stats) {
    Stopwatch sw;
    if (out.width != camera.width || out.height != camera.height) out = Image(camera.width, camera.height);
    const glm::vec3 org(camera.eye - rays.frameOrigin());
    const int W = camera.width;
    // Camera::rayDirection with the basis hoisted out of the pixel loop
    // (same operations in the same order: bit-identical directions).
    const glm::dvec3 fw = camera.forward(), rt = camera.right(), up = camera.up();
    const double tanHalf = std::tan(0.5 * camera.fovY), aspect = double(camera.width) / double(camera.height);
    tbb::combinable<uint64_t> hits([] { return uint64_t(0); });
    tbb::parallel_for(tbb::blocked_range<int>(0, camera.height, 4), [&](const tbb::blocked_range<int>& r) {
        const size_t n = static_cast<size_t>(W);
        std::vector<glm::vec3> orgs(n, org), dirs(n);
        std::vector<glm::dvec3> ddirs(n);
        std::vector<RayHit> res(n);
        uint64_t nh = 0;
        for (int y = r.begin(); y != r.end(); ++y) {
            for (int x = 0; x < W; ++x) {
                double sx = (2.0 * (x + 0.5) / camera.width - 1.0) * tanHalf * aspect;
                double sy = (1.0 - 2.0 * (y + 0.5) / camera.height) * tanHalf;
                ddirs[size_t(x)] = glm::normalize(fw + sx * rt + sy * up);
                dirs[size_t(x)] = glm::vec3(ddirs[size_t(x)]);
            }
            rays.intersectMany(orgs.data(), dirs.data(), W, res.data());
            for (int x = 0; x < W; ++x) {
                const RayHit& h = res[size_t(x)];
                if (h.hit) {
                    out.set(x, y, glm::u8vec4(h.color.x, h.color.y, h.color.z, 255));
                    ++nh;
                } else {
                    out.set(x, y, skyColor(std::asin(std::clamp(ddirs[size_t(x)].z, -1.0, 1.0))));
                }
            }
        }
        hits.local() += nh;
    });
    const uint64_t pixels = uint64_t(camera.width) * uint64_t(camera.height);
    stats.pixels.rayHit = hits.combine(std::plus<uint64_t>());
    stats.pixels.rayMiss = pixels - stats.pixels.rayHit;
    stats.raysCast += pixels;
    stats.stages.set(Stage::Rays, sw.ms());
}

// Viewer face: casts the OSG camera's frame and draws it over the viewport.
class RaycastDrawable : public osg::Drawable {
public:
    explicit RaycastDrawable(const RayScene& rays) : _rays(rays) {
        setUseDisplayList(false);
        setUseVertexBufferObjects(false);
        setCullingActive(false);
        setDataVariance(osg::Object::DYNAMIC);
    }
    RaycastDrawable(const RaycastDrawable& o, const osg::CopyOp& op) : osg::Drawable(o, op), _rays(o._rays) {}
    osg::Object* cloneType() const override { return new RaycastDrawable(_rays); }
    osg::Object* clone(const osg::CopyOp& op) const override { return new RaycastDrawable(*this, op); }
    bool isSameKindAs(const osg::Object* o) const override { return dynamic_cast<const RaycastDrawable*>(o) != nullptr; }
    const char* libraryName() const override { return "vista"; }
    const char* className() const override { return "RaycastDrawable"; }
    FrameStats lastStats() const {
        std::lock_guard<std::mutex> lock(_mutex);
        return _stats;
    }
    void drawImplementation(osg::RenderInfo& ri) const override {
        std::lock_guard<std::mutex> lock(_mutex);
        const osg::Camera* cam = ri.getCurrentCamera();
        if (!cam || !cam->getViewport()) return;
        const osg::Viewport& vp = *cam->getViewport();
        Camera c;
        double zFar = 0;
        if (!cameraFromOsg(cam->getViewMatrix(), cam->getProjectionMatrix(), int(vp.width()), int(vp.height()), c, zFar)) return;
        _stats = FrameStats();
        castEveryPixel(_rays, c, _image, _stats);
        drawImageOverViewport(vp, _image, nullptr, _upload);
    }
    osg::BoundingBox computeBoundingBox() const override { return osg::BoundingBox(); }

private:
    const RayScene& _rays;
    mutable Image _image;
    mutable std::vector<uint8_t> _upload;
    mutable FrameStats _stats;
    mutable std::mutex _mutex;
};

class RaycastMode : public RenderMode {
public:
    explicit RaycastMode(ModeContext& ctx) : _ctx(ctx) {}
    std::string name() const override { return "raycast"; }
    Status renderFrame(const Camera& camera, Image& out, FrameStats& stats) override {
        Stopwatch sw;
        castEveryPixel(*_ctx.rays, camera, out, stats);
        stats.frameMs = sw.ms();
        stats.drawMs = stats.frameMs;
        return Status::ok();
    }
    osg::Node* viewerScene() override {
        if (!_viewer) {
            _drawable = new RaycastDrawable(*_ctx.rays);
            osg::ref_ptr<osg::Geode> geode = new osg::Geode;
            geode->setCullingActive(false);
            geode->addDrawable(_drawable.get());
            _viewer = geode;
        }
        return _viewer.get();
    }
    FrameStats lastViewerStats() const override { return _drawable ? _drawable->lastStats() : FrameStats(); }

private:
    ModeContext& _ctx;
    osg::ref_ptr<osg::Node> _viewer;
    osg::ref_ptr<RaycastDrawable> _drawable;
};

}  // namespace

Result<std::unique_ptr<RenderMode>> makeRaycastMode(ModeContext& ctx) {
    if (!ctx.rays) return Status::error("mode raycast needs the city's ray scene, which is not available");
    return std::unique_ptr<RenderMode>(new RaycastMode(ctx));
}

}  // namespace vista
