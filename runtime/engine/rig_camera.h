// One image of a rig camera (rig.h), ray cast into a city RayScene: every
// channel the camera asks for from one Embree ray per pixel centre, and
// nothing for the channels it does not ask for.
//
// Rays: pixel (u, v) casts CameraModel::pixelRay(u, v) (camera_model.h: pixel
// centres at integer coordinates) turned into the world by `pose` (rig.h:
// columns x forward, y left, z up; the OpenCV camera frame is (-y, -z, x)),
// from pose.position, nothing clipped in front (no near plane). Back faces
// are culled as the rasteriser culls them (ray_scene.h).
// Channels (`channels`, RigChannel bits), row 0 at the top:
// - rgb: the prelit colour of the hit (what the rasteriser shows; run-time
//   effects that change surfaces, such as haze, are not applied), on a miss
//   the sky colour of the ray's direction (`fx`, or the default sky);
// - depth (float32 metres): pinhole: z-depth along the optical axis;
//   fisheye: the distance along the ray (a fisheye sees behind its image
//   plane); +inf for sky;
// - semantic / instance: ground_truth.h rayLabel (0 and 0 for sky); `ids`
//   is also filled for boxes (the instance image that the boxes are
//   computed from, runtime/engine/rig_boxes.h);
// - flow (float32 pairs du, dv, pixels): where the surface point (or, for
//   sky, the point at infinity in the ray's direction) seen at pixel (u, v)
//   projects in the camera at pose `next`, minus (u, v): exact forward flow
//   of a static scene. A point on a moving object of the ray scene (a mover,
//   ray_scene.h) whose instance id has an entry in `motions` moves with the
//   object first (ObjectMotion::motion, the object's rigid motion from the
//   shot's time to the next one), so the flow is exact for it too; one whose
//   entry is not `known` (the object is gone by then) gets kUnknownFlow; a
//   mover without an entry is taken as standing still. kUnknownFlow where it
//   has no projection (pinhole: behind the next camera).
// Fisheye pixels outside the image circle cast nothing: rgb black, depth
// NaN, class 255, instance 0, flow kUnknownFlow.
// Resizes the asked channels of `out` and frees the others. Parallel over
// `threads` workers (0 = all); every pixel's ray is cast in the same packet
// whatever the thread count: deterministic. Not thread-safe for one `out`.
#pragma once
#include <cstdint>
#include <vector>

#include "runtime/engine/frame_effects.h"
#include "runtime/engine/image.h"
#include "runtime/engine/camera_ray_table.h"
#include "runtime/engine/rig.h"
#include "runtime/scene/scene_model.h"

namespace vista {

class RayScene;

// Middlebury's marker of unknown flow (readers treat |value| > 1e9 as unknown).
constexpr float kUnknownFlow = 1e10f;

struct CameraImages {
    int width = 0, height = 0;
    Image rgb;
    std::vector<float> depth;
    std::vector<uint8_t> classes;
    std::vector<uint32_t> ids;
    std::vector<float> flow;  // 2 per pixel: du, dv
};

// A moving object's rigid motion over a flow's time step: world point at the
// shot's time -> the same body point at the next time.
struct ObjectMotion {
    uint32_t id = 0;         // instance id (labels.h)
    glm::dmat4 motion{1.0};  // world -> world
    bool known = false;      // false: the object is gone at the next time
};

struct CameraShot {
    CameraModel model;
    RigPose pose;
    unsigned channels = 0;
    RigPose next;                                        // flow only
    const std::vector<ObjectMotion>* motions = nullptr;  // flow only: sorted by id; null = none
    const FrameEffects* fx = nullptr;                    // sky colour; null = the default sky
    // The model's pixel rays (camera_ray_table.h), shared across firings: the same
    // rays as pixelRay's, without its trigonometry per pixel. Null, or a
    // table of another model: pixelRay per pixel.
    const CameraRayTable* rays = nullptr;
};

// The camera's world ray direction of pixel (u, v), false outside a fisheye's image circle.
bool shotRay(const CameraShot& shot, double u, double v, glm::dvec3& worldDir);
// The pixel of a world point in a camera at `pose` (camera_model.h project()).
bool projectWorld(const CameraModel& model, const RigPose& pose, const glm::dvec3& world, glm::dvec2& uv);

void castRigCamera(const SceneModel& city, const RayScene& rays, const CameraShot& shot, CameraImages& out,
                   int threads = 0);

}  // namespace vista
